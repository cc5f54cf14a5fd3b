/*
 * test_node_services.c - the optional services and the node object on a
 * test dictionary: LSS (CiA 305) storing its node-ID in the stack's own
 * LSS set (no product hook), its refusals and Fastscan's ignored requests;
 * life guarding and the heartbeat consumer (CiA 301 7.2.8.3) and how their
 * event is cleared; a late heartbeat; the NMT state hook; the CiA 303-3 LED
 * mapping; TPDO mappings too long for 8 bytes; a full EMCY error table; the
 * EMCY COB-ID's bits. Frame by frame, on a virtual clock.
 */
#include "harness.h"

#include "co_store.h"

typedef struct n_para {
    uint32_t sync_cob;
    uint32_t emcy_cob;
    uint32_t hbc;
    uint16_t guard_ms;
    uint16_t hb;
    uint8_t life;
    uint8_t map0_count;
    uint8_t map1_count;
    uint8_t type[2];
    uint16_t event0;
    uint32_t cob[2];
    uint32_t map0[3];
    uint32_t map1[3];
    uint16_t c;
} n_para_t;

typedef struct n_vol {
    uint32_t a;
    uint16_t b;
    uint16_t emcy_inhibit;
} n_vol_t;

typedef struct n_dev {
    co_node_t node;
    n_para_t para;
    n_vol_t vol;
    co_lss_para_t lss;
    unsigned state_calls;
    co_nmt_state_t last_old;
    bool start_once; /* the reset hook asks for one automatic start */
} n_dev_t;

#define P(f) CO_AT(CO_CLS_PARA, n_para_t, f)
#define V(f) CO_AT(CO_CLS_VOL, n_vol_t, f)
#define TPW CO_EXT(.write = co_tpdo_write_comm)
#define MAPW CO_EXT(.write = co_tpdo_write_map)
#define COBW CO_EXT(.write = co_tpdo_write_cobid)

/* clang-format off */
static const co_od_entry_t n_entries[] = {
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_CONST, .def = 0x0000019Au},
    {.index = 0x1001, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, CO_EXT(.read = co_emcy_read_register)},
    {.index = 0x1005, .sub = 0, CO_TYPE_U32, .attr = CO_A_RW, P(sync_cob), .def = 0x80, CO_EXT(.write = co_sync_write_cobid)},
    {.index = 0x100C, .sub = 0, CO_TYPE_U16, .attr = CO_A_RW, P(guard_ms), .def = 0},
    {.index = 0x100D, .sub = 0, CO_TYPE_U8, .attr = CO_A_RW, P(life), .def = 0},
    {.index = 0x1014, .sub = 0, CO_TYPE_U32, .attr = CO_A_RW | CO_A_NODEID, P(emcy_cob), .def = 0x80, CO_EXT(.write = co_emcy_write_cobid)},
    {.index = 0x1015, .sub = 0, CO_TYPE_U16, .attr = CO_A_RW, V(emcy_inhibit), .def = 0},
    {.index = 0x1016, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 1},
    {.index = 0x1016, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW, P(hbc), .def = 0, CO_EXT(.write = co_hbc_write_time)},
    {.index = 0x1017, .sub = 0, CO_TYPE_U16, .attr = CO_A_RW, P(hb), .def = 0, CO_EXT(.write = co_hb_write_time)},
    {.index = 0x1018, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 4},
    {.index = 0x1018, .sub = 1, CO_TYPE_U32, .attr = CO_A_R | CO_A_CONST, .def = 0x12345678u},
    {.index = 0x1018, .sub = 2, CO_TYPE_U32, .attr = CO_A_R | CO_A_CONST, .def = 0x0000ABCDu},
    {.index = 0x1018, .sub = 3, CO_TYPE_U32, .attr = CO_A_R | CO_A_CONST, .def = 0x00010002u},
    {.index = 0x1018, .sub = 4, CO_TYPE_U32, .attr = CO_A_R | CO_A_CONST, .def = 0x00000042u},
    {.index = 0x1800, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 5},
    {.index = 0x1800, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW | CO_A_NODEID, P(cob[0]), .def = 0x180, COBW},
    {.index = 0x1800, .sub = 2, CO_TYPE_U8, .attr = CO_A_RW, P(type[0]), .def = 254, TPW},
    {.index = 0x1800, .sub = 5, CO_TYPE_U16, .attr = CO_A_RW, P(event0), .def = 0, TPW},
    {.index = 0x1801, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 2},
    {.index = 0x1801, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW | CO_A_NODEID, P(cob[1]), .def = 0x280, COBW},
    {.index = 0x1801, .sub = 2, CO_TYPE_U8, .attr = CO_A_RW, P(type[1]), .def = 1, TPW},
    {.index = 0x1A00, .sub = 0, CO_TYPE_U8, .attr = CO_A_RW, P(map0_count), .def = 2, MAPW},
    {.index = 0x1A00, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW, P(map0[0]), .def = 0x20000020u, MAPW},
    {.index = 0x1A00, .sub = 2, CO_TYPE_U32, .attr = CO_A_RW, P(map0[1]), .def = 0x20010010u, MAPW},
    {.index = 0x1A00, .sub = 3, CO_TYPE_U32, .attr = CO_A_RW, P(map0[2]), .def = 0, MAPW},
    /* TPDO2's default mapping is 12 bytes: that PDO can never be sent. */
    {.index = 0x1A01, .sub = 0, CO_TYPE_U8, .attr = CO_A_RW, P(map1_count), .def = 3, MAPW},
    {.index = 0x1A01, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW, P(map1[0]), .def = 0x20000020u, MAPW},
    {.index = 0x1A01, .sub = 2, CO_TYPE_U32, .attr = CO_A_RW, P(map1[1]), .def = 0x20000020u, MAPW},
    {.index = 0x1A01, .sub = 3, CO_TYPE_U32, .attr = CO_A_RW, P(map1[2]), .def = 0x20000020u, MAPW},
    {.index = 0x2000, .sub = 0, CO_TYPE_U32, .attr = CO_A_RW | CO_A_PDO, V(a), .def = 0x11223344u},
    {.index = 0x2001, .sub = 0, CO_TYPE_U16, .attr = CO_A_RW | CO_A_PDO, V(b), .def = 0x5566u},
    {.index = 0x2002, .sub = 0, CO_TYPE_U16, .attr = CO_A_RW, P(c), .def = 0x7788u},
};
/* clang-format on */

static const co_od_t n_od = {.entries = n_entries,
                             .count = sizeof(n_entries) / sizeof(n_entries[0])};

static void n_state(co_node_t *n, co_nmt_state_t old)
{
    n_dev_t *t = n->app;
    t->state_calls++;
    t->last_old = old;
}

static void n_reset(co_node_t *n, co_reset_t kind)
{
    (void)kind;
    n_dev_t *t = n->app;
    if (t->start_once) {
        t->start_once = false;
        co_node_set_autostart(n, true);
    }
}

static const co_node_ops_t n_ops = {
    .state = n_state, .can_state = co_emcy_can_state, .reset = n_reset};

static const co_service_t *const n_services[] = {&co_guard_service, &co_hbc_service,
                                                 &co_lss_service, &co_rtr_service, NULL};

static const co_node_cfg_t n_cfg = {
    .od = &n_od,
    .ops = &n_ops,
    .services = n_services,
    .sdo_segmented = co_sdo_segmented,
    .ram_size = {0, sizeof(n_vol_t), sizeof(n_para_t), sizeof(co_lss_para_t)},
    .default_node_id = 0x40,
    .default_bitrate = 3,
    .lss_bitrates = 0x01DF, /* CiA 305 indices 0-4, 6-8 */
};

