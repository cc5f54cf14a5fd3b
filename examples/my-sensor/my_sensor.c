/*
 * my_sensor.c - my-incl's behaviour and dictionary (my_sensor.h): the
 * slope (0x6010) at 0.1 or 0.01 deg (0x6000), a preset (0x6012), TPDO1 on
 * a change of the slope and on its event timer, heartbeat, the store, and
 * EMCY 5000h while the sensing element fails.
 */
#include "my_sensor.h"

#include <string.h>

static my_dev_t *dev_of(co_node_t *n)
{
    return co_node_app(n);
}

/* 0x6010: the slope (co_incl.h). */
static co_res_t my_read_slope(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    (void)e;
    return co_incl_read(&dev_of(n)->incl, 0, v);
}

/* 0x6000: 0.1 deg (100) or 0.01 deg (10); nothing else. */
static co_res_t my_write_resolution(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    (void)e;
    if (v != 10u && v != 100u) {
        return CO_E_VAL;
    }
    if (co_od_checking(n)) { /* a restored set is being validated */
        return CO_OK;
    }
    return co_incl_set_resolution(&dev_of(n)->incl, (uint16_t)v);
}

/* 0x6012: the slope reads the preset from now on. */
static co_res_t my_write_preset(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    (void)e;
    if (!co_od_checking(n)) {
        co_incl_set_preset(&dev_of(n)->incl, 0, (int16_t)v);
    }
    return CO_OK;
}

static uint32_t my_poll(co_node_t *n, uint32_t now)
{
    (void)now;
    my_dev_t *d = dev_of(n);
    (void)co_emcy_error(n, 0x5000u, CO_ER_GENERIC, (d->faults & MY_FAULT_ELEMENT) != 0u, NULL);
    co_store_report_emcy(n); /* 6300h while the stored set was corrupt */
    return CO_NEVER;
}

static const co_node_ops_t my_ops = {.poll = my_poll};

static void my_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    my_dev_t *d = mem;
    memset(d, 0, sizeof(*d));
    d->last = INT32_MIN;
    co_incl_init(&d->incl, &d->para.incl, 1, 0, false);
    void *const ram[CO_CLS_COUNT] = {[CO_CLS_PARA] = &d->para};
    co_node_init(&d->node, p->cfg, ports[0], d, ram, 0);
    nodes[0] = &d->node;
}

/* One sample (millidegrees) every CO_FILTER_PERIOD_US. */
static void my_sample(void *mem, const int32_t values[], uint32_t faults)
{
    my_dev_t *d = mem;
    d->faults = faults;
    d->incl.fault = (faults & MY_FAULT_ELEMENT) != 0u;
    co_incl_sample(&d->incl, values);
    co_node_wake(&d->node);
    int16_t slope = co_incl_slope(&d->incl, 0);
    if (slope != d->last && co_node_nmt_state(&d->node) == CO_NMT_OPERATIONAL) {
        d->last = slope;
        co_tpdo_event(&d->node, 0);
    }
}

/* clang-format off */
#define PARA(f) CO_AT(CO_CLS_PARA, my_para_t, f)
#define CONST (CO_A_R | CO_A_CONST)

