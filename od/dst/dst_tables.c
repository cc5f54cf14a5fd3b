/*
 * dst_tables.c - the dictionaries of the Danfoss DST X730 ("top level") and
 * DST X710 ("entry level") inclination sensors: one list, DST_ENTRIES, with
 * the X710's differences from the X730 marked where they are.
 * After the DST X730 and DST X710 operating guides: the table of each
 * (section 12 'CANopen features summary') and its communication examples
 * (section 15 of the X730's, 14 of the X710's). Where the manual
 * contradicts itself, the line says which reading is taken. Behaviour is
 * the family's (dst.c).
 *
 * The table must stay sorted by (index, sub-index).
 */
#include "co_progdl.h"
#include "dst.h"
/* clang-format off */

#define RO (CO_A_R)
#define RW (CO_A_RW)
#define CONST (CO_A_R | CO_A_CONST)
#define PARA(f) CO_AT(CO_CLS_PARA, dst_para_t, f)
#define VOL(f) CO_AT(CO_CLS_VOL, dst_vol_t, f)

/* In DST_ENTRIES(model), model X730 or X710: X730_ONLY(model, ...) is its
 * arguments in the X730's table and nothing in the X710's; X710_ONLY the
 * other way round (an entry, with its comma, or a value). */
#define DST_ONLY_X730_X730(...) __VA_ARGS__
#define DST_ONLY_X730_X710(...)
#define DST_ONLY_X710_X730(...)
#define DST_ONLY_X710_X710(...) __VA_ARGS__
#define X730_ONLY(model, ...) DST_ONLY_X730_##model(__VA_ARGS__)
#define X710_ONLY(model, ...) DST_ONLY_X710_##model(__VA_ARGS__)

/* The X730's dictionary; with model X710 the X710's (its table differs in
 * 0x100A, 0x1800 sub 3 and has no 0x5001; everything else identical). */