/* The test dictionary where reset communication applies the stored
 * node-ID too (the Gefran GSH-A's "sensor reset", read as any reset). */
static const co_node_cfg_t n_comm_id_cfg = {
    .od = &n_od,
    .ops = &n_ops,
    .services = n_services,
    .ram_size = {0, sizeof(n_vol_t), sizeof(n_para_t), sizeof(co_lss_para_t)},
    .default_node_id = 0x40,
    .default_bitrate = 3,
    .comm_reset_applies_id = true,
    .lss_bitrates = 0x01DF,
};

/* A dictionary with the fewest objects the services work with: no EMCY
 * COB-ID (the default 80h + node-ID), an error history with no field,
 * a guard time without a life time factor, a consumer time kept nowhere,
 * no identity. */
/* clang-format off */
static const co_od_entry_t n_min_entries[] = {
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_CONST, .def = 0x0000019Au},
    {.index = 0x1001, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, CO_EXT(.read = co_emcy_read_register)},
#if CO_EMCY_HIST_MAX > 0
    {.index = 0x1003, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, CO_EXT(.read = co_emcy_read_hist)},
#endif
    {.index = 0x100C, .sub = 0, CO_TYPE_U16, .attr = CO_A_RW, P(guard_ms), .def = 0},
    /* A consumer time kept nowhere (no RAM): fixed at its default. */
    {.index = 0x1016, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW, .def = 0, CO_EXT(.write = co_hbc_write_time)},
};
/* clang-format on */

static const co_od_t n_min_od = {.entries = n_min_entries,
                                 .count = sizeof(n_min_entries) / sizeof(n_min_entries[0])};

static const co_node_cfg_t n_min_cfg = {
    .od = &n_min_od,
    .services = n_services,
    .ram_size = {0, 0, sizeof(n_para_t), 0},
    .default_node_id = 0x40,
    .default_bitrate = 3,
    .lss_bitrates = 0x0008,
};

/* variant: NULL = the test dictionary; otherwise what it points to. */
typedef struct n_variant {
    bool no_lss; /* the board keeps no LSS set (ram NULL): "store" is not supported */
    const co_node_cfg_t *cfg;
} n_variant_t;

static void n_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    n_dev_t *t = mem;
    memset(t, 0, sizeof(*t));
    const n_variant_t *v = p->variant;
    bool no_lss = v != NULL && v->no_lss;
    const co_node_cfg_t *cfg = v != NULL ? v->cfg : &n_cfg;
    void *const ram[CO_CLS_COUNT] = {
        NULL, cfg->ram_size[CO_CLS_VOL] != 0u ? &t->vol : NULL, &t->para,
        no_lss || !co_cfg_has_service(cfg, &co_lss_service) ? NULL : &t->lss};
    co_node_init(&t->node, cfg, ports[0], t, ram, 0);
    nodes[0] = &t->node;
}

static void n_sample(void *mem, const int32_t v[], uint32_t fault)
{
    (void)mem;
    (void)v;
    (void)fault;
}

static const n_variant_t n_no_lss = {.no_lss = true, .cfg = &n_cfg};
static const n_variant_t n_min = {.no_lss = true, .cfg = &n_min_cfg};
static const n_variant_t n_comm_id = {.no_lss = false, .cfg = &n_comm_id_cfg};
static const product_t n_prod = {.id = "services",
                                 .inputs = {{NULL, NULL, 0, 0}},
                                 .nodes = 1,
                                 .inst_size = sizeof(n_dev_t),
                                 .create = n_create,
                                 .sample = n_sample};
static const product_t n_prod_no_lss = {.id = "services-no-lss",
                                        .inputs = {{NULL, NULL, 0, 0}},
                                        .nodes = 1,
                                        .inst_size = sizeof(n_dev_t),
                                        .create = n_create,
                                        .sample = n_sample,
                                        .variant = &n_no_lss};
static const product_t n_prod_comm_id = {.id = "services-comm-id",
                                         .inputs = {{NULL, NULL, 0, 0}},
                                         .nodes = 1,
                                         .inst_size = sizeof(n_dev_t),
                                         .create = n_create,
                                         .sample = n_sample,
                                         .variant = &n_comm_id};
static const product_t n_prod_min = {.id = "services-min",
                                     .inputs = {{NULL, NULL, 0, 0}},
                                     .nodes = 1,
                                     .inst_size = sizeof(n_dev_t),
                                     .create = n_create,
                                     .sample = n_sample,
                                     .variant = &n_min};

static h_dev_t dev;
static h_dev_t *const d = &dev;

static n_dev_t *inst(void)
{
    return h_inst(d);
}

static void boot(void)
{
    h_boot(d, &n_prod, false);
    EXPECT(d, 0x740, "00");
}

/* An LSS request; resp NULL: no answer at all. */
#define LSS(req, resp) lss((req), (resp), __LINE__)
static void lss(const char *req, const char *resp, int line)
{
    h_drain(d);
    h_rx(d, 0x7E5, req);
    if (resp != NULL) {
        h_expect(d, 0x7E4, resp, __FILE__, line);
    } else {
        h_expect_none(d, __FILE__, line);
    }
}

/* "store configuration" without a product hook: the node-ID goes into the
 * stack's LSS set, and a reset communication or power-on uses it. */
static void test_lss_store_in_lss_set(void)
{
    boot();
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("11 00 00 00 00 00 00 00", "11 01 00 00 00 00 00 00"); /* 0: no node-ID */
    LSS("11 25 00 00 00 00 00 00", "11 00 00 00 00 00 00 00");
    LSS("13 01 03 00 00 00 00 00", "13 01 00 00 00 00 00 00"); /* table selector 1: none */
    LSS("13 00 10 00 00 00 00 00", "13 01 00 00 00 00 00 00"); /* index 16 */
    LSS("13 00 03 00 00 00 00 00", "13 00 00 00 00 00 00 00"); /* 125 kbit/s */
    LSS("15 00 00 00 00 00 00 00", NULL);                      /* activate: no answer */
    /* Not LSS frames: fewer than 8 bytes, a remote request, another
     * identifier above or below the master's 7E5h. */
    h_drain(d);
    h_rx(d, 0x7E5, "5E 00 00 00");
    co_frame_t rtr = {.id = 0x7E5, .rtr = true, .dlc = 8, .data = {0x5E}};
    h_rx_frame(d, &rtr);
    h_rx(d, 0x7E6, "5E 00 00 00 00 00 00 00");
    h_rx(d, 0x7E4, "5E 00 00 00 00 00 00 00");
    EXPECT_NONE(d);
    LSS("17 00 00 00 00 00 00 00", "17 00 00 00 00 00 00 00");
    LSS("5E 00 00 00 00 00 00 00", "5E 40 00 00 00 00 00 00"); /* still the active one */
    LSS("04 00 00 00 00 00 00 00", NULL);                      /* configured node: no reset */
    h_rx(d, 0x000, "82 40");
    EXPECT(d, 0x725, "00"); /* active from reset communication (CiA 305) */
    h_power_cycle(d);
    EXPECT(d, 0x725, "00"); /* and stored */
    /* The EEPROM refuses the write: error 2, the stored ID stays. */
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("11 26 00 00 00 00 00 00", "11 00 00 00 00 00 00 00");
    d->port.cut_after = 0;
    LSS("17 00 00 00 00 00 00 00", "17 02 00 00 00 00 00 00");
    CHECK_EQ(inst()->lss.node_id, 0x25);
    h_power_cycle(d);
    EXPECT(d, 0x725, "00");
    /* Without an LSS set to keep it in: error 1, not supported. */
    h_boot(d, &n_prod_no_lss, false);
    EXPECT(d, 0x740, "00");
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("17 00 00 00 00 00 00 00", "17 01 00 00 00 00 00 00");
}

