/*
 * jd_tables.c - the ifm JD2xxx (dual axis) and JD1xxx (single axis)
 * dictionaries, after the object chapters of their operating instructions
 * (sections 8.9 and 9, the overview of section 10). Values the manual does
 * not give are marked "(?)"; sorted by (index, sub-index).
 */
#include "co_progdl.h"
#include "jd.h"
/* clang-format off */

#define RO (CO_A_R)
#define RW (CO_A_RW)
#define WO (CO_A_W)
#define CONST (CO_A_R | CO_A_CONST)
#define PARA(f) CO_AT(CO_CLS_PARA, jd_para_t, f)
#define PDO (CO_A_PDO)

/* Both TPDOs: rw COB-ID (CiA 301 rules), type 1 by default, inhibit time
 * writable only while invalid, the shared event timer, dynamic mapping. */
#define JD_TPDO(n, cobdef, inhdef)                                                                           \
    {.index = 0x1800 + (n), .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 5, CO_NAME("TPDO communication parameter")}, \
    {.index = 0x1800 + (n), .sub = 1, CO_TYPE_U32, .attr = RW | CO_A_NODEID, PARA(cob[n]), .def = (cobdef), CO_EXT(.write = co_tpdo_write_cobid), CO_NAME("COB-ID")}, \
    {.index = 0x1800 + (n), .sub = 2, CO_TYPE_U8, .attr = RW, PARA(type[n]), .def = 1, CO_EXT(.write = co_tpdo_write_comm), CO_NAME("Transmission type")}, \
    {.index = 0x1800 + (n), .sub = 3, CO_TYPE_U16, .attr = RW, PARA(inhibit[n]), .def = (inhdef), CO_EXT(.write = jd_write_inhibit), CO_NAME("Inhibit time")}, \
    {.index = 0x1800 + (n), .sub = 5, CO_TYPE_U16, .attr = RW, PARA(event_ms), .def = 10, CO_EXT(.write = jd_write_event), CO_NAME("Event timer")}

#define JD_MAP(n, count, m2)                                                                                 \
    {.index = 0x1A00 + (n), .sub = 0, CO_TYPE_U8, .attr = RW, PARA(map_count[n]), .def = (count), CO_EXT(.write = co_tpdo_write_map), CO_NAME("TPDO mapping parameter")}, \
    {.index = 0x1A00 + (n), .sub = 1, CO_TYPE_U32, .attr = RW, PARA(map[n][0]), .def = 0x60100010u, CO_EXT(.write = co_tpdo_write_map), CO_NAME("1st mapped object")}, \
    {.index = 0x1A00 + (n), .sub = 2, CO_TYPE_U32, .attr = RW, PARA(map[n][1]), .def = (m2), CO_EXT(.write = co_tpdo_write_map), CO_NAME("2nd mapped object")}