#define DST_ENTRIES(model) \
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CONST, .def = 0x0008019Au, CO_NAME("Device type")}, \
    /* "Always ZERO", also inside the EMCY frame (sections 9 and 12). */ \
    {.index = 0x1001, .sub = 0, CO_TYPE_U8, .attr = RO, .def = 0, CO_NAME("Error register")}, \
    /* Not in the manual, which lists SYNC transmission types (0x1800 sub \
     * 2: 1..240 "after n synch objects"): CiA 301's COB-ID SYNC, so that a \
     * master reads the SYNC the TPDO follows. Constant 0x80: a writable one \
     * (0x1005 as the JD and P+F have it) cost 88 more bytes of flash than \
     * the X730 image has below its 10 KB target. */ \
    {.index = 0x1005, .sub = 0, CO_TYPE_U32, .attr = CONST, .def = 0x80, CO_NAME("COB-ID SYNC")}, \
    {.index = 0x1008, .sub = 0, CO_TYPE_STR("GIB"), .attr = CONST, CO_NAME("Manufacturer device name")}, \
    {.index = 0x1009, .sub = 0, CO_TYPE_STR("1.00"), .attr = CONST, CO_NAME("Manufacturer hardware version")}, \
    /* X710: "1.10" (its table). */ \
    {.index = 0x100A, .sub = 0, CO_TYPE_STR(X730_ONLY(model, "1.24") X710_ONLY(model, "1.10")), .attr = CONST, CO_NAME("Manufacturer software version")}, \
    {.index = 0x1010, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 1, CO_NAME("Store parameters")}, \
    /* The manual's table says wo and prints no read of it: CiA 301's rw, \
     * a read answers the storage capability, 1 = saves on command. */ \
    {.index = 0x1010, .sub = 1, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_save), CO_NAME("Save all parameters")}, \
    {.index = 0x1011, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 1, CO_NAME("Restore default parameters")}, \
    /* rw, reads 1 = "restores on command": the table's rw and CiA 301's, \
     * where example 11 says wo (and names the object 1001h). */ \
    {.index = 0x1011, .sub = 1, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_load), CO_NAME("Restore all default parameters")}, \
    {.index = 0x1014, .sub = 0, CO_TYPE_U32, .attr = RW | CO_A_NODEID, PARA(emcy_cobid), .def = 0x80, CO_EXT(.write = dst_write_emcy_cobid), CO_NAME("COB-ID EMCY")}, \
    /* 0 or 20..65535 ms; 1..19 "NOT ACCEPTED". */ \
    {.index = 0x1017, .sub = 0, CO_TYPE_U16, .attr = RW, PARA(hb_ms), .def = 0, CO_EXT(.write = dst_write_hb), CO_NAME("Producer heartbeat time")}, \
    {.index = 0x1018, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 4, CO_NAME("Identity object")}, \
    {.index = 0x1018, .sub = 1, CO_TYPE_U32, .attr = CONST, .def = 0x00000093u, CO_NAME("Vendor-ID")}, \
    {.index = 0x1018, .sub = 2, CO_TYPE_U32, .attr = CONST, .def = 0x00000064u, CO_NAME("Product code")}, \
    {.index = 0x1018, .sub = 3, CO_TYPE_U32, .attr = CONST, .def = 0x00000001u, CO_NAME("Revision number")}, \
    /* Per unit: the board's (co_node_set_serial), from the chip's ID. */ \
    {.index = 0x1018, .sub = 4, CO_TYPE_U32, .attr = RO | CO_A_SERIAL, .def = 0x00000000u, CO_NAME("Serial number")}, \
    {.index = 0x1200, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 2, CO_NAME("SDO server parameter")}, \
    {.index = 0x1200, .sub = 1, CO_TYPE_U32, .attr = RO | CO_A_NODEID, .def = 0x600, CO_NAME("COB-ID client to server")}, \
    {.index = 0x1200, .sub = 2, CO_TYPE_U32, .attr = RO | CO_A_NODEID, .def = 0x580, CO_NAME("COB-ID server to client")}, \
    /* Highest sub-index 5 (the table gives none); sub 4 (reserved, CiA \
     * 301) does not exist. */ \
    {.index = 0x1800, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 5, CO_NAME("TPDO1 communication parameter")}, \
    /* 0x180 + node-ID as the manual prints it, with bit 30 set: no RTR \
     * (CiA 301). The manual says nothing of remote requests, and answering \
     * them cost 268 bytes of flash the X730 image does not have below its \
     * 10 KB target; a master is not told of a service that is absent. */ \
    {.index = 0x1800, .sub = 1, CO_TYPE_U32, .attr = RO | CO_A_NODEID, .def = 0x40000180u, CO_NAME("COB-ID TPDO1")}, \
    {.index = 0x1800, .sub = 2, CO_TYPE_U8, .attr = RW, PARA(tx_type), .def = 254, CO_EXT(.write = dst_write_tx_type), CO_NAME("Transmission type")}, \
    /* X730: ro, 0, as Example 3 (its only source) prints it. X710: as its \
     * main table, rw, default 4, 4..65535, unit 1 ms (its Example 3 says \
     * ro 0 too; dst_x710_cfg's inhibit_unit_us). */ \
    X730_ONLY(model, {.index = 0x1800, .sub = 3, CO_TYPE_U16, .attr = RO, .def = 0, CO_NAME("Inhibit time")},) \
    X710_ONLY(model, {.index = 0x1800, .sub = 3, CO_TYPE_U16, .attr = RW, PARA(inhibit_ms), .def = 4, CO_EXT(.min = 4, .max = 65535, .write = co_tpdo_write_comm), CO_NAME("Inhibit time")},) \
    /* 0 = inactive (examples 12, 13), 4..65535 ms; default 100 = 0x64 \
     * (the table's "0x65" is a misprint: example 3 says 0x64). */ \
    {.index = 0x1800, .sub = 5, CO_TYPE_U16, .attr = RW, PARA(event_ms), .def = 100, CO_EXT(.write = dst_write_event), CO_NAME("Event timer")}, \
    /* The manual's table prints 2 entries (4 bytes) for its 8-byte frame; \
     * 3 here: sub 3 maps the "(0x00)" the manual's TPDO tables print \
     * in bytes 5-8 (0x2100 below), so that the mapping covers every byte \
     * sent and a CiA 301 consumer that checks the length against it (EMCY \
     * 8220h) sees none. The bytes on the wire are the manual's. */ \
    {.index = 0x1A00, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 3, CO_NAME("TPDO1 mapping parameter")}, \
    {.index = 0x1A00, .sub = 1, CO_TYPE_U32, .attr = CONST, .def = 0x60100010u, CO_NAME("1st mapped object")}, \
    /* The manual prints 0x60200020; 0x6020 is 16 bits (bytes 3-4). */ \
    {.index = 0x1A00, .sub = 2, CO_TYPE_U32, .attr = CONST, .def = 0x60200010u, CO_NAME("2nd mapped object")}, \
    {.index = 0x1A00, .sub = 3, CO_TYPE_U32, .attr = CONST, .def = 0x21000020u, CO_NAME("3rd mapped object")}, \
    /* Program download (CiA 302-3): the MCU image's side of its bootloader. */ \
    CO_PROGDL_TABLE \
    /* 0 slow, 1 medium, 2 fast; active after "save". Default 0 as the \
     * table says (example 10 starts from 2). */ \
    {.index = 0x2001, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(filter), .def = 0, CO_EXT(.min = 0, .max = 2), CO_NAME("Filter setting")}, \
    {.index = 0x20F0, .sub = 0, CO_TYPE_U8, .attr = RW, VOL(id[0]), .def = 0x7F, CO_EXT(.min = 1, .max = 127, .write = dst_write_id), CO_NAME("Node-ID setting copy 1")}, \
    {.index = 0x20F1, .sub = 0, CO_TYPE_U8, .attr = RW, VOL(id[1]), .def = 0x7F, CO_EXT(.min = 1, .max = 127, .write = dst_write_id), CO_NAME("Node-ID setting copy 2")}, \
    /* 0 1000k, 1 800k, 2 500k, 3 250k, 4 125k, 5 100k, 6 50k, 7 20k. */ \
    {.index = 0x20F2, .sub = 0, CO_TYPE_U8, .attr = RW, VOL(br[0]), .def = 3, CO_EXT(.min = 0, .max = 7, .write = dst_write_bitrate), CO_NAME("Bit rate setting copy 1")}, \
    {.index = 0x20F3, .sub = 0, CO_TYPE_U8, .attr = RW, VOL(br[1]), .def = 3, CO_EXT(.min = 0, .max = 7, .write = dst_write_bitrate), CO_NAME("Bit rate setting copy 2")}, \
    /* TPDO1 bytes 5-8, "(0x00)" in the manual (its Z-360 table: bytes 3-8, \
     * 0x6020 reading 0 there); an object of its own so that the mapping \
     * can name them (sub 3 above). A manufacturer-specific index no \
     * product uses. */ \
    {.index = 0x2100, .sub = 0, CO_TYPE_U32, .attr = CONST | CO_A_PDO, .def = 0, CO_NAME("TPDO1 bytes 5-8 (0x00)")}, \
    /* 0 pre-operational, 1 no change, 2 stopped; 3..255 accepted as 1. */ \
    {.index = 0x4000, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(err_behaviour), .def = 1, CO_NAME("Error behaviour")}, \
    {.index = 0x4001, .sub = 0, CO_TYPE_U8, .attr = RO, CO_EXT(.read = dst_read_errors), CO_NAME("Error code")}, \
    {.index = 0x5000, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(autostart), .def = 0, CO_EXT(.min = 0, .max = 1), CO_NAME("Automatic NMT start")}, \
    /* X730 only: the X710 has no 0x5001, its PDOs are always little-endian \
     * (its manual; dst.c reads the entry's presence). */ \
    X730_ONLY(model, {.index = 0x5001, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(pdo_coding), .def = 1, CO_EXT(.min = 0, .max = 1, .write = dst_write_coding), CO_NAME("PDO coding")},) \
    /* 10, 50, 100, 500, 1000 (x 0.001 deg); needs scaling on both axes. */ \
    {.index = 0x6000, .sub = 0, CO_TYPE_U16, .attr = RW, PARA(incl.resolution), .def = 50, CO_EXT(.write = dst_write_resolution), CO_NAME("Resolution")}, \
    {.index = 0x6010, .sub = 0, CO_TYPE_I16, .attr = RO | CO_A_PDO, CO_EXT(.read = dst_read_slope), CO_NAME("Slope longitudinal")}, \
    /* bit0 invert, bit1 scaling; default 0x02 (example 8; example 9 \
     * changes the resolution from the factory state, which needs bit1). */ \
    {.index = 0x6011, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(incl.op[0]), .def = 0x02, CO_EXT(.min = 0, .max = 3), CO_NAME("Slope longitudinal operating parameter")}, \
    {.index = 0x6012, .sub = 0, CO_TYPE_I16, .attr = RW, PARA(incl.preset[0]), .def = 0, CO_EXT(.write = dst_write_preset), CO_NAME("Slope longitudinal preset value")}, \
    {.index = 0x6013, .sub = 0, CO_TYPE_I16, .attr = RO, PARA(incl.offset[0]), .def = 0, CO_NAME("Slope longitudinal offset")}, \
    {.index = 0x6014, .sub = 0, CO_TYPE_I16, .attr = RW, PARA(incl.diff[0]), .def = 0, CO_NAME("Differential slope longitudinal offset")}, \
    {.index = 0x6020, .sub = 0, CO_TYPE_I16, .attr = RO | CO_A_PDO, CO_EXT(.read = dst_read_slope), CO_NAME("Slope lateral")}, \
    {.index = 0x6021, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(incl.op[1]), .def = 0x02, CO_EXT(.min = 0, .max = 3), CO_NAME("Slope lateral operating parameter")}, \
    {.index = 0x6022, .sub = 0, CO_TYPE_I16, .attr = RW, PARA(incl.preset[1]), .def = 0, CO_EXT(.write = dst_write_preset), CO_NAME("Slope lateral preset value")}, \
    {.index = 0x6023, .sub = 0, CO_TYPE_I16, .attr = RO, PARA(incl.offset[1]), .def = 0, CO_NAME("Slope lateral offset")}, \
    {.index = 0x6024, .sub = 0, CO_TYPE_I16, .attr = RW, PARA(incl.diff[1]), .def = 0, CO_NAME("Differential slope lateral offset")},