/* LSS "switch state global" with a mode CiA 305 does not define (2..255)
 * changes nothing: a slave in configuration stays there (it still answers
 * "inquire node-ID"), one in waiting stays there. */
static void test_lss_switch_global_reserved_mode(void)
{
    boot();
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("5E 00 00 00 00 00 00 00", "5E 40 00 00 00 00 00 00");
    LSS("04 02 00 00 00 00 00 00", NULL);
    LSS("5E 00 00 00 00 00 00 00", "5E 40 00 00 00 00 00 00");
    LSS("04 FF 00 00 00 00 00 00", NULL);
    LSS("5E 00 00 00 00 00 00 00", "5E 40 00 00 00 00 00 00");
    LSS("04 00 00 00 00 00 00 00", NULL);
    LSS("5E 00 00 00 00 00 00 00", NULL); /* waiting: no answer */
    LSS("04 80 00 00 00 00 00 00", NULL);
    LSS("5E 00 00 00 00 00 00 00", NULL);
}

/* LSS "activate bit timing" (CiA 305): each index of the bit timing table
 * reaches the board as its rate once the switch delay is over; the
 * reserved index 5 and automatic detection (9) are refused. */
static void test_lss_bit_timing_table(void)
{
    boot();
    LSS("04 01 00 00 00 00 00 00", NULL);
    static const struct {
        uint8_t index;
        uint16_t kbps;
    } rates[] = {{0, 1000}, {1, 800}, {2, 500}, {3, 250}, {4, 125}, {6, 50}, {7, 20}, {8, 10}};
    uint16_t was = d->port.kbps;
    for (unsigned i = 0; i < sizeof(rates) / sizeof(rates[0]); i++) {
        co_frame_t f = {.id = 0x7E5, .dlc = 8, .data = {0x13, 0x00, rates[i].index}};
        h_drain(d);
        h_rx_frame(d, &f);
        EXPECT(d, 0x7E4, "13 00 00 00 00 00 00 00");
        LSS("15 0A 00 00 00 00 00 00", NULL); /* after 10 ms */
        h_advance(d, 9999);
        CHECK_EQ(d->port.kbps, was);
        h_advance(d, 1);
        CHECK_EQ(d->port.kbps, rates[i].kbps);
        was = rates[i].kbps;
    }
    LSS("13 00 05 00 00 00 00 00", "13 01 00 00 00 00 00 00");
    LSS("13 00 09 00 00 00 00 00", "13 01 00 00 00 00 00 00");
    LSS("13 00 80 00 00 00 00 00", "13 01 00 00 00 00 00 00"); /* no such index */
    LSS("13 00 FF 00 00 00 00 00", "13 01 00 00 00 00 00 00");
    /* The board's poll is asked for at the switch, and for nothing after. */
    LSS("13 00 04 00 00 00 00 00", "13 00 00 00 00 00 00 00");
    LSS("15 0A 00 00 00 00 00 00", NULL);
    CHECK_EQ(co_node_poll(d->node, d->now), 10000);
    h_advance(d, 9999);
    d->now++;
    CHECK_EQ(co_node_poll(d->node, d->now), CO_NEVER);
    CHECK_EQ(d->port.kbps, 125);
}

/* LSS switch mode selective (CiA 305): the four parts in order, each
 * sequence from its vendor part: a vendor part starts it again, a wrong
 * part ends it (the right one after it is too late), and a completed
 * selection leaves nothing for the next. */
static void test_lss_switch_selective_sequence(void)
{
    boot();
    LSS("40 78 56 34 12 00 00 00", NULL);
    LSS("41 CD AB 00 00 00 00 00", NULL);
    LSS("40 78 56 34 12 00 00 00", NULL); /* again from the start */
    LSS("41 CD AB 00 00 00 00 00", NULL);
    LSS("42 02 00 01 00 00 00 00", NULL);
    LSS("43 42 00 00 00 00 00 00", "44 00 00 00 00 00 00 00");
    LSS("41 CD AB 00 00 00 00 00", NULL); /* no vendor part: nothing */
    LSS("42 02 00 01 00 00 00 00", NULL);
    LSS("43 42 00 00 00 00 00 00", NULL);
    LSS("04 00 00 00 00 00 00 00", NULL);
    LSS("40 78 56 34 12 00 00 00", NULL);
    LSS("41 CE AB 00 00 00 00 00", NULL); /* wrong product code */
    LSS("41 CD AB 00 00 00 00 00", NULL);
    LSS("42 02 00 01 00 00 00 00", NULL);
    LSS("43 42 00 00 00 00 00 00", NULL);
    LSS("5E 00 00 00 00 00 00 00", NULL); /* still waiting */
}

/* LSS identify remote slave (CiA 305): the revision and serial ranges
 * include both their bounds; a bound one past the node's value leaves it
 * out. Inquire identity: each part of 0x1018; other command specifiers
 * are no service. Configure node-ID: 1..127 and FFh (none) taken, 0, 80h
 * and FEh refused. */
static void test_lss_identity_bounds(void)
{
    boot();
    /* vendor, product, revision low, high, serial low, high */
    static const char *const seq[6] = {"46 78 56 34 12 00 00 00", "47 CD AB 00 00 00 00 00",
                                       "48 02 00 01 00 00 00 00", "49 02 00 01 00 00 00 00",
                                       "4A 42 00 00 00 00 00 00", "4B 42 00 00 00 00 00 00"};
    for (unsigned k = 0; k < 6u; k++) {
        LSS(seq[k], k == 5u ? "4F 00 00 00 00 00 00 00" : NULL);
    }
    /* Each bound one past the node's value: no answer. */
    static const char *const off[4] = {"48 03 00 01 00 00 00 00", "49 01 00 01 00 00 00 00",
                                       "4A 43 00 00 00 00 00 00", "4B 41 00 00 00 00 00 00"};
    for (unsigned j = 0; j < 4u; j++) {
        for (unsigned k = 0; k < 6u; k++) {
            LSS(k == j + 2u ? off[j] : seq[k], NULL);
        }
    }
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("5A 00 00 00 00 00 00 00", "5A 78 56 34 12 00 00 00");
    LSS("5B 00 00 00 00 00 00 00", "5B CD AB 00 00 00 00 00");
    LSS("5C 00 00 00 00 00 00 00", "5C 02 00 01 00 00 00 00");
    LSS("5D 00 00 00 00 00 00 00", "5D 42 00 00 00 00 00 00");
    /* Command specifiers of no service: no answer (CiA 305). */
    LSS("20 00 00 00 00 00 00 00", NULL);
    LSS("59 00 00 00 00 00 00 00", NULL);
    LSS("5F 00 00 00 00 00 00 00", NULL);
    LSS("11 01 00 00 00 00 00 00", "11 00 00 00 00 00 00 00");
    LSS("11 7F 00 00 00 00 00 00", "11 00 00 00 00 00 00 00");
    LSS("11 80 00 00 00 00 00 00", "11 01 00 00 00 00 00 00");
    LSS("11 FE 00 00 00 00 00 00", "11 01 00 00 00 00 00 00");
    LSS("04 00 00 00 00 00 00 00", NULL);
    h_rx(d, 0x000, "82 40");
    EXPECT(d, 0x77F, "00"); /* the last one taken: 127 */
}