/* 0x1000 .. 0x1018, the same on both models but for the device type and name. */
#define JD_COMM(devtype, devname)                                                                            \
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CONST, .def = (devtype), CO_NAME("Device type")},       \
    {.index = 0x1001, .sub = 0, CO_TYPE_U8, .attr = RO, CO_EXT(.read = co_emcy_read_register), CO_NAME("Error register")}, \
    /* Depth 1: only sub 1 is documented (manual, section 9.3). */ \
    {.index = 0x1003, .sub = 0, CO_TYPE_U8, .attr = RW, CO_EXT(.write = co_emcy_write_hist, .read = co_emcy_read_hist), CO_NAME("Pre-defined error field")}, \
    {.index = 0x1003, .sub = 1, CO_TYPE_U32, .attr = RO, CO_EXT(.read = co_emcy_read_hist), CO_NAME("Most recent error")}, \
    {.index = 0x1005, .sub = 0, CO_TYPE_U32, .attr = RW, PARA(sync_cobid), .def = 0x80, CO_EXT(.write = co_sync_write_cobid), CO_NAME("COB-ID SYNC")}, \
    {.index = 0x1008, .sub = 0, CO_TYPE_STR(devname), .attr = CONST, CO_NAME("Manufacturer device name")}, /* (?) */ \
    {.index = 0x1009, .sub = 0, CO_TYPE_STR("HW 1.0"), .attr = CONST, CO_NAME("Manufacturer hardware version")}, /* (?) */ \
    {.index = 0x100A, .sub = 0, CO_TYPE_STR("FW 1.0"), .attr = CONST, CO_NAME("Manufacturer software version")}, /* (?) */ \
    {.index = 0x100C, .sub = 0, CO_TYPE_U16, .attr = RW, PARA(guard_ms), .def = 0, CO_NAME("Guard time")}, \
    {.index = 0x100D, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(life_factor), .def = 0, CO_NAME("Life time factor")}, \
    {.index = 0x1010, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 4, CO_NAME("Store parameters")}, \
    {.index = 0x1010, .sub = 1, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_save), CO_NAME("Save all parameters")}, \
    {.index = 0x1010, .sub = 2, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_group_save), CO_NAME("Save communication parameters")}, \
    {.index = 0x1010, .sub = 3, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_group_save), CO_NAME("Save application parameters")}, \
    {.index = 0x1010, .sub = 4, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_group_save), CO_NAME("Save manufacturer parameters")}, \
    {.index = 0x1011, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 4, CO_NAME("Restore default parameters")}, \
    {.index = 0x1011, .sub = 1, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_load), CO_NAME("Restore all parameters")}, \
    {.index = 0x1011, .sub = 2, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_group_load), CO_NAME("Restore communication parameters")}, \
    {.index = 0x1011, .sub = 3, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_group_load), CO_NAME("Restore application parameters")}, \
    {.index = 0x1011, .sub = 4, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_group_load), CO_NAME("Restore manufacturer parameters")}, \
    /* UNSIGNED32, rw, 0x80 + node-ID (CiA 301; the manual's overview says \
     * read-only and its section prints the node-1 value 0x81). */ \
    {.index = 0x1014, .sub = 0, CO_TYPE_U32, .attr = RW | CO_A_NODEID, PARA(emcy_cobid), .def = 0x80, CO_EXT(.write = co_emcy_write_cobid), CO_NAME("COB-ID EMCY")}, \
    {.index = 0x1016, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 1, CO_NAME("Consumer heartbeat time")}, \
    {.index = 0x1016, .sub = 1, CO_TYPE_U32, .attr = RW, PARA(hb_consumer), .def = 0, CO_EXT(.write = co_hbc_write_time), CO_NAME("Consumer heartbeat time 1")}, \
    {.index = 0x1017, .sub = 0, CO_TYPE_U16, .attr = RW, PARA(hb_ms), .def = 0, CO_EXT(.write = co_hb_write_time), CO_NAME("Producer heartbeat time")}, \
    {.index = 0x1018, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 4, CO_NAME("Identity object")}, \
    {.index = 0x1018, .sub = 1, CO_TYPE_U32, .attr = CONST, .def = 0x0069666Du, CO_NAME("Vendor-ID")}, /* "ifm" */ \
    {.index = 0x1018, .sub = 2, CO_TYPE_U32, .attr = CONST, .def = 0, CO_NAME("Product code")}, /* "0x0 (JDxxxx)" (?) */ \
    {.index = 0x1018, .sub = 3, CO_TYPE_U32, .attr = CONST, .def = 0x00010000u, CO_NAME("Revision number")}, /* build constant (?) */ \
    {.index = 0x1018, .sub = 4, CO_TYPE_U32, .attr = RO | CO_A_SERIAL, .def = 0, CO_NAME("Serial number")} /* per unit (co_node_set_serial) */

