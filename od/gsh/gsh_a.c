/*
 * gsh_a.c - the Gefran GSH-A dictionary, after the object table of its
 * manual (section 12 'CANopen features summary'), one table for both
 * channels; the channels differ only in their default node-ID (0x13,
 * 0x14). Sorted by (index, sub-index).
 */
#include "co_progdl.h"
#include "gsh.h"
#include "product_eds.h"
/* clang-format off */

#define RO (CO_A_R)
#define RW (CO_A_RW)
#define CONST (CO_A_R | CO_A_CONST)
#define PARA(f) CO_AT(CO_CLS_PARA, gsh_para_t, f)
#define LSS(f) CO_AT(CO_CLS_LSS, co_lss_para_t, f)

/* The node-ID default (0x3001) is per channel, so two tables differ in one line. */
#define GSH_ENTRIES(node_id_default)                                                                        \
    /* Multiple logical device, DS-406 first (manual, section 12). */ \
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CONST, .def = 0xFFFF0196u, CO_NAME("Device type")}, \
    /* "Always 0" (manual, section 12), even with alarms in the PDO. */ \
    {.index = 0x1001, .sub = 0, CO_TYPE_U8, .attr = RO, .def = 0, CO_NAME("Error register")}, \
    {.index = 0x1005, .sub = 0, CO_TYPE_U32, .attr = RW, PARA(sync_cobid), .def = 0x80, CO_EXT(.write = co_sync_write_cobid), CO_NAME("COB-ID SYNC")}, \
    {.index = 0x1008, .sub = 0, CO_TYPE_STR("GSHA"), .attr = CONST, CO_NAME("Manufacturer device name")}, \
    /* "1.xx", format Maj.MinMin: the unit's own values are not known. */ \
    {.index = 0x1009, .sub = 0, CO_TYPE_STR("1.00"), .attr = CONST, CO_NAME("Manufacturer hardware version")}, \
    {.index = 0x100A, .sub = 0, CO_TYPE_STR("1.00"), .attr = CONST, CO_NAME("Manufacturer software version")}, \
    {.index = 0x1010, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 4, CO_NAME("Store parameters")}, \
    /* The manual's table says wo and prints no read of it: CiA 301's rw, \
     * a read answers the storage capability (1 = saves on command), as \
     * subs 2-4 do (sub 0 says 4; the manual lists only sub 1). */ \
    {.index = 0x1010, .sub = 1, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_save), CO_NAME("Save all parameters")}, \
    {.index = 0x1010, .sub = 2, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_group_save), CO_NAME("Save communication parameters")}, \
    {.index = 0x1010, .sub = 3, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_group_save), CO_NAME("Save application parameters")}, \
    {.index = 0x1010, .sub = 4, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_group_save), CO_NAME("Save manufacturer parameters")}, \
    /* No 0x1011: the manual has none. Heartbeat 0x1017 is not in the table \
     * but described (section 8); decision: CiA 301's default 0 (off). */ \
    {.index = 0x1017, .sub = 0, CO_TYPE_U16, .attr = RW, PARA(hb_ms), .def = 0, CO_EXT(.write = co_hb_write_time), CO_NAME("Producer heartbeat time")}, \
    {.index = 0x1018, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 4, CO_NAME("Identity object")}, \
    {.index = 0x1018, .sub = 1, CO_TYPE_U32, .attr = CONST, .def = 0x00000093u, CO_NAME("Vendor-ID")}, \
    {.index = 0x1018, .sub = 2, CO_TYPE_U32, .attr = CONST, .def = 0x00000067u, CO_NAME("Product code")}, \
    {.index = 0x1018, .sub = 3, CO_TYPE_U32, .attr = CONST, .def = 0x00000001u, CO_NAME("Revision number")}, \
    {.index = 0x1018, .sub = 4, CO_TYPE_U32, .attr = RO | CO_A_SERIAL, .def = 0, CO_NAME("Serial number")}, /* per unit, each channel its own (co_node_set_serial) */ \
    {.index = 0x1200, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 2, CO_NAME("SDO server parameter")}, \
    {.index = 0x1200, .sub = 1, CO_TYPE_U32, .attr = RO | CO_A_NODEID, .def = 0x600, CO_NAME("COB-ID client to server")}, \
    {.index = 0x1200, .sub = 2, CO_TYPE_U32, .attr = RO | CO_A_NODEID, .def = 0x580, CO_NAME("COB-ID server to client")}, \
    {.index = 0x1800, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 5, CO_NAME("Tx PDO #0 communication parameter")}, \
    {.index = 0x1800, .sub = 1, CO_TYPE_U32, .attr = RO | CO_A_NODEID, .def = 0x180, CO_NAME("COB-ID")}, \
    {.index = 0x1800, .sub = 2, CO_TYPE_U8, .attr = RO, .def = 254, CO_NAME("Transmission type")}, /* ro in the manual's table */ \
    {.index = 0x1800, .sub = 3, CO_TYPE_U16, .attr = RO, .def = 4, CO_NAME("Inhibit time")}, /* as printed; nothing depends on it */ \
    {.index = 0x1800, .sub = 4, CO_TYPE_U8, .attr = RO, .def = 0, CO_NAME("Reserved")}, /* listed in the manual's table */ \
    /* 100 ms as the table and the examples say (the PDO text says 50); \
     * 0 = off, 4..65535 ms. */ \
    {.index = 0x1800, .sub = 5, CO_TYPE_U16, .attr = RW, PARA(event_ms), .def = 100, CO_EXT(.write = gsh_write_event), CO_NAME("Event timer")}, \
    /* The manual's table prints 2 entries (4 bytes) for its 8-byte frame; \
     * 5 here, so that the mapping covers every byte the frame has \
     * and a CiA 301 consumer that checks the length against it (EMCY 8220h) \
     * sees none: subs 3..5 map the alarm word, counter and checksum the \
     * manual's Table 3 prints in bytes 5-6, 7 and 8 (0x2110..0x2112 below). \
     * Subs 1 and 2 are the manual's bytes. */ \
    {.index = 0x1A00, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 5, CO_NAME("Tx PDO #0 mapping parameter")}, \
    {.index = 0x1A00, .sub = 1, CO_TYPE_U32, .attr = CONST, .def = 0x60040010u, CO_NAME("1st object")}, /* UNSIGNED32; the table says Unsigned16 */ \
    {.index = 0x1A00, .sub = 2, CO_TYPE_U32, .attr = CONST, .def = 0x68100010u, CO_NAME("2nd object")}, \
    {.index = 0x1A00, .sub = 3, CO_TYPE_U32, .attr = CONST, .def = 0x21100010u, CO_NAME("3rd object")}, /* bytes 5-6 */ \
    {.index = 0x1A00, .sub = 4, CO_TYPE_U32, .attr = CONST, .def = 0x21110008u, CO_NAME("4th object")}, /* byte 7 */ \
    {.index = 0x1A00, .sub = 5, CO_TYPE_U32, .attr = CONST, .def = 0x21120008u, CO_NAME("5th object")}, /* byte 8 */ \
    /* Program download (CiA 302-3): the MCU image's side of its bootloader. */ \
    CO_PROGDL_TABLE \
    /* The PDO's bytes 5-8 as objects (the manual has none), \
     * manufacturer-specific indices no other product uses: the alarm word \
     * now (GSH_ALARM_*), the counter and the checksum of the last PDO sent \
     * (0 before the first). */ \
    {.index = 0x2110, .sub = 0, CO_TYPE_U16, .attr = RO | CO_A_PDO, CO_EXT(.read = gsh_read_alarm), CO_NAME("Alarm")}, \
    {.index = 0x2111, .sub = 0, CO_TYPE_U8, .attr = RO | CO_A_PDO, CO_EXT(.read = gsh_read_counter), CO_NAME("Counter")}, \
    {.index = 0x2112, .sub = 0, CO_TYPE_U8, .attr = RO | CO_A_PDO, CO_EXT(.read = gsh_read_checksum), CO_NAME("Checksum")}, \
    /* Bit rate 0..7 = 1000, 800, 500, 250, 125, 100, 50, 20 kbit/s; node-ID 1..127.
     * Both saved by 0x1010 and active after a reset (manual, section 13, \
     * example 1; decision: an NMT reset counts as the "sensor reset"). */ \
    {.index = 0x3000, .sub = 0, CO_TYPE_U8, .attr = RW, LSS(bitrate), .def = 3, CO_EXT(.min = 0, .max = 7), CO_NAME("Setting of the baud rate")}, \
    {.index = 0x3001, .sub = 0, CO_TYPE_U8, .attr = RW, LSS(node_id), .def = (node_id_default), CO_EXT(.min = 1, .max = 127), CO_NAME("Setting of the node-ID")}, \
    {.index = 0x5000, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(autostart), .def = 1, CO_EXT(.min = 0, .max = 1), CO_NAME("Automatic NMT start after power on")}, \
    {.index = 0x6000, .sub = 0, CO_TYPE_U16, .attr = RO, .def = 0, CO_NAME("Operating parameters")}, /* ro, as the table says */ \
    /* Position in 0x6005 steps (1 mm). UNSIGNED16, where the manual's \
     * 0x6004 row says "Unsigned32": its PDO text ("Byte 1 and 2 \
     * contain the length measurement ... unsigned integer 16-bit value") \
     * and its mapping length 0x10 (1A00h:01 = 60040010h) both say 16 bits, \
     * and the same type column calls 1A00h's 32-bit subs "Unsigned16" \
     * So a master decoding by the mapping and this type gets the \
     * manual's value; the bytes on the wire are the manual's either way. */ \
    {.index = 0x6004, .sub = 0, CO_TYPE_U16, .attr = RO | CO_A_PDO, CO_EXT(.read = gsh_read_position), CO_NAME("Position value")}, \
    {.index = 0x6005, .sub = 0, CO_TYPE_U32, .attr = RO, .def = 1000000u, CO_NAME("Position step setting")}, /* nm; sub 0, as the manual lists it */ \
    {.index = 0x67FF, .sub = 0, CO_TYPE_U32, .attr = RO, .def = 0x000A0196u, CO_NAME("Device type logical device 1")}, \
    {.index = 0x6800, .sub = 0, CO_TYPE_U16, .attr = RO, .def = 100, CO_NAME("Resolution")}, /* 0.1 deg */ \
    /* 0..3599: UNSIGNED16 as the manual says (CiA 410 has INTEGER16). */ \
    {.index = 0x6810, .sub = 0, CO_TYPE_U16, .attr = RO | CO_A_PDO, CO_EXT(.read = gsh_read_angle), CO_NAME("Slope long16")}, \
    {.index = 0x6811, .sub = 0, CO_TYPE_U8, .attr = RO, .def = 0, CO_NAME("Slope long16 operating parameter")}, \
    {.index = 0x6FFF, .sub = 0, CO_TYPE_U32, .attr = RO, .def = 0x0002019Au, CO_NAME("Device type logical device 2")} /* as printed; 0x019A: CiA 410 */