/* Fastscan: only a node without node-ID in waiting state takes part, and
 * only in the sequence a master runs (restart first, bit 31..0, sub 0..3). */
static void test_lss_fastscan_ignored_requests(void)
{
    boot();
    LSS("51 00 00 00 00 80 00 00", NULL); /* configured: never answers */
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("11 FF 00 00 00 00 00 00", "11 00 00 00 00 00 00 00");
    LSS("04 00 00 00 00 00 00 00", NULL); /* still 0x40 until reset communication */
    LSS("4C 00 00 00 00 00 00 00", NULL);
    h_drain(d);
    h_rx(d, 0x000, "82 40");
    EXPECT_NONE(d); /* no node-ID: no boot-up */
    CHECK_EQ(d->node->node_id, CO_LSS_UNCONFIGURED);
    LSS("4C 00 00 00 00 00 00 00", "50 00 00 00 00 00 00 00");
    LSS("51 78 56 34 12 00 00 00", NULL); /* no restart yet */
    LSS("51 00 00 00 00 80 00 00", "4F 00 00 00 00 00 00 00");
    LSS("51 00 00 00 00 20 00 00", NULL);                      /* bit 32 */
    LSS("51 00 00 00 00 1F 04 00", NULL);                      /* sub 4 */
    LSS("51 00 00 00 00 1F 01 00", NULL);                      /* sub 1 before sub 0 */
    LSS("51 00 00 00 00 1F 00 00", "4F 00 00 00 00 00 00 00"); /* bit 31 of 0x12345678: 0 */
    LSS("51 00 00 00 80 1F 00 00", NULL);                      /* a 1 there: not us */
    LSS("51 78 56 34 12 00 00 01", "4F 00 00 00 00 00 00 00"); /* vendor confirmed */
    LSS("51 78 56 34 12 00 00 01", NULL);                      /* sub 0 is done */
    /* In configuration state Fastscan is not for this node. */
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("51 00 00 00 00 80 00 00", NULL);
    LSS("5E 00 00 00 00 00 00 00", "5E FF 00 00 00 00 00 00");
    /* A node-ID of 0xFF configured is still "non-configured". */
    LSS("11 FF 00 00 00 00 00 00", "11 00 00 00 00 00 00 00");
    LSS("04 00 00 00 00 00 00 00", NULL);
    LSS("4C 00 00 00 00 00 00 00", "50 00 00 00 00 00 00 00");
}

/* Fastscan knows LSS address parts 0..3 only: after a master named a
 * part 4 to go on with, no request for it is answered. A restart begins
 * at part 0; the node is selected when part 3 is confirmed with 0 to go
 * on with, not before; a scan after that needs a restart. */
static void test_lss_fastscan_no_part_4(void)
{
    boot();
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("11 FF 00 00 00 00 00 00", "11 00 00 00 00 00 00 00");
    LSS("04 00 00 00 00 00 00 00", NULL);
    h_rx(d, 0x000, "82 40");
    LSS("51 00 00 00 00 80 00 00", "4F 00 00 00 00 00 00 00");
    LSS("51 78 56 34 12 00 00 04", "4F 00 00 00 00 00 00 00"); /* vendor; next: 4 */
    LSS("51 00 00 00 00 1F 04 00", NULL);
    LSS("51 00 00 00 00 00 04 00", NULL);
    /* A restart begins at part 0 again. */
    LSS("51 00 00 00 00 80 00 00", "4F 00 00 00 00 00 00 00");
    LSS("51 00 00 00 00 1F 00 00", "4F 00 00 00 00 00 00 00");
    /* Part 0 confirmed with 0 to go on with: not yet the whole address. */
    LSS("51 78 56 34 12 00 00 00", "4F 00 00 00 00 00 00 00");
    LSS("5E 00 00 00 00 00 00 00", NULL); /* still waiting */
    /* All four parts confirmed: selected (configuration state). */
    LSS("51 78 56 34 12 00 00 01", "4F 00 00 00 00 00 00 00");
    LSS("51 CD AB 00 00 00 01 02", "4F 00 00 00 00 00 00 00");
    LSS("51 02 00 01 00 00 02 03", "4F 00 00 00 00 00 00 00");
    LSS("51 42 00 00 00 00 03 00", "4F 00 00 00 00 00 00 00");
    LSS("5E 00 00 00 00 00 00 00", "5E FF 00 00 00 00 00 00");
    /* Back in waiting, a new scan needs its restart first. */
    LSS("04 00 00 00 00 00 00 00", NULL);
    LSS("51 78 56 34 12 00 00 01", NULL);
    LSS("51 00 00 00 00 1F 00 00", NULL);
    /* Node-ID 1 given: the node starts with it once back in waiting. */
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("11 01 00 00 00 00 00 00", "11 00 00 00 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x7E5, "04 00 00 00 00 00 00 00");
    EXPECT(d, 0x701, "00");
}

/* A life-guarding event is cleared by reset communication: error register 0. */
static void test_life_guard_event_cleared_by_reset_communication(void)
{
    boot();
    SDO(d, "2B 0C 10 00 64 00 00 00", "60 0C 10 00 00 00 00 00"); /* 100 ms */
    SDO(d, "2F 0D 10 00 02 00 00 00", "60 0D 10 00 00 00 00 00"); /* x 2 */
    co_frame_t rtr = {.id = 0x740, .rtr = true, .dlc = 1};
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x740, "7F");
    h_advance(d, 199999);
    EXPECT_NONE(d);
    h_advance(d, 1);
    EXPECT(d, 0xC0, "30 81 11 00 00 00 00 00");
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP); /* not operational: stays */
    CHECK_EQ(h_read(d, 0x1001, 0), 0x11);
    h_drain(d);
    h_rx(d, 0x000, "82 40");
    EXPECT(d, 0x740, "00"); /* boot-up; no EMCY while initialising */
    EXPECT_NONE(d);
    CHECK_EQ(h_read(d, 0x1001, 0), 0);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x740, "7F");
}

/* A life-guarding event moves an operational node to pre-operational
 * (CiA 301's default error behaviour) and leaves a stopped one stopped. */
static void test_life_guard_event_in_stopped(void)
{
    boot();
    SDO(d, "2B 0C 10 00 64 00 00 00", "60 0C 10 00 00 00 00 00"); /* 100 ms */
    SDO(d, "2F 0D 10 00 02 00 00 00", "60 0D 10 00 00 00 00 00"); /* x 2 */
    co_frame_t rtr = {.id = 0x740, .rtr = true, .dlc = 1};
    h_rx(d, 0x000, "02 40");
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x740, "04");
    h_advance(d, 200000); /* the event (no EMCY frame while stopped) */
    CHECK_EQ(co_emcy_register(d->node), 0x11);
    CHECK_EQ(d->node->nmt.state, CO_NMT_STOPPED);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x740, "84"); /* still stopped; the request ends the event */
    EXPECT_NONE(d);
    CHECK_EQ(co_emcy_register(d->node), 0);
    h_rx(d, 0x000, "01 40");
    h_drain(d);
    h_advance(d, 200000);
    EXPECT(d, 0xC0, "30 81 11 00 00 00 00 00");
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
}

/* Life guarding (CiA 301) runs from the last guard request answered: a
 * reset communication forgets the requests before it, and the life time
 * starts again with the first one after. A life time factor of 0 is node
 * guarding without life guarding: answered, never an event, no timer. */