static const co_od_entry_t x730_entries[] = {DST_ENTRIES(X730)};
static const co_od_entry_t x710_entries[] = {DST_ENTRIES(X710)};

static const co_od_t x730_od = {
    .entries = x730_entries,
    .count = (uint16_t)(sizeof(x730_entries) / sizeof(x730_entries[0])),
};
static const co_od_t x710_od = {
    .entries = x710_entries,
    .count = (uint16_t)(sizeof(x710_entries) / sizeof(x710_entries[0])),
};

_Static_assert(sizeof(dst_para_t) <= CO_STORE_MAX_DATA, "PARA set must fit one store slot");
_Static_assert(sizeof(co_lss_para_t) <= CO_STORE_MAX_DATA, "LSS set must fit one store slot");

/* A model's node config: its dictionary, then what differs. Both MCU
 * images fix one of these two symbols (od/dst/family.cmake). */
#define DST_CFG(odp, ...)                                                                    \
    {.od = (odp), .ops = &dst_ops,                                                           \
     /* No SDO block transfer: the manual's SDO section (10) has only expedited transfer. */ \
     .ram_size = {[CO_CLS_VOL] = sizeof(dst_vol_t), [CO_CLS_PARA] = sizeof(dst_para_t),       \
                  [CO_CLS_LSS] = sizeof(co_lss_para_t)},                                     \
     .default_node_id = 0x7F, .default_bitrate = 3 /* 250 kbit/s */,                        \
     .kbps = product_kbps_cia, .tpdo_dlc = 8 /* the manual's frames are always 8 bytes */, \
     .store_write_limit = DST_WRITE_LIMIT, __VA_ARGS__}
