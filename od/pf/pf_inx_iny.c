/*
 * pf_inx_iny.c - Pepperl+Fuchs INX360D-F99-B16-V15 (single axis) and
 * INY360D-F99-B16-V15 (dual axis). The manual's object chapter (section 8)
 * is missing from the edition at hand; these tables are inferred from its
 * other chapters. Every value the manual does not give is marked on its
 * line:
 *   [inf]  inferred from the manual's text
 *   [301]  CiA 301 / CiA 410 default, not in the manual
 *   [ph]   placeholder: unknown, never confirmed (no source gives the
 *          identity; a real unit or P+F's EDS would)
 * Tables sorted by (index, sub-index).
 */
#include "co_progdl.h"
#include "pf.h"
/* clang-format off */

#define RO (CO_A_R)
#define RW (CO_A_RW)
#define CONST (CO_A_R | CO_A_CONST)
#define PARA(f) CO_AT(CO_CLS_PARA, pf_para_t, f)
#define LSS(f) CO_AT(CO_CLS_LSS, co_lss_para_t, f)

/* The entries both models have, up to 0x1800. */
#define PF_COMMON_1000_TO_1800(devtype, devname)                                                          \
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CONST, .def = (devtype), CO_NAME("Device type")}, \
    {.index = 0x1001, .sub = 0, CO_TYPE_U8, .attr = RO, CO_EXT(.read = co_emcy_read_register), CO_NAME("Error register")}, \
    {.index = 0x1005, .sub = 0, CO_TYPE_U32, .attr = RW, PARA(sync_cobid), .def = 0x80, CO_EXT(.write = co_sync_write_cobid), CO_NAME("COB-ID SYNC")}, /* [301]: the SYNC types need it */ \
    {.index = 0x1008, .sub = 0, CO_TYPE_STR(devname), .attr = CONST, CO_NAME("Manufacturer device name")}, /* [inf] the type code on the title page */ \
    {.index = 0x100C, .sub = 0, CO_TYPE_U16, .attr = RW, PARA(guard_ms), .def = 0, CO_NAME("Guard time")}, /* default [301] */ \
    {.index = 0x100D, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(life_factor), .def = 0, CO_NAME("Life time factor")}, /* default [301] */ \
    {.index = 0x1010, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 1, CO_NAME("Store parameters")}, /* [301] */ \
    /* Reads 3: saves on command and autonomously (every write is stored). */ \
    {.index = 0x1010, .sub = 1, CO_TYPE_U32, .attr = RW, .def = 3, CO_EXT(.write = co_store_write_save), CO_NAME("Save all parameters")}, \
    {.index = 0x1011, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 1, CO_NAME("Restore default parameters")}, /* [301] */ \
    {.index = 0x1011, .sub = 1, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_load), CO_NAME("Restore all default parameters")}, \
    {.index = 0x1014, .sub = 0, CO_TYPE_U32, .attr = RW | CO_A_NODEID, PARA(emcy_cobid), .def = 0x80, CO_EXT(.write = co_emcy_write_cobid), CO_NAME("COB-ID EMCY")}, \
    /* UNSIGNED16 (CiA 301) though the manual says "32-bit" (section 7.2.2). */ \
    {.index = 0x1017, .sub = 0, CO_TYPE_U16, .attr = RW, PARA(hb_ms), .def = 0, CO_EXT(.write = co_hb_write_time), CO_NAME("Producer heartbeat time")}, \
    {.index = 0x1018, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 4, CO_NAME("Identity object")}, \
    {.index = 0x1018, .sub = 1, CO_TYPE_U32, .attr = CONST, .def = 0, CO_NAME("Vendor-ID")}, /* [ph] */ \
    {.index = 0x1018, .sub = 2, CO_TYPE_U32, .attr = CONST, .def = 0, CO_NAME("Product code")}, /* [ph] */ \
    {.index = 0x1018, .sub = 3, CO_TYPE_U32, .attr = CONST, .def = 0, CO_NAME("Revision number")}, /* [ph] */ \
    {.index = 0x1018, .sub = 4, CO_TYPE_U32, .attr = RO | CO_A_SERIAL, .def = 0, CO_NAME("Serial number")}, /* per unit (co_node_set_serial) */ \
    {.index = 0x1800, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 5, CO_NAME("TPDO1 communication parameter")}, \
    {.index = 0x1800, .sub = 1, CO_TYPE_U32, .attr = RW | CO_A_NODEID, PARA(tpdo_cobid), .def = 0x180, CO_EXT(.write = co_tpdo_write_cobid), CO_NAME("COB-ID TPDO1")}, \
    /* Default 1: synchronous, CiA 410's default (the manual gives none); 0, \
     * 1..240, 252..255 accepted: the manual's types (section 7.1.1) and \
     * CiA 301's 0, FCh, FEh. */ \
    {.index = 0x1800, .sub = 2, CO_TYPE_U8, .attr = RW, PARA(tx_type), .def = 1, CO_EXT(.write = co_tpdo_write_comm), CO_NAME("Transmission type")}, \
    /* 100 us units; writable while the PDO is valid, as the manual's \
     * example writes it (section 7.1.1). */ \
    {.index = 0x1800, .sub = 3, CO_TYPE_U16, .attr = RW, PARA(inhibit), .def = 0, CO_EXT(.write = co_tpdo_write_comm), CO_NAME("Inhibit time")}, /* default [301] */ \
    {.index = 0x1800, .sub = 5, CO_TYPE_U16, .attr = RW, PARA(event_ms), .def = 0, CO_EXT(.write = co_tpdo_write_comm), CO_NAME("Event timer")} /* [301], so that tools writing it do not fail */