static void test_life_guard_starts_with_a_request(void)
{
    boot();
    SDO(d, "2B 0C 10 00 64 00 00 00", "60 0C 10 00 00 00 00 00"); /* 100 ms */
    co_frame_t rtr = {.id = 0x740, .rtr = true, .dlc = 1};
    h_drain(d);
    co_node_receive(d->node, &rtr, d->now);
    EXPECT(d, 0x740, "7F");
    CHECK_EQ(co_node_poll(d->node, d->now), CO_NEVER); /* nothing to time */
    h_advance(d, 1000000);
    EXPECT_NONE(d);
    SDO(d, "2F 0D 10 00 02 00 00 00", "60 0D 10 00 00 00 00 00"); /* x 2 */
    CHECK(co_store_save(d->node, CO_CLS_PARA) == CO_OK);          /* kept over the reset */
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x740, "FF");
    h_advance(d, 100000);
    h_rx(d, 0x000, "82 40");
    EXPECT(d, 0x740, "00");
    h_advance(d, 1000000);
    EXPECT_NONE(d); /* no request since the reset: not guarded yet */
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x740, "7F"); /* the toggle bit starts at 0 again */
    h_advance(d, 199999);
    EXPECT_NONE(d);
    d->now++;
    CHECK_EQ(co_node_poll(d->node, d->now), CO_NEVER); /* lost: no timer after */
    EXPECT(d, 0xC0, "30 81 11 00 00 00 00 00");
}

/* Life guarding and the heartbeat consumer report one EMCY code (8130h);
 * each one's event ends by its own protocol only: a guard request after a
 * reset does not end the consumer's event, nor a heartbeat after a new
 * 0x1016 value the life guarding's. */
static void test_guard_and_consumer_events_apart(void)
{
    boot();
    SDO(d, "2B 0C 10 00 64 00 00 00", "60 0C 10 00 00 00 00 00"); /* 100 ms */
    SDO(d, "2F 0D 10 00 02 00 00 00", "60 0D 10 00 00 00 00 00"); /* x 2 */
    co_frame_t rtr = {.id = 0x740, .rtr = true, .dlc = 1};
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x740, "7F");
    h_advance(d, 200000);
    EXPECT(d, 0xC0, "30 81 11 00 00 00 00 00"); /* life guarding's event */
    h_rx(d, 0x000, "82 40");
    EXPECT(d, 0x740, "00");
    CHECK_EQ(h_read(d, 0x1001, 0), 0);
    SDO(d, "23 16 10 01 64 00 05 00", "60 16 10 01 00 00 00 00"); /* node 5, 100 ms */
    h_rx(d, 0x705, "05");
    h_advance(d, 100000);
    EXPECT(d, 0xC0, "30 81 11 00 00 00 00 00"); /* the consumer's event */
    SDO(d, "2B 0C 10 00 64 00 00 00", "60 0C 10 00 00 00 00 00");
    SDO(d, "2F 0D 10 00 02 00 00 00", "60 0D 10 00 00 00 00 00");
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x740, "7F");
    EXPECT_NONE(d); /* a guard request: the consumer's event stays */
    CHECK_EQ(h_read(d, 0x1001, 0), 0x11);
    /* A new consumer time ends its event; then life guarding's comes. */
    h_drain(d);
    h_rx(d, 0x640, "23 16 10 01 C8 00 05 00");
    EXPECT(d, 0xC0, "00 00 00 00 00 00 00 00");
    EXPECT(d, 0x5C0, "60 16 10 01 00 00 00 00");
    h_advance(d, 200000);
    EXPECT(d, 0xC0, "30 81 11 00 00 00 00 00");
    h_rx(d, 0x705, "05");
    EXPECT_NONE(d); /* a heartbeat: life guarding's event stays */
    CHECK_EQ(h_read(d, 0x1001, 0), 0x11);
}

/* Heartbeat consumer (0x1016): only a 1-byte heartbeat of the node it
 * watches counts; the event (8130h) ends with the next heartbeat or a new
 * 0x1016 value. */
static void test_heartbeat_consumer(void)
{
    boot();
    SDO(d, "23 16 10 01 64 00 05 01", "80 16 10 01 30 00 09 06"); /* bits 24-31 */
    SDO(d, "23 16 10 01 64 00 80 00", "80 16 10 01 30 00 09 06"); /* node 128 */
    SDO(d, "23 16 10 01 65 00 7F 00", "60 16 10 01 00 00 00 00"); /* node 127, 101 ms */
    SDO(d, "23 16 10 01 64 00 05 00", "60 16 10 01 00 00 00 00"); /* node 5, 100 ms */
    h_rx(d, 0x000, "01 40");
    h_drain(d);
    co_frame_t rtr = {.id = 0x705, .rtr = true, .dlc = 1};
    h_rx_frame(d, &rtr);
    h_rx(d, 0x705, "05 00");
    h_rx(d, 0x706, "05");
    h_advance(d, 500000);
    EXPECT_NONE(d); /* not started: none of these was node 5's heartbeat */
    h_rx(d, 0x705, "05");
    h_advance(d, 99999);
    EXPECT_NONE(d);
    h_advance(d, 1);
    EXPECT(d, 0xC0, "30 81 11 00 00 00 00 00");
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP); /* CiA 301 default error behaviour */
    h_rx(d, 0x705, "05");
    EXPECT(d, 0xC0, "00 00 00 00 00 00 00 00");
    h_advance(d, 100000);
    EXPECT(d, 0xC0, "30 81 11 00 00 00 00 00");
    /* A new consumer time while the event is active clears it. */
    SDO(d, "23 16 10 01 C8 00 05 00", "60 16 10 01 00 00 00 00");
    CHECK_EQ(h_read(d, 0x1001, 0), 0);
    h_drain(d);
    h_advance(d, 1000000);
    EXPECT_NONE(d); /* waits for the first heartbeat again */
}

/* The consumer's timer as a board sees it: the poll asks to be called
 * when the consumer time runs out, and for nothing after the event; 1 ms
 * is a time too. The consumer takes only heartbeats: a TPDO still answers
 * its remote request. */
static void test_heartbeat_consumer_timer(void)
{
    boot();
    SDO(d, "23 16 10 01 01 00 05 00", "60 16 10 01 00 00 00 00"); /* node 5, 1 ms */
    h_drain(d);
    h_rx(d, 0x705, "05");
    CHECK_EQ(co_node_poll(d->node, d->now), 1000);
    CHECK_EQ(co_node_poll(d->node, d->now + 999u), 1);
    EXPECT_NONE(d);
    d->now += 1000u;
    CHECK_EQ(co_node_poll(d->node, d->now), CO_NEVER);
    EXPECT(d, 0xC0, "30 81 11 00 00 00 00 00");
    h_rx(d, 0x000, "01 40");
    h_drain(d);
    co_frame_t rtr = {.id = 0x1C0, .rtr = true, .dlc = 0};
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x1C0, "44 33 22 11 66 55");
    EXPECT_NONE(d);
    /* Node 1 is a node to watch too. */
    SDO(d, "23 16 10 01 0A 00 01 00", "60 16 10 01 00 00 00 00"); /* node 1, 10 ms */
    h_rx(d, 0x701, "05");
    h_advance(d, 9999);
    EXPECT_NONE(d);
    h_advance(d, 1);
    EXPECT(d, 0xC0, "30 81 11 00 00 00 00 00");
}

