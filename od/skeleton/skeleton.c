/*
 * skeleton.c - the template family's behaviour and dictionary (skeleton.h).
 *
 * A real family cites its manual (title and section or table) on every
 * line that follows it, marks a CiA default the manual does not give
 * ([301]) and writes "Decision: ... because ..." where the manual is silent.
 * Here the choices are CiA 301 / CiA 410 defaults throughout.
 */
#include "skeleton.h"
#include "co_progdl.h"

#include <string.h>

static skel_dev_t *dev_of(co_node_t *n)
{
    return co_node_app(n);
}

/* ---- behaviour ------------------------------------------------------- */

/* 0x6010: the slope, from the CiA 410 module (co_incl.h). */
static co_res_t skel_read_slope(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    (void)e;
    return co_incl_read(&dev_of(n)->incl, 0, v);
}

/* 0x6000: the resolutions CiA 410 lists, taken while scaling is on; the
 * module clears the presets. The module asks both axes' operating
 * parameters for the scaling bit (a one-axis product may have 0x6021 too);
 * this one has no 0x6021: its one axis' bit stands for both. */
static co_res_t skel_write_resolution(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    (void)e;
    if (v != 1u && v != 10u && v != 100u && v != 1000u) {
        return CO_E_VAL;
    }
    if (co_od_checking(n)) { /* a restored set is being validated: act on nothing */
        return CO_OK;
    }
    skel_dev_t *d = dev_of(n);
    d->para.incl.op[1] = d->para.incl.op[0];
    return co_incl_set_resolution(&d->incl, (uint16_t)v);
}

/* 0x6012: the output equals the preset from now on (CiA 410). */
static co_res_t skel_write_preset(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    (void)e;
    if (!co_od_checking(n)) {
        co_incl_set_preset(&dev_of(n)->incl, 0, (int16_t)v);
    }
    return CO_OK;
}

/* The product's work after the stack's: raise or clear its errors. */
static uint32_t skel_poll(co_node_t *n, uint32_t now)
{
    (void)now;
    skel_dev_t *d = dev_of(n);
    /* EMCY 5000h "device hardware" while the sensor element fails (its
     * outputs hold: co_incl_t.fault); the error register's generic bit. */
    (void)co_emcy_error(n, 0x5000u, CO_ER_GENERIC, (d->faults & SKEL_FAULT_SENSOR) != 0u, NULL);
    co_store_report_emcy(n); /* 6300h while the stored set was corrupt */
    return CO_NEVER;
}

static const co_node_ops_t skel_ops = {.poll = skel_poll};

/* Build the instance: the node runs the product's own config (p->cfg), so
 * that each product of a family may have its table. */
static void skel_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    skel_dev_t *d = mem;
    memset(d, 0, sizeof(*d));
    d->sent = INT32_MIN;
    co_incl_init(&d->incl, &d->para.incl, 1, 0, false);
    d->incl.shift = 0; /* no filter: one sample, one output */
    void *const ram[CO_CLS_COUNT] = {[CO_CLS_PARA] = &d->para};
    co_node_init(&d->node, p->cfg, ports[0], d, ram, 0);
    nodes[0] = &d->node;
}

/* One sensor sample (millidegrees), every CO_FILTER_PERIOD_US. */
static void skel_sample(void *mem, const int32_t values[], uint32_t faults)
{
    skel_dev_t *d = mem;
    d->faults = faults;
    d->incl.fault = (faults & SKEL_FAULT_SENSOR) != 0u;
    co_incl_sample(&d->incl, values);
    co_node_wake(&d->node); /* the poll hook looks at the faults */
    /* Transmission types 254/255: an event when the slope changes (CiA
     * 301's application event), not on every sample (200 a second of one
     * value); the event timer (1800h:05) sends it cyclically besides. An
     * event counts once the node is operational, where it is sent. */
    int16_t slope = co_incl_slope(&d->incl, 0);
    if (slope != d->sent && co_node_nmt_state(&d->node) == CO_NMT_OPERATIONAL) {
        d->sent = slope;
        co_tpdo_event(&d->node, 0);
    }
}

/* clang-format off */
/* ---- dictionary (sorted by index, sub-index) -------------------------- */

#define RO (CO_A_R)
#define RW (CO_A_RW)
#define CONST (CO_A_R | CO_A_CONST)
#define PARA(f) CO_AT(CO_CLS_PARA, skel_para_t, f)