static const co_od_entry_t ch1_entries[] = {GSH_ENTRIES(0x13)};
static const co_od_entry_t ch2_entries[] = {GSH_ENTRIES(0x14)};
static const co_od_t ch1_od = {.entries = ch1_entries, .count = sizeof(ch1_entries) / sizeof(ch1_entries[0])};
static const co_od_t ch2_od = {.entries = ch2_entries, .count = sizeof(ch2_entries) / sizeof(ch2_entries[0])};

_Static_assert(sizeof(gsh_para_t) <= CO_STORE_MAX_DATA, "PARA set must fit one store slot");

/* Remote requests on the TPDO are answered: 0x1800 sub 1 has bit 30
 * clear (RTR allowed, CiA 301); the manual says nothing of RTR. The
 * answer is the fixed layout with the next counter (gsh_tpdo_fill). */
static const co_service_t *const gsh_services[] = {&co_rtr_service, NULL};

#define GSH_CFG(odp, id)                                                             \
    {.od = (odp), .ops = &gsh_ops, .led = NULL, .services = gsh_services,              \
     .sdo_segmented = co_sdo_segmented, .sdo_block = co_sdo_block,                     \
     .ram_size = {[CO_CLS_PARA] = sizeof(gsh_para_t), [CO_CLS_LSS] = sizeof(co_lss_para_t)}, \
     .default_node_id = (id), .default_bitrate = 3, .tpdo_dlc = 8,                     \
     .store_write_limit = 100000u /* manual, section 7 */,                             \
     .save_includes_lss = true /* the manual's example 1 saves 0x3001 */,              \
     .comm_reset_applies_id = true /* an NMT reset is a "sensor reset" */, .kbps = product_kbps_cia}