/* 0x2200 .. 0x3411 (2601h on JD2 only). */
#define JD_MFR_HEAD \
    /* The cyclic timer is the event timer (manual, sections 8.9.6, 9.16). */ \
    {.index = 0x2200, .sub = 0, CO_TYPE_U16, .attr = RW, PARA(event_ms), .def = 10, CO_EXT(.write = jd_write_event), CO_NAME("Cyclic time")}, \
    {.index = 0x2300, .sub = 0, CO_TYPE_U32, .attr = WO, CO_EXT(.write = jd_write_save_reset), CO_NAME("Save parameters with reset")}, \
    {.index = 0x2600, .sub = 0, CO_TYPE_I16, .attr = RW, CO_EXT(.write = jd_write_preset, .read = jd_read_preset), CO_NAME("Preset X-axis")}
#define JD_MFR_TAIL \
    /* Fast boot-up: stored; the simulated boot is immediate either way. */ \
    {.index = 0x2700, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(fast_boot), .def = 0, CO_EXT(.min = 0, .max = 1), CO_NAME("Fast boot-up")}, \
    /* Node-ID - 1 (manual, section 9.21); default 0x09: "ifm standard \
     * node number is 10" (the table's 0 would be node 1); active after \
     * save and reset. */ \
    {.index = 0x3000, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(node_number), .def = 0x09, CO_EXT(.min = 0, .max = 0x7E), CO_NAME("Node number")}, \
    /* 0..7 = 20, 50, 100, 125, 250, 500, 800, 1000 kbit/s. */ \
    {.index = 0x3001, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(bitrate), .def = 0x03, CO_EXT(.min = 0, .max = 7), CO_NAME("Baud rate")}, \
    {.index = 0x3002, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(termination), .def = 0, CO_EXT(.min = 0, .max = 1), CO_NAME("Termination resistor")}, \
    {.index = 0x3005, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(autostart), .def = 0, CO_EXT(.min = 0, .max = 1), CO_NAME("Auto boot-up")}, \
    {.index = 0x3022, .sub = 0, CO_TYPE_U16, .attr = RW, PARA(recursive), .def = 0, CO_NAME("Digital recursive filter")}, /* undocumented (?) */ \
    {.index = 0x3100, .sub = 0, CO_TYPE_U16, .attr = RW, PARA(maf), .def = 0, CO_EXT(.min = 0, .max = JD_MAF_MAX), CO_NAME("Moving average filter")}, \
    {.index = 0x3400, .sub = 0, CO_TYPE_I16, .attr = RO | PDO, CO_EXT(.read = jd_read_sensor), CO_NAME("Gyro X axis 16")}, \
    {.index = 0x3401, .sub = 0, CO_TYPE_I16, .attr = RO | PDO, CO_EXT(.read = jd_read_sensor), CO_NAME("Gyro Y axis 16")}, \
    {.index = 0x3402, .sub = 0, CO_TYPE_I16, .attr = RO | PDO, CO_EXT(.read = jd_read_sensor), CO_NAME("Gyro Z axis 16")}, \
    {.index = 0x3403, .sub = 0, CO_TYPE_I16, .attr = RO | PDO, CO_EXT(.read = jd_read_sensor), CO_NAME("Acceleration X axis 16")}, \
    {.index = 0x3404, .sub = 0, CO_TYPE_I16, .attr = RO | PDO, CO_EXT(.read = jd_read_sensor), CO_NAME("Acceleration Y axis 16")}, \
    {.index = 0x3405, .sub = 0, CO_TYPE_I16, .attr = RO | PDO, CO_EXT(.read = jd_read_sensor), CO_NAME("Acceleration Z axis 16")}, \
    {.index = 0x3411, .sub = 0, CO_TYPE_U16, .attr = RO | PDO, CO_EXT(.read = jd_read_sensor), CO_NAME("Temperature gyro")}, \
    /* 10, 100, 1000 (x 0.001 deg); a change rescales presets and offsets \
     * (manual, section 9.37). */ \
    {.index = 0x6000, .sub = 0, CO_TYPE_U16, .attr = RW, PARA(resolution), .def = 10, CO_EXT(.write = jd_write_resolution), CO_NAME("Resolution")}