const co_node_cfg_t dst_x730_cfg = DST_CFG(&x730_od, .led = &dst_led);
/* X710: the manual describes no LED (CiA 303-3 patterns); the inhibit time
 * in "unit 1 ms" as its table prints it. */
const co_node_cfg_t dst_x710_cfg = DST_CFG(&x710_od, .led = NULL, .inhibit_unit_us = 1000);

/* Error limits: 110 % of the range, but +-87 deg on the +-90 variant (section 9);
 * the same on both models. */
#define XY(cfgp, lim) {.cfg = (cfgp), .axes = 2, .wrap = false, .limit_mdeg = (lim)}
#define Z360(cfgp) {.cfg = (cfgp), .axes = 1, .wrap = true, .limit_mdeg = 0}
static const dst_variant_t x730_xy10 = XY(&dst_x730_cfg, DST_LIMIT_XY10),
                           x730_xy15 = XY(&dst_x730_cfg, DST_LIMIT_XY15),
                           x730_xy20 = XY(&dst_x730_cfg, DST_LIMIT_XY20),
                           x730_xy30 = XY(&dst_x730_cfg, DST_LIMIT_XY30),
                           x730_xy45 = XY(&dst_x730_cfg, DST_LIMIT_XY45),
                           x730_xy60 = XY(&dst_x730_cfg, DST_LIMIT_XY60),
                           x730_xy90 = XY(&dst_x730_cfg, DST_LIMIT_XY90),
                           x730_z360 = Z360(&dst_x730_cfg);