static const co_od_entry_t my_entries[] = {
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CONST, .def = 0x0001019Au, CO_NAME("Device type")}, /* CiA 410, one axis */
    {.index = 0x1001, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, CO_EXT(.read = co_emcy_read_register), CO_NAME("Error register")},
    {.index = 0x1010, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 1, CO_NAME("Store parameters")},
    {.index = 0x1010, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW, .def = 1, CO_EXT(.write = co_store_write_save), CO_NAME("Save all parameters")},
    {.index = 0x1011, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 1, CO_NAME("Restore default parameters")},
    {.index = 0x1011, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW, .def = 1, CO_EXT(.write = co_store_write_load), CO_NAME("Restore all default parameters")},
    {.index = 0x1017, .sub = 0, CO_TYPE_U16, .attr = CO_A_RW, PARA(hb_ms), .def = 1000, CO_EXT(.write = co_hb_write_time), CO_NAME("Producer heartbeat time")},
    {.index = 0x1018, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 4, CO_NAME("Identity object")},
    {.index = 0x1018, .sub = 1, CO_TYPE_U32, .attr = CONST, .def = 0, CO_NAME("Vendor-ID")},
    {.index = 0x1018, .sub = 2, CO_TYPE_U32, .attr = CONST, .def = 0x4D59u, CO_NAME("Product code")},
    {.index = 0x1018, .sub = 3, CO_TYPE_U32, .attr = CONST, .def = 0x00010000u, CO_NAME("Revision number")},
    {.index = 0x1018, .sub = 4, CO_TYPE_U32, .attr = CO_A_R | CO_A_SERIAL, .def = 0, CO_NAME("Serial number")},
    {.index = 0x1800, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 5, CO_NAME("TPDO1 communication parameter")},
    {.index = 0x1800, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW | CO_A_NODEID, PARA(tpdo_cobid), .def = 0x180, CO_EXT(.write = co_tpdo_write_cobid), CO_NAME("COB-ID TPDO1")},
    {.index = 0x1800, .sub = 2, CO_TYPE_U8, .attr = CO_A_RW, PARA(tx_type), .def = 254, CO_EXT(.write = co_tpdo_write_comm), CO_NAME("Transmission type")},
    {.index = 0x1800, .sub = 5, CO_TYPE_U16, .attr = CO_A_RW, PARA(event_ms), .def = 500, CO_EXT(.write = co_tpdo_write_comm), CO_NAME("Event timer")},
    {.index = 0x1A00, .sub = 0, CO_TYPE_U8, .attr = CONST, .def = 1, CO_NAME("TPDO1 mapping parameter")},
    {.index = 0x1A00, .sub = 1, CO_TYPE_U32, .attr = CONST, .def = 0x60100010u, CO_NAME("1st mapped object")},
    {.index = 0x6000, .sub = 0, CO_TYPE_U16, .attr = CO_A_RW, PARA(incl.resolution), .def = 10, CO_EXT(.write = my_write_resolution), CO_NAME("Resolution")},
    {.index = 0x6010, .sub = 0, CO_TYPE_I16, .attr = CO_A_R | CO_A_PDO, CO_EXT(.read = my_read_slope), CO_NAME("Slope long16")},
    {.index = 0x6012, .sub = 0, CO_TYPE_I16, .attr = CO_A_RW, PARA(incl.preset[0]), .def = 0, CO_EXT(.write = my_write_preset), CO_NAME("Slope long16 preset value")},
};

static const co_od_t my_od = {.entries = my_entries, .count = sizeof(my_entries) / sizeof(my_entries[0])};

_Static_assert(sizeof(my_para_t) <= CO_STORE_MAX_DATA, "PARA set must fit one store slot");

/* 250 kbit/s only (code 3 of the CiA table). */
static const uint16_t my_kbps[16] = {[3] = 250};

const co_node_cfg_t my_cfg = {
    .od = &my_od, .ops = &my_ops, .led = NULL,
    .services = NULL, .sdo_segmented = NULL, .sdo_block = NULL, /* expedited SDO only */
    .ram_size = {[CO_CLS_PARA] = sizeof(my_para_t)},
    .default_node_id = 0x21, .default_bitrate = 3,
    .kbps = my_kbps,
};

const product_t my_incl = {
    .id = PRODUCT_TEXT("my-incl"), .summary = PRODUCT_TEXT("example: one-axis inclinometer"),
    .inputs = {{"x", PRODUCT_TEXT("deg"), 0, PRODUCT_ANGLE_LIMIT}},
    .faults = {PRODUCT_FAULT("element"), NULL},
    .nodes = 1, .inst_size = sizeof(my_dev_t), .create = my_create, .sample = my_sample,
    .variant = NULL, .cfg = &my_cfg, .vendor = PRODUCT_TEXT("(example)")};
/* clang-format on */