/* One axis of 16-bit slope objects at base (0x6010 / 0x6020). */
#define JD_AXIS16(base, ax, type16, nm) \
    {.index = (base), .sub = 0, type16, .attr = RO | PDO, CO_EXT(.read = jd_read_slope), CO_NAME("Slope " nm "16")}, \
    {.index = (base) + 1, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(op16[ax]), .def = 0, CO_EXT(.min = 0, .max = 3), CO_NAME("Slope " nm "16 operating parameter")}, \
    {.index = (base) + 2, .sub = 0, CO_TYPE_I16, .attr = RW, CO_EXT(.write = jd_write_preset, .read = jd_read_preset), CO_NAME("Slope " nm "16 preset value")}, \
    {.index = (base) + 3, .sub = 0, CO_TYPE_I16, .attr = RO, PARA(off16[ax]), .def = 0, CO_NAME("Slope " nm "16 offset")}, \
    {.index = (base) + 4, .sub = 0, CO_TYPE_I16, .attr = RW, PARA(diff16[ax]), .def = 0, CO_EXT(.write = jd_write_diff), CO_NAME("Differential slope " nm "16 offset")}
#define JD_AXIS32(base, ax, nm) \
    {.index = (base), .sub = 0, CO_TYPE_I32, .attr = RO | PDO, CO_EXT(.read = jd_read_slope), CO_NAME("Slope " nm "32")}, \
    {.index = (base) + 1, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(op32[ax]), .def = 0, CO_EXT(.min = 0, .max = 3), CO_NAME("Slope " nm "32 operating parameter")}, \
    {.index = (base) + 2, .sub = 0, CO_TYPE_I32, .attr = RW, PARA(preset[ax]), .def = 0, CO_EXT(.write = jd_write_preset), CO_NAME("Slope " nm "32 preset value")}, \
    {.index = (base) + 3, .sub = 0, CO_TYPE_I32, .attr = RO, PARA(off32[ax]), .def = 0, CO_NAME("Slope " nm "32 offset")}, \
    {.index = (base) + 4, .sub = 0, CO_TYPE_I32, .attr = RW, PARA(diff32[ax]), .def = 0, CO_EXT(.write = jd_write_diff), CO_NAME("Differential slope " nm "32 offset")}

static const co_od_entry_t jd2_entries[] = {
    JD_COMM(0x0002019Au, "JD2xxx"),
    JD_TPDO(0, 0x180, 0),
    JD_TPDO(1, 0x280, 1), /* TPDO2 inhibit default 1, as printed (manual, 8.9.2) */
    JD_MAP(0, 2, 0x60200010u),
    JD_MAP(1, 2, 0x60200010u),
    CO_PROGDL_TABLE /* program download: the MCU image's side (co_progdl.h) */
    JD_MFR_HEAD,
    {.index = 0x2601, .sub = 0, CO_TYPE_I16, .attr = RW, CO_EXT(.write = jd_write_preset, .read = jd_read_preset), CO_NAME("Preset Y-axis")},
    JD_MFR_TAIL,
    JD_AXIS16(0x6010, 0, CO_TYPE_I16, "long"),
    JD_AXIS16(0x6020, 1, CO_TYPE_I16, "lateral"),
    JD_AXIS32(0x6110, 0, "long"),
    JD_AXIS32(0x6120, 1, "lateral"),
};