static const dst_variant_t x710_xy10 = XY(&dst_x710_cfg, DST_LIMIT_XY10),
                           x710_xy15 = XY(&dst_x710_cfg, DST_LIMIT_XY15),
                           x710_xy20 = XY(&dst_x710_cfg, DST_LIMIT_XY20),
                           x710_xy30 = XY(&dst_x710_cfg, DST_LIMIT_XY30),
                           x710_xy45 = XY(&dst_x710_cfg, DST_LIMIT_XY45),
                           x710_xy60 = XY(&dst_x710_cfg, DST_LIMIT_XY60),
                           x710_xy90 = XY(&dst_x710_cfg, DST_LIMIT_XY90),
                           x710_z360 = Z360(&dst_x710_cfg);

DST_PRODUCT(dst_x730_xy10, "dst-x730-xy10", "Danfoss DST X730 dual axis +-10 deg (CiA 410)", x730_xy10, DST_XY_INPUTS, &dst_x730_cfg);
DST_PRODUCT(dst_x730_xy15, "dst-x730-xy15", "Danfoss DST X730 dual axis +-15 deg (CiA 410)", x730_xy15, DST_XY_INPUTS, &dst_x730_cfg);
DST_PRODUCT(dst_x730_xy20, "dst-x730-xy20", "Danfoss DST X730 dual axis +-20 deg (CiA 410)", x730_xy20, DST_XY_INPUTS, &dst_x730_cfg);
DST_PRODUCT(dst_x730_xy30, "dst-x730-xy30", "Danfoss DST X730 dual axis +-30 deg (CiA 410)", x730_xy30, DST_XY_INPUTS, &dst_x730_cfg);
DST_PRODUCT(dst_x730_xy45, "dst-x730-xy45", "Danfoss DST X730 dual axis +-45 deg (CiA 410)", x730_xy45, DST_XY_INPUTS, &dst_x730_cfg);
DST_PRODUCT(dst_x730_xy60, "dst-x730-xy60", "Danfoss DST X730 dual axis +-60 deg (CiA 410)", x730_xy60, DST_XY_INPUTS, &dst_x730_cfg);
DST_PRODUCT(dst_x730_xy90, "dst-x730-xy90", "Danfoss DST X730 dual axis +-90 deg, stops at +-87 (CiA 410)", x730_xy90, DST_XY_INPUTS, &dst_x730_cfg);
DST_PRODUCT(dst_x730_z360, "dst-x730-z360", "Danfoss DST X730 single axis Z, -180..+180 deg (CiA 410)", x730_z360, DST_Z_INPUTS, &dst_x730_cfg);
DST_PRODUCT(dst_x710_xy10, "dst-x710-xy10", "Danfoss DST X710 dual axis +-10 deg (CiA 410)", x710_xy10, DST_XY_INPUTS, &dst_x710_cfg);
DST_PRODUCT(dst_x710_xy15, "dst-x710-xy15", "Danfoss DST X710 dual axis +-15 deg (CiA 410)", x710_xy15, DST_XY_INPUTS, &dst_x710_cfg);
DST_PRODUCT(dst_x710_xy20, "dst-x710-xy20", "Danfoss DST X710 dual axis +-20 deg (CiA 410)", x710_xy20, DST_XY_INPUTS, &dst_x710_cfg);
DST_PRODUCT(dst_x710_xy30, "dst-x710-xy30", "Danfoss DST X710 dual axis +-30 deg (CiA 410)", x710_xy30, DST_XY_INPUTS, &dst_x710_cfg);
DST_PRODUCT(dst_x710_xy45, "dst-x710-xy45", "Danfoss DST X710 dual axis +-45 deg (CiA 410)", x710_xy45, DST_XY_INPUTS, &dst_x710_cfg);
DST_PRODUCT(dst_x710_xy60, "dst-x710-xy60", "Danfoss DST X710 dual axis +-60 deg (CiA 410)", x710_xy60, DST_XY_INPUTS, &dst_x710_cfg);
DST_PRODUCT(dst_x710_xy90, "dst-x710-xy90", "Danfoss DST X710 dual axis +-90 deg, stops at +-87 (CiA 410)", x710_xy90, DST_XY_INPUTS, &dst_x710_cfg);
DST_PRODUCT(dst_x710_z360, "dst-x710-z360", "Danfoss DST X710 single axis Z, -180..+180 deg (CiA 410)", x710_z360, DST_Z_INPUTS, &dst_x710_cfg);
/* clang-format on */