static const co_od_entry_t skel_entries[] = {
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CONST, .def = 0x0000019Au, CO_NAME("Device type")}, /* CiA 410 */
    {.index = 0x1001, .sub = 0, CO_TYPE_U8, .attr = RO, CO_EXT(.read = co_emcy_read_register), CO_NAME("Error register")},
    {.index = 0x1010, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 1, CO_NAME("Store parameters")},
    {.index = 0x1010, .sub = 1, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_save), CO_NAME("Save all parameters")},
    {.index = 0x1011, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 1, CO_NAME("Restore default parameters")},
    {.index = 0x1011, .sub = 1, CO_TYPE_U32, .attr = RW, .def = 1, CO_EXT(.write = co_store_write_load), CO_NAME("Restore all default parameters")},
    {.index = 0x1017, .sub = 0, CO_TYPE_U16, .attr = RW, PARA(hb_ms), .def = 0, CO_EXT(.write = co_hb_write_time), CO_NAME("Producer heartbeat time")},
    {.index = 0x1018, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 4, CO_NAME("Identity object")},
    {.index = 0x1018, .sub = 1, CO_TYPE_U32, .attr = CONST, .def = 0, CO_NAME("Vendor-ID")}, /* the vendor's CiA ID */
    {.index = 0x1018, .sub = 2, CO_TYPE_U32, .attr = CONST, .def = 1, CO_NAME("Product code")},
    {.index = 0x1018, .sub = 3, CO_TYPE_U32, .attr = CONST, .def = 0x00010000u, CO_NAME("Revision number")},
    {.index = 0x1018, .sub = 4, CO_TYPE_U32, .attr = RO | CO_A_SERIAL, .def = 0, CO_NAME("Serial number")}, /* per unit: co_node_set_serial */
    {.index = 0x1800, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 5, CO_NAME("TPDO1 communication parameter")},
    {.index = 0x1800, .sub = 1, CO_TYPE_U32, .attr = RW | CO_A_NODEID, PARA(tpdo_cobid), .def = 0x180, CO_EXT(.write = co_tpdo_write_cobid), CO_NAME("COB-ID TPDO1")},
    {.index = 0x1800, .sub = 2, CO_TYPE_U8, .attr = RW, PARA(tx_type), .def = 254, CO_EXT(.write = co_tpdo_write_comm), CO_NAME("Transmission type")},
    {.index = 0x1800, .sub = 5, CO_TYPE_U16, .attr = RW, PARA(event_ms), .def = 0, CO_EXT(.write = co_tpdo_write_comm), CO_NAME("Event timer")},
    {.index = 0x1A00, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 1, CO_NAME("TPDO1 mapping parameter")},
    {.index = 0x1A00, .sub = 1, CO_TYPE_U32, .attr = CONST, .def = 0x60100010u, CO_NAME("1st mapped object")},
    CO_PROGDL_TABLE /* program download: the MCU image's side (co_progdl.h) */
    {.index = 0x6000, .sub = 0, CO_TYPE_U16, .attr = RW, PARA(incl.resolution), .def = 10, CO_EXT(.write = skel_write_resolution), CO_NAME("Resolution")}, /* 0.01 deg */
    {.index = 0x6010, .sub = 0, CO_TYPE_I16, .attr = RO | CO_A_PDO, CO_EXT(.read = skel_read_slope), CO_NAME("Slope long16")},
    {.index = 0x6011, .sub = 0, CO_TYPE_U8, .attr = RW, PARA(incl.op[0]), .def = 0, CO_EXT(.min = 0, .max = 3), CO_NAME("Slope long16 operating parameter")},
    {.index = 0x6012, .sub = 0, CO_TYPE_I16, .attr = RW, PARA(incl.preset[0]), .def = 0, CO_EXT(.write = skel_write_preset), CO_NAME("Slope long16 preset value")},
    {.index = 0x6013, .sub = 0, CO_TYPE_I16, .attr = RW, PARA(incl.offset[0]), .def = 0, CO_NAME("Slope long16 offset")},
    {.index = 0x6014, .sub = 0, CO_TYPE_I16, .attr = RW, PARA(incl.diff[0]), .def = 0, CO_NAME("Differential slope long16 offset")},
};

static const co_od_t skel_od = {.entries = skel_entries, .count = sizeof(skel_entries) / sizeof(skel_entries[0])};

_Static_assert(sizeof(skel_para_t) <= CO_STORE_MAX_DATA, "PARA set must fit one store slot");

/* Its bit rates (kbit/s by code): 250 only, code 3 as in the CiA table
 * (product_kbps_cia), since nothing here changes the code. A family
 * whose node-ID/bit-rate objects or LSS select others lists them, or
 * takes a manual's table of od/bitrates.c; the EDS declares the rates
 * listed (product_eds_bitrates). */
static const uint16_t skel_kbps[16] = {[3] = 250};

/* The node config: what the stack needs to know of the product. */
const co_node_cfg_t skel_cfg = {
    .od = &skel_od, .ops = &skel_ops, .led = NULL /* CiA 303-3 LEDs */,
    .services = NULL /* no guarding, no LSS, no RTR: core services only */,
    .sdo_segmented = NULL, .sdo_block = NULL, /* every object fits an expedited transfer */
    .ram_size = {[CO_CLS_PARA] = sizeof(skel_para_t)},
    .default_node_id = 0x20, .default_bitrate = 3,
    .kbps = skel_kbps,
};

/* The registry row: what the boards need to know of the product. */
const product_t skel_incl = {
    .id = PRODUCT_TEXT("skeleton-incl"), .summary = PRODUCT_TEXT("template: one-axis CiA 410 inclinometer (not a device)"),
    .inputs = {{"x", PRODUCT_TEXT("deg"), 0, PRODUCT_ANGLE_LIMIT}},
    .faults = {PRODUCT_FAULT("sensor"), NULL},
    .nodes = 1, .inst_size = sizeof(skel_dev_t), .create = skel_create, .sample = skel_sample,
    .variant = NULL, .cfg = &skel_cfg, .vendor = PRODUCT_TEXT("(template)")};
/* clang-format on */