const co_node_cfg_t gsh_ch1_cfg = GSH_CFG(&ch1_od, 0x13);
const co_node_cfg_t gsh_ch2_cfg = GSH_CFG(&ch2_od, 0x14);

#define GSH_INPUTS                                                                       \
    {{"length", PRODUCT_TEXT("mm"), 0, 100000},                                          \
     {"angle", PRODUCT_TEXT("deg"), 0, PRODUCT_ANGLE_LIMIT},                                            \
     {"field", PRODUCT_TEXT("%"), 100000, 1000}}
#define GSH_FAULTS {PRODUCT_FAULT("extension-element"), PRODUCT_FAULT("tilt-element"), NULL, NULL}
#ifndef CO_OD_NO_NAMES
/* Where the manual asks the EDS to differ from the device (product_eds.h). */
static const product_eds_override_t gsh_eds_overrides[] = {
    /* The device keeps 100 ms; 0 written is accepted as "off". */
    {.index = 0x1800, .sub = 5, .value = 0,
     .reason = "GSH-A manual (0x1800 sub 5): \"In the EDS file this default value must be set to 0, "
               "otherwise errors will be generated.\""},
    /* Channel 1 0x13, channel 2 0x14 (manual, section 6): one EDS for both nodes. */
    {.index = 0x3001, .sub = 0, .value = 0, .nodeid = true,
     .reason = "0x13 on channel 1, 0x14 on channel 2 (GSH-A manual, 0x3001)"},
    {.index = 0},
};
#endif