/* Per axis: CiA 410 slope objects in 0.1 deg, full turn. */
#define PF_AXIS(base, ax, nm)                                                                           \
    {.index = (base), .sub = 0, CO_TYPE_I16, .attr = RO | CO_A_PDO, CO_EXT(.read = pf_read_slope), CO_NAME("Slope " nm)}, \
    /* bit0 reverse, bit1 scaling; default 0 [301]. */ \
    {.index = (base) + 1, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(incl.op[ax]), .def = 0, CO_EXT(.min = 0, .max = 3), CO_NAME("Slope " nm " operating parameter")}, \
    {.index = (base) + 2, .sub = 0, CO_TYPE_I16, .attr = RW, PARA(incl.preset[ax]), .def = 0, CO_EXT(.min = 0, .max = 3599, .write = pf_write_preset), CO_NAME("Slope " nm " preset value")}, \
    {.index = (base) + 3, .sub = 0, CO_TYPE_I16, .attr = RW, PARA(incl.offset[ax]), .def = 0, CO_EXT(.min = -3599, .max = 3599), CO_NAME("Slope " nm " offset")}, \
    {.index = (base) + 4, .sub = 0, CO_TYPE_I16, .attr = RW, PARA(incl.diff[ax]), .def = 0, CO_EXT(.min = -3599, .max = 3599), CO_NAME("Differential slope " nm " offset")}

#define PF_2000_TO_6000                                                                                 \
    /* Stored at once, active after reset node or power-on (manual, \
     * sections 6.2 and 6.3; not at reset communication). */ \
    {.index = 0x2000, .sub = 0, CO_TYPE_U8, .attr = RW, LSS(node_id), .def = 1, CO_EXT(.min = 1, .max = 127), CO_NAME("Node-ID")}, \
    {.index = 0x2001, .sub = 0, CO_TYPE_U8, .attr = RW, LSS(bitrate), .def = PF_BR_250K, CO_EXT(.write = pf_write_bitrate), CO_NAME("Baud rate")}, \
    {.index = 0x6000, .sub = 0, CO_TYPE_U16, .attr = RW, PARA(incl.resolution), .def = 100, CO_EXT(.write = pf_write_resolution), CO_NAME("Resolution")} /* [301] fixed 0.1 deg */

static const co_od_entry_t inx_entries[] = {
    PF_COMMON_1000_TO_1800(0x0000019Au /* high word [ph] */, "INX360D-F99-B16-V15"),
    {.index = 0x1A00, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(map_count), .def = 1, CO_EXT(.write = co_tpdo_write_map), CO_NAME("TPDO1 mapping parameter")}, /* [inf] the INY frame without Y */
    {.index = 0x1A00, .sub = 1, CO_TYPE_U32, .attr = RW, PARA(map[0]), .def = 0x60100010u, CO_EXT(.write = co_tpdo_write_map), CO_NAME("1st mapped object")}, /* [inf] the INY frame without Y */
    CO_PROGDL_TABLE /* program download: the MCU image's side (co_progdl.h) */
    PF_2000_TO_6000,
    PF_AXIS(0x6010, 0, "long16"),
};