/* A poll late by more than a period sends one heartbeat, not a burst. */
static void test_heartbeat_late_poll(void)
{
    boot();
    SDO(d, "2B 17 10 00 0A 00 00 00", "60 17 10 00 00 00 00 00"); /* 10 ms */
    uint32_t t0 = d->now;
    h_drain(d);
    CHECK_EQ(co_node_poll(d->node, t0), 10000);
    CHECK_EQ(co_node_poll(d->node, t0 + 35000u), 10000);
    EXPECT(d, 0x740, "7F");
    EXPECT_NONE(d);
    CHECK_EQ(co_node_poll(d->node, t0 + 45000u), 10000);
    EXPECT(d, 0x740, "7F");
}

/* The product's state hook sees every change with the old state; NMT
 * frames that are not 2 bytes, or are remote requests, change nothing. */
static void test_nmt_state_hook(void)
{
    boot();
    CHECK_EQ(inst()->state_calls, 1); /* boot-up: INIT -> pre-operational */
    CHECK_EQ(inst()->last_old, CO_NMT_INIT);
    h_rx(d, 0x000, "01 40");
    CHECK_EQ(inst()->state_calls, 2);
    CHECK_EQ(inst()->last_old, CO_NMT_PREOP);
    h_rx(d, 0x000, "01 40"); /* no change: no call */
    CHECK_EQ(inst()->state_calls, 2);
    co_frame_t rtr = {.id = 0x000, .rtr = true, .dlc = 2, .data = {0x02, 0x40}};
    h_rx_frame(d, &rtr);
    CHECK_EQ(d->node->nmt.state, CO_NMT_OPERATIONAL);
    h_rx(d, 0x000, "02 40");
    CHECK_EQ(inst()->last_old, CO_NMT_OPERATIONAL);
    CHECK_EQ(d->node->nmt.state, CO_NMT_STOPPED);
}

/* Without a product LED hook: the CiA 303-3 mapping of co_node.h. */
static void test_cia303_led_mapping(void)
{
    boot();
    co_led_pattern_t g;
    co_led_pattern_t r;
    co_node_led_patterns(d->node, &g, &r);
    CHECK(g == CO_LED_BLINK && r == CO_LED_OFF);
    h_rx(d, 0x000, "01 40");
    co_node_led_patterns(d->node, &g, &r);
    CHECK(g == CO_LED_ON && r == CO_LED_OFF);
    h_rx(d, 0x000, "02 40");
    co_node_led_patterns(d->node, &g, &r);
    CHECK(g == CO_LED_FLASH1);
    h_rx(d, 0x000, "80 40");
    h_drain(d);
    co_node_set_can_state(d->node, CO_CAN_WARNING);
    co_node_led_patterns(d->node, &g, &r);
    CHECK(r == CO_LED_FLASH1);
    EXPECT_NONE(d); /* a warning is no EMCY */
    co_node_set_can_state(d->node, CO_CAN_PASSIVE);
    EXPECT(d, 0xC0, "20 81 11 00 00 00 00 00");
    co_node_set_can_state(d->node, CO_CAN_PASSIVE); /* no change: nothing */
    EXPECT_NONE(d);
    co_node_set_can_state(d->node, CO_CAN_BUSOFF);
    uint32_t dropped = co_node_tx_dropped(d->node);
    co_node_set_can_state(d->node, CO_CAN_BUSOFF); /* no change: no EMCY tried */
    CHECK_EQ(co_node_tx_dropped(d->node), dropped);
    co_node_set_can_state(d->node, CO_CAN_PASSIVE);
    h_drain(d);
    co_node_led_patterns(d->node, &g, &r);
    CHECK(r == CO_LED_FLASH1);
    /* A node without node-ID is in no NMT state: green off. */
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("11 FF 00 00 00 00 00 00", "11 00 00 00 00 00 00 00");
    h_rx(d, 0x000, "82 40");
    co_node_led_patterns(d->node, &g, &r);
    CHECK(g == CO_LED_OFF);
    /* The names the Linux program logs. */
    static const char *const names[] = {"off",      "on",           "flickering",
                                        "blinking", "single flash", "double flash"};
    static const co_led_pattern_t pats[] = {CO_LED_OFF,   CO_LED_ON,     CO_LED_FLICKER,
                                            CO_LED_BLINK, CO_LED_FLASH1, CO_LED_FLASH2};
    for (unsigned i = 0; i < 6u; i++) {
        CHECK(strcmp(co_led_pattern_name(pats[i]), names[i]) == 0);
    }
    CHECK(strcmp(co_led_pattern_name((co_led_pattern_t)99), "?") == 0);
    /* The levels with CiA 303-3's timing (blinking: 200 ms on, 200 off). */
    boot();
    bool gl = false;
    bool rl = true;
    uint32_t next = 0;
    co_node_leds(d->node, 4000000u, &gl, &rl, &next);
    CHECK(gl && !rl);
    CHECK_EQ(next, 200000);
    co_node_leds(d->node, 4250000u, &gl, &rl, &next);
    CHECK(!gl && !rl);
    CHECK_EQ(next, 150000);
}

/* A mapping of more than 8 bytes: refused when written (0x06040042), and a
 * default one that long leaves the PDO invalid: never sent, never answered. */