static const co_od_entry_t jd1_entries[] = {
    JD_COMM(0x0001019Au, "JD1xxx"),
    JD_TPDO(0, 0x180, 0),
    JD_TPDO(1, 0x280, 1),
    JD_MAP(0, 1, 0x60200010u),
    JD_MAP(1, 1, 0x60200010u),
    CO_PROGDL_TABLE /* program download: the MCU image's side (co_progdl.h) */
    JD_MFR_HEAD,
    JD_MFR_TAIL,
    /* Z, 0..N-1 as UNSIGNED16 (0..360 deg clockwise, manual section 8.2). */
    JD_AXIS16(0x6010, 0, CO_TYPE_U16, "long"),
    /* 6020h "will output 0 for a sensor with one axis" (manual, section
     * 9.41); 6021h-6024h absent (?). */
    {.index = 0x6020, .sub = 0, CO_TYPE_I16, .attr = RO | PDO, CO_EXT(.read = jd_read_slope), CO_NAME("Slope lateral16")},
    JD_AXIS32(0x6110, 0, "long"),
    {.index = 0x6120, .sub = 0, CO_TYPE_I32, .attr = RO | PDO, CO_EXT(.read = jd_read_slope), CO_NAME("Slope lateral32")},
};

static const co_od_t jd2_od = {.entries = jd2_entries, .count = sizeof(jd2_entries) / sizeof(jd2_entries[0])};
static const co_od_t jd1_od = {.entries = jd1_entries, .count = sizeof(jd1_entries) / sizeof(jd1_entries[0])};

_Static_assert(sizeof(jd_para_t) <= CO_STORE_MAX_DATA, "PARA set must fit one store slot");

/* CiA 305 bit-timing indices 0-4, 6, 7 (not 5 = reserved, not 8 = 10k):
 * the rates 3001h has (product_kbps_ifm; test_products_edge checks that
 * the two agree). */
#define JD_LSS_BITRATES 0x00DFu
static const co_service_t *const jd_services[] = {&co_lss_service, &co_guard_service,
                                                  &co_hbc_service, &co_rtr_service, NULL};

#define JD_CFG(odp)                                                                   \
    {.od = (odp), .ops = &jd_ops, .led = NULL /* CiA 303-3 timing: the manual has none */, \
     .services = jd_services,                                                           \
     .sdo_segmented = co_sdo_segmented, .sdo_block = co_sdo_block,                      \
     .ram_size = {[CO_CLS_PARA] = sizeof(jd_para_t)}, .default_node_id = 10,            \
     .id_index = 0x3000, .id_offset = 1 /* 3000h = node-ID - 1 (manual, 9.21) */,       \
     .default_bitrate = 3, .tpdo_dlc = 0, .lss_bitrates = JD_LSS_BITRATES,     \
     .kbps = product_kbps_ifm}
const co_node_cfg_t jd2_cfg = JD_CFG(&jd2_od);
const co_node_cfg_t jd1_cfg = JD_CFG(&jd1_od);

static const uint8_t axes2 = 2;
static const uint8_t axes1 = 1;

const product_t jd2xxx = {
    .id = PRODUCT_TEXT("jd2xxx"), .summary = PRODUCT_TEXT("ifm JD2xxx dual axis +-90 deg, LSS (CiA 410)"),
    .inputs = {{"x", PRODUCT_TEXT("deg"), 0, PRODUCT_ANGLE_LIMIT}, {"y", PRODUCT_TEXT("deg"), 0, PRODUCT_ANGLE_LIMIT},
               {"temp", PRODUCT_TEXT("degC"), 25000, 200}},
    .nodes = 1, .inst_size = sizeof(jd_dev_t), .create = jd_create, .sample = jd_sample,
    .variant = &axes2, .cfg = &jd2_cfg, .vendor = PRODUCT_TEXT("ifm electronic")};
const product_t jd1xxx = {
    .id = PRODUCT_TEXT("jd1xxx"), .summary = PRODUCT_TEXT("ifm JD1xxx single axis 0..360 deg, LSS (CiA 410)"),
    .inputs = {{"z", PRODUCT_TEXT("deg"), 0, PRODUCT_ANGLE_LIMIT}, {"temp", PRODUCT_TEXT("degC"), 25000, 200}},
    .nodes = 1, .inst_size = sizeof(jd_dev_t), .create = jd_create, .sample = jd_sample,
    .variant = &axes1, .cfg = &jd1_cfg, .vendor = PRODUCT_TEXT("ifm electronic")};
/* clang-format on */