const product_t gsh_a = {
    .id = PRODUCT_TEXT("gsh-a"),
    .summary = PRODUCT_TEXT("Gefran GSH-A draw-wire + tilt, node 0x13 (CiA 406 + 410)"),
    .inputs = GSH_INPUTS, .faults = GSH_FAULTS, .nodes = 1, .inst_size = sizeof(gsh_dev_t),
    .create = gsh_create, .sample = gsh_sample, .cfg = &gsh_ch1_cfg, .vendor = PRODUCT_TEXT("Gefran"),
    PRODUCT_EDS_OVERRIDES(gsh_eds_overrides)};
const product_t gsh_a_redundant = {
    .id = PRODUCT_TEXT("gsh-a-redundant"),
    .summary = PRODUCT_TEXT("Gefran GSH-A redundant: two nodes 0x13 + 0x14 (--iface A or A,B)"),
    .inputs = GSH_INPUTS, .faults = GSH_FAULTS, .nodes = 2, .inst_size = sizeof(gsh_dev_t),
    .create = gsh_create, .sample = gsh_sample, .cfg = &gsh_ch1_cfg, .vendor = PRODUCT_TEXT("Gefran"),
    PRODUCT_EDS_OVERRIDES(gsh_eds_overrides)};
/* clang-format on */