static void test_tpdo_mapping_longer_than_8_bytes(void)
{
    boot();
    SDO(d, "2F 00 18 02 01 00 00 00", "60 00 18 02 00 00 00 00"); /* TPDO1 on every SYNC */
    h_rx(d, 0x000, "01 40");
    h_drain(d);
    h_rx(d, 0x080, "");
    EXPECT(d, 0x1C0, "44 33 22 11 66 55");
    EXPECT_NONE(d); /* TPDO2 (type 1 too): 12 bytes mapped, invalid */
    co_frame_t rtr = {.id = 0x2C0, .rtr = true, .dlc = 0};
    h_rx_frame(d, &rtr);
    EXPECT_NONE(d);
    /* An RTR is no SYNC. */
    co_frame_t sync_rtr = {.id = 0x080, .rtr = true, .dlc = 0};
    h_rx_frame(d, &sync_rtr);
    EXPECT_NONE(d);
    SDO(d, "23 01 18 01 C0 02 00 80", "60 01 18 01 00 00 00 00"); /* invalidate TPDO2 */
    SDO(d, "2F 01 1A 00 03 00 00 00", "80 01 1A 00 42 00 04 06");
    SDO(d, "2F 01 1A 00 02 00 00 00", "60 01 1A 00 00 00 00 00"); /* 8 bytes: fine */
    SDO(d, "23 01 18 01 C0 02 00 00", "60 01 18 01 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x080, "");
    EXPECT(d, 0x1C0, "44 33 22 11 66 55");
    EXPECT(d, 0x2C0, "44 33 22 11 44 33 22 11");
    /* No TPDO 6: ignored (a broken contract, CO_CHECK). */
    unsigned seen = h_asserts;
    h_expect_assert(2);
    CHECK(!co_tpdo_changed(d->node, 5));
    co_tpdo_event(d->node, 5);
    CHECK_EQ(h_asserts, seen + 2u);
    h_advance(d, 1000);
    EXPECT_NONE(d);
}

/* CiA 301's answers to a mapping count (0x1A00 sub 0) larger than the
 * entries written: an entry that names no object (0, or a sub-index the
 * mapping lacks) 0x06020000, more than 8 bytes 0x06040042; an entry that
 * names an unmappable object is refused when written (0x06040041). */
static void test_tpdo_mapping_count_beyond_entries(void)
{
    boot();
    SDO(d, "23 00 18 01 C0 01 00 80", "60 00 18 01 00 00 00 00"); /* invalidate TPDO1 */
    /* Invalid or not, an 11-bit CAN-ID: bit 12 (here 11C0h) is refused. */
    SDO(d, "23 00 18 01 C0 11 00 80", "80 00 18 01 30 00 09 06");
    SDO(d, "2F 00 1A 00 03 00 00 00", "80 00 1A 00 00 00 02 06"); /* sub 3 is 0 */
    SDO(d, "2F 00 1A 00 04 00 00 00", "80 00 1A 00 00 00 02 06"); /* no sub 4 */
    SDO(d, "2F 00 1A 00 08 00 00 00", "80 00 1A 00 00 00 02 06");
    SDO(d, "2F 00 1A 00 41 00 00 00", "80 00 1A 00 31 00 09 06"); /* beyond 64 */
    SDO(d, "2F 00 1A 00 00 00 00 00", "60 00 1A 00 00 00 00 00");
    SDO(d, "23 00 1A 03 20 00 00 10", "80 00 1A 03 41 00 04 06"); /* 0x1000: not mappable */
    SDO(d, "23 00 1A 03 20 00 00 20", "60 00 1A 03 00 00 00 00"); /* 4 + 2 + 4 bytes */
    SDO(d, "2F 00 1A 00 03 00 00 00", "80 00 1A 00 42 00 04 06");
    SDO(d, "2F 00 1A 00 02 00 00 00", "60 00 1A 00 00 00 00 00"); /* the two first: fine */
    SDO(d, "40 00 1A 00 00 00 00 00", "4F 00 1A 00 02 00 00 00");
}

/* The active-error table holds CO_EMCY_ACTIVE_MAX errors; one more is
 * refused (no EMCY) until one clears. EMCY COB-ID: 11-bit, never 0. */
static void test_emcy_table_full_and_cobid(void)
{
    boot();
    h_drain(d);
    for (uint16_t i = 0; i < CO_EMCY_ACTIVE_MAX; i++) {
        CHECK(co_emcy_error(d->node, (uint16_t)(0xFF00u + i), CO_ER_MANUFACTURER, true, NULL));
    }
    unsigned sent = 0;
    while (h_next(d) != NULL) {
        sent++;
    }
    CHECK_EQ(sent, CO_EMCY_ACTIVE_MAX);
    CHECK(!co_emcy_error(d->node, 0xFF80, CO_ER_MANUFACTURER, true, NULL));
    EXPECT_NONE(d);
    CHECK(co_emcy_error(d->node, 0xFF00, 0, false, NULL));
    CHECK(co_emcy_error(d->node, 0xFF80, CO_ER_MANUFACTURER, true, NULL));
    EXPECT(d, 0xC0, "80 FF 81 00 00 00 00 00");
    SDO(d, "23 14 10 00 C0 00 00 20", "80 14 10 00 30 00 09 06"); /* bit 29: 29-bit ID */
    /* Invalid (bit 31) may name any CAN-ID, as for a PDO; valid never a
     * restricted one, CAN-ID 0 included (CiA 301 7.3.5). */
    SDO(d, "23 14 10 00 00 00 00 80", "60 14 10 00 00 00 00 00");
    SDO(d, "23 14 10 00 00 00 00 00", "80 14 10 00 30 00 09 06");
    SDO(d, "23 14 10 00 C0 00 00 00", "60 14 10 00 00 00 00 00"); /* its own value again */
    CHECK_EQ(h_read(d, 0x1014, 0), 0xC0);
}

/* Reset communication puts the communication objects (1000h..1FFFh) back
 * to their defaults, or to what is stored, and leaves the others alone;
 * reset node puts every one back (CiA 301). */
static void test_reset_areas(void)
{
    boot();
    SDO(d, "2B 15 10 00 0A 00 00 00", "60 15 10 00 00 00 00 00"); /* RAM only */
    SDO(d, "2B 17 10 00 64 00 00 00", "60 17 10 00 00 00 00 00"); /* stored set */
    SDO(d, "23 00 20 00 01 02 03 04", "60 00 20 00 00 00 00 00");
    SDO(d, "2B 02 20 00 99 00 00 00", "60 02 20 00 00 00 00 00");
    h_rx(d, 0x000, "82 40");
    CHECK_EQ(h_read(d, 0x1015, 0), 0);
    CHECK_EQ(h_read(d, 0x1017, 0), 0);
    CHECK_EQ(h_read(d, 0x2000, 0), 0x04030201);
    CHECK_EQ(h_read(d, 0x2002, 0), 0x99);
    h_rx(d, 0x000, "81 40");
    CHECK_EQ(h_read(d, 0x2000, 0), 0x11223344);
    CHECK_EQ(h_read(d, 0x2002, 0), 0x7788);
}

/* What a reset does not keep: a stored node-ID out of 1..127 (128) is
 * refused, the store reported corrupt, the default used; an automatic
 * start is for the boot-up it was asked for; an SDO transfer in progress
 * is forgotten (its next segment is no valid request); an LSS node-ID
 * applied once is not applied again. */
static void test_reset_forgets(void)
{
    boot();
    inst()->lss.node_id = 128;
    CHECK(co_store_save(d->node, CO_CLS_LSS) == CO_OK);
    h_power_cycle(d);
    EXPECT(d, 0x740, "00");
    CHECK_EQ(co_node_store_status(d->node, CO_CLS_LSS), CO_STORE_CORRUPT);
    inst()->start_once = true;
    h_rx(d, 0x000, "82 40");
    CHECK_EQ(co_node_nmt_state(d->node), CO_NMT_OPERATIONAL);
    h_rx(d, 0x000, "82 40");
    CHECK_EQ(co_node_nmt_state(d->node), CO_NMT_PREOP);
    SDO(d, "21 00 20 00 04 00 00 00", "60 00 20 00 00 00 00 00"); /* segmented */
    h_rx(d, 0x000, "82 40");
    SDO(d, "07 00 00 00 05 00 00 00", "80 00 00 00 01 00 04 05");
    CHECK_EQ(h_read(d, 0x2000, 0), 0x11223344);
    /* An LSS node-ID not stored is active from reset communication until a
     * reset node, which loads the stored set (here the default 40h). */
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("11 25 00 00 00 00 00 00", "11 00 00 00 00 00 00 00");
    LSS("04 00 00 00 00 00 00 00", NULL);
    h_rx(d, 0x000, "82 40");
    EXPECT(d, 0x725, "00");
    h_rx(d, 0x000, "81 25");
    EXPECT(d, 0x740, "00");
    /* Without a bit rate table the board is told 0 (its default), once a
     * power-on (two here): the resets since changed no rate. */
    CHECK_EQ(d->port.kbps, 0);
    CHECK_EQ(d->port.bitrate_calls, 2);
}

/* Where reset communication applies the node-ID, it applies the stored
 * one: a node-ID in RAM that was never stored is replaced by it. */
static void test_comm_reset_applies_stored_id(void)
{
    h_boot(d, &n_prod_comm_id, false);
    EXPECT(d, 0x740, "00");
    inst()->lss.node_id = 0x30; /* not stored */
    h_rx(d, 0x000, "82 40");
    EXPECT(d, 0x740, "00");
}

/* A reset requested (co_node_request_reset) happens once, at the next
 * poll. */
static void test_reset_request_once(void)
{
    boot();
    h_drain(d);
    co_node_request_reset(d->node, CO_RESET_COMM);
    EXPECT_NONE(d);
    h_advance(d, 1000);
    EXPECT(d, 0x740, "00");
    h_rx(d, 0x000, "01 40");
    h_advance(d, 100000);
    EXPECT_NONE(d);
    CHECK_EQ(co_node_nmt_state(d->node), CO_NMT_OPERATIONAL);
}

/* A reset the board's poll performs late (requested at t, polled at
 * t + 50 ms) runs from the poll's time: an automatic start's event timer
 * (100 ms) sends at once and then 100 ms after that poll. */
static void test_late_reset_runs_from_the_poll(void)
{
    boot();
    SDO(d, "2B 00 18 05 64 00 00 00", "60 00 18 05 00 00 00 00"); /* TPDO1 event timer */
    CHECK(co_store_save(d->node, CO_CLS_PARA) == CO_OK);
    inst()->start_once = true;
    h_drain(d);
    co_node_request_reset(d->node, CO_RESET_COMM);
    d->now += 50000u;
    (void)co_node_poll(d->node, d->now);
    EXPECT(d, 0x740, "00");
    EXPECT(d, 0x1C0, "44 33 22 11 66 55");
    h_advance(d, 99999);
    EXPECT_NONE(d);
    h_advance(d, 1);
    EXPECT(d, 0x1C0, "44 33 22 11 66 55");
}

/* A node started late in the clock's range (past 2^31 us, about 36 min
 * after the board's clock began) runs its timers as at any other time:
 * the stored heartbeat goes out after its period. */
static void test_start_late_in_the_clock(void)
{
    boot();
    SDO(d, "2B 17 10 00 64 00 00 00", "60 17 10 00 00 00 00 00"); /* 100 ms */
    CHECK(co_store_save(d->node, CO_CLS_PARA) == CO_OK);
    d->now = 0x90000000u - 1000000u;
    h_power_cycle(d);
    EXPECT(d, 0x740, "00");
    h_advance(d, 99999);
    EXPECT_NONE(d);
    h_advance(d, 1);
    EXPECT(d, 0x740, "7F");
}

/* A frame the board cannot queue is not sent: the sender learns it and
 * the node counts it. */
static void test_send_refused(void)
{
    boot();
    uint32_t dropped = co_node_tx_dropped(d->node);
    d->port.tx_full = true;
    CHECK(!co_emcy_send(d->node, 0x1000, 0x01, NULL));
    CHECK_EQ(co_node_tx_dropped(d->node), dropped + 1u);
    d->port.tx_full = false;
    CHECK(co_emcy_send(d->node, 0x1000, 0x01, NULL));
    EXPECT(d, 0xC0, "00 10 01 00 00 00 00 00");
}

/* The fewest objects: an EMCY on 80h + node-ID without 0x1014; an error
 * history the dictionary keeps no field of counts 0 errors; a guard time
 * without a life time factor (0x100D) is node guarding without life
 * guarding: answered, never an event. */
static void test_fewest_objects(void)
{
    h_boot(d, &n_prod_min, false);
    EXPECT(d, 0x740, "00");
    CHECK(co_emcy_error(d->node, 0xFF00, CO_ER_MANUFACTURER, true, NULL));
    EXPECT(d, 0xC0, "00 FF 81 00 00 00 00 00");
#if CO_EMCY_HIST_MAX > 0
    SDO(d, "40 03 10 00 00 00 00 00", "4F 03 10 00 00 00 00 00");
#endif
    SDO(d, "2B 0C 10 00 64 00 00 00", "60 0C 10 00 00 00 00 00"); /* 100 ms */
    co_frame_t rtr = {.id = 0x740, .rtr = true, .dlc = 1};
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x740, "7F");
    h_advance(d, 1000000);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x740, "FF");
    h_advance(d, 1000000);
    EXPECT_NONE(d);
    /* A consumer time without RAM cannot be written (read only). */
    SDO(d, "23 16 10 01 64 00 05 00", "80 16 10 01 02 00 01 06");
    /* No identity object: LSS inquiries answer 0. */
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("5A 00 00 00 00 00 00 00", "5A 00 00 00 00 00 00 00");
    LSS("5D 00 00 00 00 00 00 00", "5D 00 00 00 00 00 00 00");
}