static const co_od_entry_t iny_entries[] = {
    PF_COMMON_1000_TO_1800(0x0000019Au /* high word [ph] */, "INY360D-F99-B16-V15"),
    {.index = 0x1A00, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(map_count), .def = 2, CO_EXT(.write = co_tpdo_write_map), CO_NAME("TPDO1 mapping parameter")},
    {.index = 0x1A00, .sub = 1, CO_TYPE_U32, .attr = RW, PARA(map[0]), .def = 0x60100010u, CO_EXT(.write = co_tpdo_write_map), CO_NAME("1st mapped object")}, /* [inf] the INY frame (section 7.1.1) */
    {.index = 0x1A00, .sub = 2, CO_TYPE_U32, .attr = RW, PARA(map[1]), .def = 0x60200010u, CO_EXT(.write = co_tpdo_write_map), CO_NAME("2nd mapped object")}, /* [inf] the INY frame (section 7.1.1) */
    CO_PROGDL_TABLE /* program download: the MCU image's side (co_progdl.h) */
    PF_2000_TO_6000,
    PF_AXIS(0x6010, 0, "long16"),
    PF_AXIS(0x6020, 1, "lateral16"),
};

static const co_od_t inx_od = {.entries = inx_entries, .count = sizeof(inx_entries) / sizeof(inx_entries[0])};
static const co_od_t iny_od = {.entries = iny_entries, .count = sizeof(iny_entries) / sizeof(iny_entries[0])};

_Static_assert(sizeof(pf_para_t) <= CO_STORE_MAX_DATA, "PARA set must fit one store slot");

static const co_service_t *const pf_services[] = {&co_guard_service, &co_rtr_service, NULL};

#define PF_CFG(odp)                                                                 \
    {.od = (odp), .ops = &pf_ops, .led = NULL /* CiA 303-3 timing: the manual has none */, \
     .services = pf_services,                                                        \
     .sdo_segmented = co_sdo_segmented, .sdo_block = co_sdo_block,                   \
     .ram_size = {[CO_CLS_PARA] = sizeof(pf_para_t), [CO_CLS_LSS] = sizeof(co_lss_para_t)}, \
     .default_node_id = 1, .default_bitrate = PF_BR_250K, .tpdo_dlc = 0,             \
     .autosave = true /* node-ID and bit rate survive without a save (6.2) */, \
     .load_keeps_lss = true /* decision: "load" keeps node-ID and bit rate */, \
     .kbps = product_kbps_pf}
const co_node_cfg_t pf_inx_cfg = PF_CFG(&inx_od);
const co_node_cfg_t pf_iny_cfg = PF_CFG(&iny_od);

static const pf_variant_t v_inx = {.cfg = &pf_inx_cfg, .axes = 1};
static const pf_variant_t v_iny = {.cfg = &pf_iny_cfg, .axes = 2};

const product_t pf_inx360d = {
    .id = PRODUCT_TEXT("inx360d"), .summary = PRODUCT_TEXT("Pepperl+Fuchs INX360D single axis 0..359.9 deg (CiA 410)"),
    .inputs = {{"x", PRODUCT_TEXT("deg"), 0, PRODUCT_ANGLE_LIMIT}},
    .faults = {PRODUCT_FAULT("range-x"), PRODUCT_FAULT("range-y"), PRODUCT_FAULT("undervoltage"), NULL},
    .nodes = 1, .inst_size = sizeof(pf_dev_t), .create = pf_create, .sample = pf_sample,
    .variant = &v_inx, .cfg = &pf_inx_cfg, .vendor = PRODUCT_TEXT("Pepperl+Fuchs")};
const product_t pf_iny360d = {
    .id = PRODUCT_TEXT("iny360d"), .summary = PRODUCT_TEXT("Pepperl+Fuchs INY360D dual axis 0..359.9 deg (CiA 410)"),
    .inputs = {{"x", PRODUCT_TEXT("deg"), 0, PRODUCT_ANGLE_LIMIT}, {"y", PRODUCT_TEXT("deg"), 0, PRODUCT_ANGLE_LIMIT}},
    .faults = {PRODUCT_FAULT("range-x"), PRODUCT_FAULT("range-y"), PRODUCT_FAULT("undervoltage"), NULL},
    .nodes = 1, .inst_size = sizeof(pf_dev_t), .create = pf_create, .sample = pf_sample,
    .variant = &v_iny, .cfg = &pf_iny_cfg, .vendor = PRODUCT_TEXT("Pepperl+Fuchs")};
/* clang-format on */