/* A reset starts LSS afresh: waiting state, no selection sequence in
 * progress; "store configuration" keeps the node-ID for power-on. */
static void test_lss_reset_starts_afresh(void)
{
    boot();
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("5E 00 00 00 00 00 00 00", "5E 40 00 00 00 00 00 00");
    h_rx(d, 0x000, "82 40");
    LSS("5E 00 00 00 00 00 00 00", NULL); /* waiting */
    LSS("40 78 56 34 12 00 00 00", NULL);
    LSS("41 CD AB 00 00 00 00 00", NULL);
    h_rx(d, 0x000, "82 40");
    LSS("42 02 00 01 00 00 00 00", NULL);
    LSS("43 42 00 00 00 00 00 00", NULL); /* the selection began before the reset */
    LSS("5E 00 00 00 00 00 00 00", NULL);
    /* So does a switch mode global: a selection runs from its vendor part. */
    LSS("40 78 56 34 12 00 00 00", NULL);
    LSS("41 CD AB 00 00 00 00 00", NULL);
    LSS("04 00 00 00 00 00 00 00", NULL);
    LSS("42 02 00 01 00 00 00 00", NULL);
    LSS("43 42 00 00 00 00 00 00", NULL);
    LSS("04 00 00 00 00 00 00 00", NULL);
    LSS("41 CD AB 00 00 00 00 00", NULL);
    LSS("42 02 00 01 00 00 00 00", NULL);
    LSS("43 42 00 00 00 00 00 00", NULL);
    LSS("5E 00 00 00 00 00 00 00", NULL);
    /* Store without a node-ID configured stores the active one; with 1
     * configured, 1 (active after reset, and after power-on). */
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("17 00 00 00 00 00 00 00", "17 00 00 00 00 00 00 00");
    CHECK_EQ(inst()->lss.node_id, 0x40);
    LSS("11 01 00 00 00 00 00 00", "11 00 00 00 00 00 00 00");
    LSS("17 00 00 00 00 00 00 00", "17 00 00 00 00 00 00 00");
    h_power_cycle(d);
    EXPECT(d, 0x701, "00");
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("11 7F 00 00 00 00 00 00", "11 00 00 00 00 00 00 00");
    LSS("17 00 00 00 00 00 00 00", "17 00 00 00 00 00 00 00");
    h_power_cycle(d);
    EXPECT(d, 0x77F, "00");
}

int main(void)
{
    RUN(test_lss_store_in_lss_set);
    RUN(test_lss_fastscan_ignored_requests);
    RUN(test_lss_bit_timing_table);
    RUN(test_lss_switch_global_reserved_mode);
    RUN(test_lss_identity_bounds);
    RUN(test_lss_switch_selective_sequence);
    RUN(test_lss_fastscan_no_part_4);
    RUN(test_lss_reset_starts_afresh);
    RUN(test_life_guard_event_cleared_by_reset_communication);
    RUN(test_life_guard_starts_with_a_request);
    RUN(test_life_guard_event_in_stopped);
    RUN(test_guard_and_consumer_events_apart);
    RUN(test_heartbeat_consumer);
    RUN(test_heartbeat_consumer_timer);
    RUN(test_heartbeat_late_poll);
    RUN(test_nmt_state_hook);
    RUN(test_cia303_led_mapping);
    RUN(test_tpdo_mapping_longer_than_8_bytes);
    RUN(test_tpdo_mapping_count_beyond_entries);
    RUN(test_emcy_table_full_and_cobid);
    RUN(test_reset_areas);
    RUN(test_reset_forgets);
    RUN(test_comm_reset_applies_stored_id);
    RUN(test_reset_request_once);
    RUN(test_late_reset_runs_from_the_poll);
    RUN(test_start_late_in_the_clock);
    RUN(test_send_refused);
    RUN(test_fewest_objects);
    return h_finish();
}
