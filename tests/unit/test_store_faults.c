/*
 * test_store_faults.c - the parameter store beyond "save all": the CiA 301
 * groups of 0x1010 / 0x1011 sub 2..4 (communication 1000h-1FFFh,
 * application 6000h-9FFFh, manufacturer 2000h-5FFFh), the node-ID set
 * saved with the parameters only when it changed, a record in the wrong
 * class's slot, and an EEPROM read that fails at any point of a restore
 * or of a group save: a class is then all defaults (reported as a hardware
 * fault), never a mix of stored and default values, and a stored set is
 * never damaged by a failed save.
 */
#include "harness.h"

#include "co_store.h"

/* The PARA struct as bytes: 0x2001 lies across the store's 24-byte chunks. */
typedef struct s_dev {
    co_node_t node;
    uint8_t para[32];
    co_lss_para_t lss;
    unsigned stored; /* calls of the "stored" op */
    uint32_t sig;    /* its last signature */
} s_dev_t;

#define PARA(o) .cls = CO_CLS_PARA, .off = (o)
/* clang-format off */
#define SAVE(s, fn) {.index = 0x1010, .sub = (s), CO_TYPE_U32, .attr = CO_A_RW, .def = 1, CO_EXT(.write = fn)}
#define LOAD(s, fn) {.index = 0x1011, .sub = (s), CO_TYPE_U32, .attr = CO_A_RW, .def = 1, CO_EXT(.write = fn)}

static const co_od_entry_t s_entries[] = {
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_CONST, .def = 0x0000019Au},
    {.index = 0x1010, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 4},
    SAVE(1, co_store_write_save),
    SAVE(2, co_store_write_group_save),
    SAVE(3, co_store_write_group_save),
    SAVE(4, co_store_write_group_save),
    SAVE(5, co_store_write_group_save), /* a group the stack does not know */
    {.index = 0x1011, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 4},
    LOAD(1, co_store_write_load),
    LOAD(2, co_store_write_group_load),
    LOAD(3, co_store_write_group_load),
    LOAD(4, co_store_write_group_load),
    LOAD(5, co_store_write_group_load),
    {.index = 0x1017, .sub = 0, CO_TYPE_U16, .attr = CO_A_RW, PARA(0), .def = 0, CO_EXT(.write = co_hb_write_time)},
    {.index = 0x1FFF, .sub = 0, CO_TYPE_U8, .attr = CO_A_RW, PARA(2), .def = 0},
    {.index = 0x2000, .sub = 0, CO_TYPE_U32, .attr = CO_A_RW, PARA(4), .def = 100, CO_EXT(.min = 10, .max = 1000)},
    {.index = 0x2001, .sub = 0, CO_TYPE_U32, .attr = CO_A_RW, PARA(22), .def = 0xA5A5A5A5u},
    {.index = 0x5FFF, .sub = 0, CO_TYPE_U8, .attr = CO_A_RW, PARA(3), .def = 0},
    {.index = 0x6000, .sub = 0, CO_TYPE_U16, .attr = CO_A_RW, PARA(28), .def = 7},
    {.index = 0x9FFF, .sub = 0, CO_TYPE_U8, .attr = CO_A_RW, PARA(30), .def = 0},
    {.index = 0xA000, .sub = 0, CO_TYPE_U8, .attr = CO_A_RW, PARA(31), .def = 0}, /* in no group */
};
/* clang-format on */

static const co_od_t s_od = {.entries = s_entries,
                             .count = sizeof(s_entries) / sizeof(s_entries[0])};

static void s_stored(co_node_t *n, uint32_t sig)
{
    s_dev_t *t = n->app;
    t->stored++;
    t->sig = sig;
}

static const co_node_ops_t s_ops = {.stored = s_stored};

static const co_node_cfg_t s_cfg = {
    .od = &s_od,
    .ops = &s_ops,
    .ram_size = {0, 0, 32, sizeof(co_lss_para_t)},
    .default_node_id = 0x30,
    .default_bitrate = 3,
    .save_includes_lss = true,
    .id_index = 0x5FFF, /* the node-ID's object, given a factory node-ID */
};

static void s_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    (void)p;
    s_dev_t *t = mem;
    memset(t, 0, sizeof(*t));
    void *const ram[CO_CLS_COUNT] = {NULL, NULL, t->para, &t->lss};
    co_node_init(&t->node, &s_cfg, ports[0], t, ram, 0);
    nodes[0] = &t->node;
}

static void s_sample(void *mem, const int32_t v[], uint32_t fault)
{
    (void)mem;
    (void)v;
    (void)fault;
}

static const product_t s_prod = {.id = "store-faults",
                                 .inputs = {{NULL, NULL, 0, 0}},
                                 .nodes = 1,
                                 .inst_size = sizeof(s_dev_t),
                                 .create = s_create,
                                 .sample = s_sample};

static h_dev_t dev;
static h_dev_t *const d = &dev;

static s_dev_t *inst(void)
{
    return h_inst(d);
}

static void boot(void)
{
    h_boot(d, &s_prod, false);
    EXPECT(d, 0x730, "00");
}

/* Write every parameter a non-default value (RAM only). */
static void set_all(uint16_t hb, uint32_t u, uint32_t across, uint16_t app)
{
    char req[64];
    snprintf(req, sizeof(req), "2B 17 10 00 %02X %02X 00 00", hb & 0xFFu, hb >> 8);
    SDO(d, req, "60 17 10 00 00 00 00 00");
    snprintf(req, sizeof(req), "23 00 20 00 %02X %02X %02X %02X", (unsigned)(u & 0xFFu),
             (unsigned)((u >> 8) & 0xFFu), (unsigned)((u >> 16) & 0xFFu), (unsigned)(u >> 24));
    SDO(d, req, "60 00 20 00 00 00 00 00");
    snprintf(req, sizeof(req), "23 01 20 00 %02X %02X %02X %02X", (unsigned)(across & 0xFFu),
             (unsigned)((across >> 8) & 0xFFu), (unsigned)((across >> 16) & 0xFFu),
             (unsigned)(across >> 24));
    SDO(d, req, "60 01 20 00 00 00 00 00");
    snprintf(req, sizeof(req), "2B 00 60 00 %02X %02X 00 00", app & 0xFFu, app >> 8);
    SDO(d, req, "60 00 60 00 00 00 00 00");
}

/* The four values as the bus reads them, compared with what is expected. */
static void expect_all(long long hb, long long u, long long across, long long app, int line)
{
    long long got[4] = {h_read(d, 0x1017, 0), h_read(d, 0x2000, 0), h_read(d, 0x2001, 0),
                        h_read(d, 0x6000, 0)};
    long long want[4] = {hb, u, across, app};
    for (unsigned i = 0; i < 4u; i++) {
        h_checks++;
        if (got[i] != want[i]) {
            h_failures++;
            fprintf(stderr, "%s:%d: value %u is 0x%llX, expected 0x%llX\n", __FILE__, line, i,
                    got[i], want[i]);
        }
    }
}
#define EXPECT_ALL(hb, u, across, app) expect_all((hb), (u), (across), (app), __LINE__)

/* The four values are exactly set a or exactly set b; returns which (0, 1), -1: neither. */
static int which_set(const long long a[4], const long long b[4])
{
    long long got[4] = {h_read(d, 0x1017, 0), h_read(d, 0x2000, 0), h_read(d, 0x2001, 0),
                        h_read(d, 0x6000, 0)};
    if (memcmp(got, a, sizeof(got)) == 0) {
        return 0;
    }
    return memcmp(got, b, sizeof(got)) == 0 ? 1 : -1;
}

static void test_group_save(void)
{
    boot();
    set_all(100, 200, 0x11223344u, 300);
    /* Application group only: the rest stays what was stored (nothing: defaults). */
    SDO(d, "23 10 10 03 73 61 76 65", "60 10 10 03 00 00 00 00");
    CHECK_EQ(inst()->stored, 1);
    CHECK_EQ(inst()->sig, CO_SIG_SAVE);
    h_power_cycle(d);
    EXPECT_ALL(0, 100, 0xA5A5A5A5u, 300);
    /* All, then the manufacturer group alone on top of it. */
    set_all(100, 200, 0x11223344u, 300);
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    set_all(101, 201, 0x55667788u, 301);
    SDO(d, "23 10 10 04 73 61 76 65", "60 10 10 04 00 00 00 00");
    h_power_cycle(d);
    EXPECT_ALL(100, 201, 0x55667788u, 300); /* 0x2001 whole across the chunks */
    /* Communication group. */
    set_all(102, 202, 0x99AABBCCu, 302);
    SDO(d, "23 10 10 02 73 61 76 65", "60 10 10 02 00 00 00 00");
    h_power_cycle(d);
    EXPECT_ALL(102, 201, 0x55667788u, 300);
    /* Anything but "save": 0x08000020, nothing notified; the same for a
     * group sub-index beyond CiA 301's three. */
    unsigned before = inst()->stored;
    SDO(d, "23 10 10 02 73 61 76 66", "80 10 10 02 20 00 00 08");
    SDO(d, "23 11 10 03 6C 6F 61 65", "80 11 10 03 20 00 00 08");
    SDO(d, "23 10 10 05 73 61 76 65", "80 10 10 05 20 00 00 08");
    SDO(d, "23 11 10 05 6C 6F 61 64", "80 11 10 05 20 00 00 08");
    CHECK_EQ(inst()->stored, before);
    /* "load" of all: notified; one the EEPROM cannot write: an abort
     * (hardware), nothing notified. */
    SDO(d, "23 11 10 01 6C 6F 61 64", "60 11 10 01 00 00 00 00");
    CHECK_EQ(inst()->stored, before + 1u);
    CHECK_EQ(inst()->sig, CO_SIG_LOAD);
    d->port.cut_after = 0;
    SDO(d, "23 11 10 01 6C 6F 61 64", "80 11 10 01 00 00 06 06");
    d->port.cut_after = -1;
    CHECK_EQ(inst()->stored, before + 1u);
}

static void test_group_load(void)
{
    boot();
    set_all(100, 200, 0x11223344u, 300);
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    /* "load" of the application group: defaults there after the next reset,
     * running values untouched until then (CiA 301). */
    SDO(d, "23 11 10 03 6C 6F 61 64", "60 11 10 03 00 00 00 00");
    CHECK_EQ(inst()->sig, CO_SIG_LOAD);
    EXPECT_ALL(100, 200, 0x11223344u, 300);
    h_rx(d, 0x000, "81 30");
    EXPECT_ALL(100, 200, 0x11223344u, 7);
    /* Manufacturer group (0x2001 across the chunks too), then communication. */
    SDO(d, "23 11 10 04 6C 6F 61 64", "60 11 10 04 00 00 00 00");
    h_power_cycle(d);
    EXPECT_ALL(100, 100, 0xA5A5A5A5u, 7);
    SDO(d, "23 11 10 02 6C 6F 61 64", "60 11 10 02 00 00 00 00");
    h_power_cycle(d);
    EXPECT_ALL(0, 100, 0xA5A5A5A5u, 7);
}

/* After "load all", a group save keeps the other groups at their defaults:
 * the restore that "load" asked for still happens to them. */
static void test_group_save_after_load(void)
{
    boot();
    set_all(100, 200, 0x11223344u, 300);
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    SDO(d, "23 11 10 01 6C 6F 61 64", "60 11 10 01 00 00 00 00");
    SDO(d, "23 10 10 03 73 61 76 65", "60 10 10 03 00 00 00 00");
    h_power_cycle(d);
    EXPECT_ALL(0, 100, 0xA5A5A5A5u, 300);
    CHECK_EQ(d->node->node_id, 0x30);
}

/* "save" writes the node-ID set only when it changed: no EEPROM write
 * cycle is spent on an unchanged one (the write-cycle limit counts them). */
static void test_unchanged_lss_set_not_rewritten(void)
{
    boot();
    uint32_t w0 = d->node->store.writes;
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    uint32_t w1 = d->node->store.writes;
    CHECK_EQ(w1 - w0, 2); /* first save: both sets */
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    CHECK_EQ(d->node->store.writes - w1, 1); /* the parameters only */
    h_drain(d);
    h_power_cycle(d); /* the count is the newest record's, the parameters' here */
    EXPECT(d, 0x730, "00");
    CHECK_EQ(d->node->store.writes, w1 + 1u);
    inst()->lss.node_id = 0x31; /* the product changed its node-ID set */
    w1 = d->node->store.writes;
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    CHECK_EQ(d->node->store.writes - w1, 2);
    h_drain(d);
    h_power_cycle(d);
    EXPECT(d, 0x731, "00");
    /* "load" of everything brings the default node-ID back at the next reset. */
    SDO(d, "23 11 10 01 6C 6F 61 64", "60 11 10 01 00 00 00 00");
    h_drain(d);
    h_power_cycle(d);
    EXPECT(d, 0x730, "00");
    /* A class that is not stored cannot be saved, and restores nothing. */
    CHECK(co_store_save(d->node, CO_CLS_VOL) == CO_E_STORE);
    CHECK(co_store_save(d->node, CO_CLS_NONE) == CO_E_STORE);
    CHECK(co_store_restore(d->node, CO_CLS_VOL, 0, 0xFFFF) == CO_STORE_BLANK);
    CHECK(co_store_restore(d->node, CO_CLS_NONE, 0, 0xFFFF) == CO_STORE_BLANK);
}

/* A valid record of the parameters copied into the node-ID set's slots is
 * not that set: it is refused (corrupt, defaults), never applied. */
static void test_record_of_other_class_refused(void)
{
    boot();
    set_all(100, 200, 0x11223344u, 300);
    inst()->lss.node_id = 0x31;
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    /* PARA: slots 0 and 1 (a first save goes to 0); LSS: slots 2 and 3. */
    memcpy(&d->port.nvm[2u * CO_STORE_SLOT], &d->port.nvm[0], CO_STORE_SLOT);
    memcpy(&d->port.nvm[3u * CO_STORE_SLOT], &d->port.nvm[0], CO_STORE_SLOT);
    h_drain(d);
    h_power_cycle(d);
    EXPECT(d, 0x730, "00");
    CHECK_EQ(d->node->store.status[CO_CLS_LSS], CO_STORE_CORRUPT);
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_OK);
    EXPECT_ALL(100, 200, 0x11223344u, 300);
}

/* Power-on with the EEPROM failing at every read in turn: each class is
 * either its stored set (status OK) or all defaults (status HW). */
static void test_read_fault_at_every_read_of_power_on(void)
{
    boot();
    set_all(100, 200, 0x11223344u, 300);
    inst()->lss.node_id = 0x31;
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    unsigned faults = 0;
    for (long k = 0; k < 1000; k++) {
        d->port.reads_left = k;
        d->port.read_faults = 0;
        h_power_cycle(d);
        bool hit = d->port.read_faults != 0;
        d->port.reads_left = -1;
        uint8_t ps = d->node->store.status[CO_CLS_PARA];
        uint8_t ls = d->node->store.status[CO_CLS_LSS];
        CHECK(ps == CO_STORE_OK || ps == CO_STORE_HW);
        CHECK(ls == CO_STORE_OK || ls == CO_STORE_HW);
        if (ps == CO_STORE_OK) {
            EXPECT_ALL(100, 200, 0x11223344u, 300);
        } else {
            EXPECT_ALL(0, 100, 0xA5A5A5A5u, 7);
        }
        CHECK_EQ(d->node->node_id, ls == CO_STORE_OK ? 0x31 : 0x30);
        faults += ps == CO_STORE_HW || ls == CO_STORE_HW;
        if (!hit) {
            CHECK(ps == CO_STORE_OK && ls == CO_STORE_OK);
            break;
        }
    }
    CHECK(faults >= 4); /* both classes' headers, data and copies were hit */
}

/* Reset communication with the EEPROM failing at every read in turn: the
 * communication group is stored or default, the application's running
 * values are never touched. */
static void test_read_fault_in_reset_communication(void)
{
    boot();
    set_all(100, 200, 0x11223344u, 300);
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    unsigned faults = 0;
    for (long k = 0; k < 1000; k++) {
        set_all(150, 555, 0x01020304u, 666);
        d->port.reads_left = k;
        d->port.read_faults = 0;
        h_rx(d, 0x000, "82 30");
        bool hit = d->port.read_faults != 0;
        d->port.reads_left = -1;
        uint8_t ps = d->node->store.status[CO_CLS_PARA];
        CHECK(ps == CO_STORE_OK || ps == CO_STORE_HW);
        EXPECT_ALL(ps == CO_STORE_OK ? 100 : 0, 555, 0x01020304u, 666);
        faults += ps == CO_STORE_HW;
        if (!hit) {
            break;
        }
    }
    CHECK(faults >= 2);
}

/* A group save must read the other groups' stored values: when a read
 * fails the save is refused. After it, power-on finds the old set or the
 * new one (the parameters may be stored when only the node-ID set's save
 * failed: the answer is still an abort), never a mix or defaults. */
static void test_read_fault_in_group_save(void)
{
    static const long long old_set[4] = {100, 200, 0x11223344, 300};
    static const long long new_set[4] = {100, 200, 0x11223344, 301}; /* group 3 only */
    boot();
    set_all(100, 200, 0x11223344u, 300);
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    unsigned refused = 0;
    for (long k = 0; k < 1000; k++) {
        set_all(101, 201, 0x55667788u, 301);
        d->port.reads_left = k;
        d->port.read_faults = 0;
        h_drain(d);
        h_rx(d, 0x630, "23 10 10 03 73 61 76 65");
        bool hit = d->port.read_faults != 0;
        d->port.reads_left = -1;
        const co_frame_t *f = h_next(d);
        CHECK(f != NULL && f->id == 0x5B0);
        bool ok = f != NULL && f->data[0] == 0x60u;
        h_power_cycle(d);
        int got = which_set(old_set, new_set);
        CHECK(got == 1 || (!ok && got == 0));
        if (!hit) {
            CHECK(ok);
            break;
        }
        /* Not the abort code of a failed save: what matters here is the
         * abort and that a whole stored set survived. */
        CHECK(!ok);
        refused++;
        set_all(100, 200, 0x11223344u, 300);
        SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    }
    CHECK(refused >= 10);
}

/* "save all" with the EEPROM failing at every read in turn, both slots
 * holding records: success and the new set at power-on, or an abort and
 * the old set or the new one (the node-ID set's save may be what failed).
 * A save that cannot read the slots must not guess where to write: its
 * record could lose to the older one and be forgotten after an "OK". */
static void test_read_fault_in_save_all(void)
{
    static const long long old_set[4] = {100, 200, 0x11223344, 300};
    static const long long new_set[4] = {101, 201, 0x55667788, 301};
    boot();
    unsigned refused = 0;
    for (long k = 0; k < 1000; k++) {
        set_all(100, 200, 0x11223344u, 300);
        SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
        SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00"); /* both slots used */
        set_all(101, 201, 0x55667788u, 301);
        inst()->lss.node_id = (uint8_t)(0x31 + (k & 1)); /* the node-ID set changed too */
        d->port.reads_left = k;
        d->port.read_faults = 0;
        h_drain(d);
        h_rx(d, 0x630, "23 10 10 01 73 61 76 65");
        bool hit = d->port.read_faults != 0;
        d->port.reads_left = -1;
        const co_frame_t *f = h_next(d);
        CHECK(f != NULL && f->id == 0x5B0);
        bool ok = f != NULL && f->data[0] == 0x60u;
        h_power_cycle(d);
        int got = which_set(old_set, new_set);
        CHECK(got == 1 || (!ok && got == 0));
        if (!hit) {
            CHECK(ok);
            break;
        }
        CHECK(!ok);
        refused++;
    }
    CHECK(refused >= 10);
}

/* The edges of the groups (0x1FFF, 0x2000, 0x5FFF, 0x6000, 0x9FFF) belong
 * to their group alone, and 0xA000 to none: a group save stores what is in
 * its range and keeps the stored (here: default) value of the rest. */
static void test_group_edges(void)
{
    static const uint16_t edge[4] = {0x1FFF, 0x5FFF, 0x9FFF, 0xA000};
    static const char *const save[3] = {"23 10 10 02 73 61 76 65", "23 10 10 04 73 61 76 65",
                                        "23 10 10 03 73 61 76 65"};
    for (unsigned g = 0; g < 3u; g++) {
        boot();
        set_all(100, 200, 0x11223344u, 300);
        for (unsigned i = 0; i < 4u; i++) {
            char req[64];
            char resp[64];
            snprintf(req, sizeof(req), "2F %02X %02X 00 %02X 00 00 00", edge[i] & 0xFFu,
                     edge[i] >> 8, i + 1u);
            snprintf(resp, sizeof(resp), "60 %02X %02X 00 00 00 00 00", edge[i] & 0xFFu,
                     edge[i] >> 8);
            SDO(d, req, resp);
        }
        h_drain(d);
        h_rx(d, 0x630, save[g]);
        const co_frame_t *f = h_next(d);
        CHECK(f != NULL && f->data[0] == 0x60);
        h_power_cycle(d);
        /* Group g holds edge g only (comm: 0x1FFF, manufacturer: 0x5FFF, application: 0x9FFF). */
        for (unsigned i = 0; i < 4u; i++) {
            CHECK_EQ(h_read(d, edge[i], 0), i == g ? (long long)(i + 1u) : 0);
        }
        EXPECT_ALL(g == 0u ? 100 : 0, g == 1u ? 200 : 100, g == 1u ? 0x11223344u : 0xA5A5A5A5u,
                   g == 2u ? 300 : 7);
    }
}

/* Reset communication restores the stored communication objects, up to
 * the area's last index 0x1FFF, and leaves the others' running values. */
static void test_reset_communication_restores_its_area(void)
{
    boot();
    set_all(100, 200, 0x11223344u, 300);
    SDO(d, "2F FF 1F 00 09 00 00 00", "60 FF 1F 00 00 00 00 00");
    SDO(d, "2F FF 5F 00 09 00 00 00", "60 FF 5F 00 00 00 00 00");
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    set_all(101, 201, 0x55667788u, 301);
    SDO(d, "2F FF 1F 00 01 00 00 00", "60 FF 1F 00 00 00 00 00");
    SDO(d, "2F FF 5F 00 01 00 00 00", "60 FF 5F 00 00 00 00 00");
    h_rx(d, 0x000, "82 30");
    EXPECT(d, 0x730, "00");
    EXPECT_ALL(100, 201, 0x55667788u, 301);
    CHECK_EQ(h_read(d, 0x1FFF, 0), 9);
    CHECK_EQ(h_read(d, 0x5FFF, 0), 1);
}

/* A record under another magic is none of ours, even with a CRC that
 * matches it (another firmware's data): the set is reported corrupt and
 * its defaults are used. */
static void test_record_without_its_magic(void)
{
    boot();
    set_all(100, 200, 0x11223344u, 300);
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00"); /* slot 0 only */
    d->port.nvm[0] ^= 0x01u;
    co_put_u32(&d->port.nvm[CO_STORE_HDR + 32u], co_crc32(0, d->port.nvm, CO_STORE_HDR + 32u));
    h_power_cycle(d);
    EXPECT(d, 0x730, "00");
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_CORRUPT);
    EXPECT_ALL(0, 100, 0xA5A5A5A5u, 7);
}

/* The smallest parameter set, one byte, is stored and restored too. */
typedef struct one_dev {
    co_node_t node;
    uint8_t para;
} one_dev_t;

/* clang-format off */
static const co_od_entry_t one_entries[] = {
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_CONST, .def = 0},
    {.index = 0x1010, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 1},
    SAVE(1, co_store_write_save),
    {.index = 0x2000, .sub = 0, CO_TYPE_U8, .attr = CO_A_RW, PARA(0), .def = 7},
};
/* clang-format on */

static const co_od_t one_od = {.entries = one_entries,
                               .count = sizeof(one_entries) / sizeof(one_entries[0])};

static const co_node_cfg_t one_cfg = {
    .od = &one_od,
    .ram_size = {0, 0, 1, 0},
    .default_node_id = 0x31,
};

static void one_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    (void)p;
    one_dev_t *t = mem;
    memset(t, 0, sizeof(*t));
    void *const ram[CO_CLS_COUNT] = {NULL, NULL, &t->para, NULL};
    co_node_init(&t->node, &one_cfg, ports[0], t, ram, 0);
    nodes[0] = &t->node;
}

static const product_t one_prod = {.id = "one byte",
                                   .inputs = {{NULL, NULL, 0, 0}},
                                   .nodes = 1,
                                   .inst_size = sizeof(one_dev_t),
                                   .create = one_create,
                                   .sample = s_sample};

/* The same with its node-ID object named as 0x1000, a constant: a broken
 * contract (co_node_cfg_t.id_index names a PARA object). */
static const co_node_cfg_t bad_id_cfg = {
    .od = &one_od,
    .ram_size = {0, 0, 1, 0},
    .default_node_id = 0x31,
    .id_index = 0x1000,
};

static void bad_id_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    (void)p;
    one_dev_t *t = mem;
    memset(t, 0, sizeof(*t));
    void *const ram[CO_CLS_COUNT] = {NULL, NULL, &t->para, NULL};
    co_node_init(&t->node, &bad_id_cfg, ports[0], t, ram, 0);
    nodes[0] = &t->node;
}

static const product_t bad_id_prod = {.id = "bad id object",
                                      .inputs = {{NULL, NULL, 0, 0}},
                                      .nodes = 1,
                                      .inst_size = sizeof(one_dev_t),
                                      .create = bad_id_create,
                                      .sample = s_sample};

static void test_one_byte_set(void)
{
    h_boot(d, &one_prod, false);
    EXPECT(d, 0x731, "00");
    SDO(d, "2F 00 20 00 42 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    h_power_cycle(d);
    EXPECT(d, 0x731, "00");
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_OK);
    CHECK_EQ(h_read(d, 0x2000, 0), 0x42);
}

/* A node whose records end where the EEPROM ends, with a node-ID set that
 * fills its slots (the product keeps more beside node-ID and bit rate):
 * saved into both slots, every byte and the CRC read back, nothing past
 * the end. */
typedef struct big_lss {
    co_lss_para_t id;
    uint8_t more[CO_STORE_MAX_DATA - sizeof(co_lss_para_t)];
} big_lss_t;

typedef struct end_dev {
    co_node_t node;
    uint8_t para[1];
    big_lss_t lss;
} end_dev_t;

static const co_node_cfg_t end_cfg = {
    .od = &one_od,
    .ram_size = {0, 0, 1, sizeof(big_lss_t)},
    .default_node_id = 0x32,
    .save_includes_lss = true,
};

static void end_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    (void)p;
    end_dev_t *t = mem;
    memset(t, 0, sizeof(*t));
    void *const ram[CO_CLS_COUNT] = {NULL, NULL, t->para, &t->lss};
    co_node_init(&t->node, &end_cfg, ports[0], t, ram, FAKE_NVM_SIZE - CO_STORE_NVM_SIZE);
    nodes[0] = &t->node;
}

static const product_t end_prod = {.id = "at the end",
                                   .inputs = {{NULL, NULL, 0, 0}},
                                   .nodes = 1,
                                   .inst_size = sizeof(end_dev_t),
                                   .create = end_create,
                                   .sample = s_sample};

static void test_records_at_the_end_of_the_eeprom(void)
{
    _Static_assert(sizeof(big_lss_t) == CO_STORE_MAX_DATA, "the node-ID set fills its slot");
    h_boot(d, &end_prod, false);
    EXPECT(d, 0x732, "00");
    end_dev_t *t = h_inst(d);
    for (unsigned k = 0; k < 2u; k++) { /* both slots */
        t->lss.more[sizeof(t->lss.more) - 1u] = (uint8_t)(0x5Au + k);
        SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    }
    h_power_cycle(d);
    EXPECT(d, 0x732, "00");
    t = h_inst(d);
    CHECK_EQ(d->node->store.status[CO_CLS_LSS], CO_STORE_OK);
    CHECK_EQ(t->lss.more[sizeof(t->lss.more) - 1u], 0x5B);
    /* Unchanged, all of its chunks compared: not written again. */
    uint32_t w = d->node->store.writes;
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    CHECK_EQ(d->node->store.writes - w, 1);
}

/* Two valid records of one sequence number (never written so by a save:
 * each takes the newest one's number + 1) are a tie the first slot wins,
 * the same at every power-on. */
static void test_sequence_tie(void)
{
    boot();
    set_all(100, 200, 0x11223344u, 300);
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00"); /* slot 0 */
    uint8_t *s1 = &d->port.nvm[CO_STORE_SLOT];
    memcpy(s1, d->port.nvm, CO_STORE_SLOT);
    co_put_u16(&s1[CO_STORE_HDR], 101); /* 0x1017 */
    co_put_u32(&s1[CO_STORE_HDR + 32u], co_crc32(0, s1, CO_STORE_HDR + 32u));
    h_power_cycle(d);
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_OK);
    EXPECT_ALL(100, 200, 0x11223344u, 300);
}

/* Given a factory node-ID, the node-ID's own object (id_index) takes it as
 * its default: with nothing stored, and not over a stored value when only
 * the node-ID set has nothing stored. An id_index naming no PARA object is
 * a broken contract, reported (CO_CHECK) at each reset. */
static void test_node_id_object_default(void)
{
    static const uint8_t ids[PRODUCT_MAX_NODES] = {0x40};
    h_boot_ids(d, &s_prod, ids);
    EXPECT(d, 0x740, "00");
    CHECK_EQ(h_read(d, 0x5FFF, 0), 0x40);
    SDO(d, "2F FF 5F 00 22 00 00 00", "60 FF 5F 00 00 00 00 00");
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    memset(&d->port.nvm[2u * CO_STORE_SLOT], 0xFF, 2u * CO_STORE_SLOT); /* the node-ID set: blank */
    h_power_cycle(d);
    EXPECT(d, 0x740, "00");
    CHECK_EQ(d->node->store.status[CO_CLS_LSS], CO_STORE_BLANK);
    CHECK_EQ(h_read(d, 0x5FFF, 0), 0x22);
    unsigned seen = h_asserts;
    h_expect_assert(1);
    static const uint8_t ids1[PRODUCT_MAX_NODES] = {0x41};
    h_boot_ids(d, &bad_id_prod, ids1);
    CHECK_EQ(h_asserts, seen + 1u);
    EXPECT(d, 0x741, "00");
}

/* A corrupt set stays reported until a full save (co_store.h): a group
 * save or a "load" leaves it so; "save all" makes it sound again. */
static void test_corrupt_until_full_save(void)
{
    boot();
    set_all(100, 200, 0x11223344u, 300);
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    d->port.nvm[CO_STORE_HDR + 5u] ^= 0x5Au; /* slot 0's data: its CRC fails */
    h_power_cycle(d);
    EXPECT(d, 0x730, "00");
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_CORRUPT);
    SDO(d, "23 10 10 03 73 61 76 65", "60 10 10 03 00 00 00 00");
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_CORRUPT);
    SDO(d, "23 11 10 01 6C 6F 61 64", "60 11 10 01 00 00 00 00");
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_CORRUPT);
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_OK);
}

/* "save" after a "load" (before the reset that would apply it) stores the
 * running sets again, the node-ID set too: the load is undone. */
static void test_save_after_load(void)
{
    boot();
    inst()->lss.node_id = 0x31; /* the product changed its node-ID set */
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    SDO(d, "23 11 10 01 6C 6F 61 64", "60 11 10 01 00 00 00 00");
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    h_drain(d);
    h_power_cycle(d);
    EXPECT(d, 0x731, "00");
    CHECK_EQ(d->node->store.status[CO_CLS_LSS], CO_STORE_OK);
}

/* A stored set whose CRC holds but whose 0x2000 is out of its range
 * (other firmware's, or forged): 0x2000 takes its default and the set is
 * reported corrupt. Reset communication restores the communication area
 * only, so the report stays; reset node judges the whole set afresh. */
static void test_corrupt_report_across_resets(void)
{
    boot();
    set_all(100, 200, 0x11223344u, 300);
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00"); /* slot 0 */
    co_put_u32(&d->port.nvm[CO_STORE_HDR + 4u], 5000u);
    co_put_u32(&d->port.nvm[CO_STORE_HDR + 32u], co_crc32(0, d->port.nvm, CO_STORE_HDR + 32u));
    h_power_cycle(d);
    EXPECT(d, 0x730, "00");
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_CORRUPT);
    EXPECT_ALL(100, 100, 0x11223344u, 300);
    h_rx(d, 0x000, "82 30");
    EXPECT(d, 0x730, "00");
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_CORRUPT);
    /* Any restore of part of the set (co_store_restore), from index 0 too. */
    CHECK_EQ(co_store_restore(d->node, CO_CLS_PARA, 0x0000, 0x1FFF), CO_STORE_OK);
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_CORRUPT);
    /* Repaired: a set marked corrupt (here by the product) is sound again
     * once a reset node finds it so. */
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    co_store_mark_corrupt(d->node, CO_CLS_PARA);
    h_rx(d, 0x000, "82 30");
    EXPECT(d, 0x730, "00");
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_CORRUPT);
    h_rx(d, 0x000, "81 30");
    EXPECT(d, 0x730, "00");
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_OK);
}

/* A product that reports a corrupt stored set with EMCY 6300h from its
 * poll hook (co_store_report_emcy): while stopped nothing is raised, so
 * that the EMCY goes out once pre-operational (CiA 301: none in stopped). */
static uint32_t r_poll(co_node_t *n, uint32_t now)
{
    (void)now;
    co_store_report_emcy(n);
    return CO_NEVER;
}

static const co_node_ops_t r_ops = {.poll = r_poll};

static const co_node_cfg_t r_cfg = {
    .od = &s_od,
    .ops = &r_ops,
    .ram_size = {0, 0, 32, sizeof(co_lss_para_t)},
    .default_node_id = 0x30,
};

static void r_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    (void)p;
    s_dev_t *t = mem;
    memset(t, 0, sizeof(*t));
    void *const ram[CO_CLS_COUNT] = {NULL, NULL, t->para, &t->lss};
    co_node_init(&t->node, &r_cfg, ports[0], t, ram, 0);
    nodes[0] = &t->node;
}

static const product_t r_prod = {.id = "emcy 6300h",
                                 .inputs = {{NULL, NULL, 0, 0}},
                                 .nodes = 1,
                                 .inst_size = sizeof(s_dev_t),
                                 .create = r_create,
                                 .sample = s_sample};

static void test_corrupt_set_emcy_after_stopped(void)
{
    h_boot(d, &r_prod, false);
    EXPECT(d, 0x730, "00");
    h_advance(d, 1000);
    EXPECT_NONE(d); /* nothing stored: nothing to report */
    h_rx(d, 0x000, "02 30");
    co_store_mark_corrupt(d->node, CO_CLS_PARA);
    co_node_wake(d->node); /* polled while stopped */
    h_advance(d, 1000);
    EXPECT_NONE(d);
    h_rx(d, 0x000, "80 30");
    h_advance(d, 1000);
    EXPECT(d, 0xB0, "00 63 01 00 00 00 00 00");
    EXPECT_NONE(d);
}

/* The same product saves no node-ID set with its parameters: a group save
 * whose reads fail at any point is answered with an abort, never "done",
 * and the old set stays. */
static void test_read_fault_in_group_save_alone(void)
{
    static const long long old_set[4] = {100, 200, 0x11223344, 300};
    static const long long new_set[4] = {100, 200, 0x11223344, 301}; /* group 3 only */
    h_boot(d, &r_prod, false);
    EXPECT(d, 0x730, "00");
    set_all(100, 200, 0x11223344u, 300);
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    unsigned refused = 0;
    for (long k = 0; k < 1000; k++) {
        set_all(101, 201, 0x55667788u, 301);
        d->port.reads_left = k;
        d->port.read_faults = 0;
        h_drain(d);
        h_rx(d, 0x630, "23 10 10 03 73 61 76 65");
        bool hit = d->port.read_faults != 0;
        d->port.reads_left = -1;
        const co_frame_t *f = h_next(d);
        CHECK(f != NULL && f->id == 0x5B0);
        bool ok = f != NULL && f->data[0] == 0x60u;
        CHECK(ok == !hit);
        h_drain(d);
        h_power_cycle(d);
        h_drain(d);
        CHECK_EQ(which_set(old_set, new_set), ok ? 1 : 0);
        if (!hit) {
            break;
        }
        refused++;
        set_all(100, 200, 0x11223344u, 300);
        SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    }
    CHECK(refused >= 10);
}

/* The slot at NVM offset at holds exactly these bytes (hex). */
static void expect_slot(unsigned at, const char *hex, int line)
{
    uint8_t want[CO_STORE_SLOT];
    unsigned n = h_hex(hex, want, sizeof(want));
    for (unsigned i = 0; i < n; i++) {
        h_checks++;
        if (d->port.nvm[at + i] != want[i]) {
            h_failures++;
            fprintf(stderr, "%s:%d: NVM byte %u is %02X, expected %02X\n", __FILE__, line, at + i,
                    d->port.nvm[at + i], want[i]);
        }
    }
}
/* clang-format off */
#define EXPECT_SLOT(k, hex) expect_slot((k) * CO_STORE_SLOT, (hex), __LINE__)
/* clang-format on */

/*
 * The record format (co_store.h) is what a device in the field holds: a
 * later firmware with the same dictionary layout must read it, so the
 * bytes are fixed. Little-endian header: magic "CoPS", the layout hash
 * (FNV-1a over index, sub-index, size and offset of each entry of the
 * class, then XOR the class's size), sequence, write count, data length,
 * flags (1: "load" asked for defaults), class (2 parameters, 3 node-ID
 * set), four zero bytes; the data; CRC-32 (IEEE 802.3) over both. The
 * expected hashes and CRCs were computed apart from the firmware.
 */
static void test_record_bytes(void)
{
    static const char s[] = "123456789";
    CHECK_EQ(co_crc32(0, s, 9), 0xCBF43926u);                     /* the CRC-32 check value */
    CHECK_EQ(co_crc32(co_crc32(0, s, 4), s + 4, 5), 0xCBF43926u); /* chained */
    CHECK_EQ(co_crc32(0x12345678u, s, 0), 0x12345678u);
    boot();
    set_all(100, 200, 0x11223344u, 300);
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    /* The parameters: slot 0, sequence 1, the first write. */
    EXPECT_SLOT(0, "43 6F 50 53 D7 1A 7F DA 01 00 00 00 01 00 00 00 20 00 00 02 00 00 00 00 "
                   "64 00 00 00 C8 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 44 33 "
                   "22 11 00 00 2C 01 00 00 91 78 F6 5F");
    /* The node-ID set (0x30, bit-rate code 3): slot 2, the second write. */
    EXPECT_SLOT(2, "43 6F 50 53 C7 9D 1C 81 01 00 00 00 02 00 00 00 02 00 00 03 00 00 00 00 "
                   "30 03 2D E1 42 69");
    /* "load": records of no data with the defaults flag, in the other slots. */
    SDO(d, "23 11 10 01 6C 6F 61 64", "60 11 10 01 00 00 00 00");
    EXPECT_SLOT(1, "43 6F 50 53 D7 1A 7F DA 02 00 00 00 03 00 00 00 00 00 01 02 00 00 00 00 "
                   "59 81 50 86");
    EXPECT_SLOT(3, "43 6F 50 53 C7 9D 1C 81 02 00 00 00 04 00 00 00 00 00 01 03 00 00 00 00 "
                   "F9 44 91 0D");
    EXPECT_SLOT(0, "43 6F 50 53 D7 1A 7F DA 01 00 00 00 01 00 00 00 20 00 00 02"); /* kept */
}

int main(void)
{
    RUN(test_record_bytes);
    RUN(test_group_edges);
    RUN(test_reset_communication_restores_its_area);
    RUN(test_record_without_its_magic);
    RUN(test_one_byte_set);
    RUN(test_records_at_the_end_of_the_eeprom);
    RUN(test_sequence_tie);
    RUN(test_node_id_object_default);
    RUN(test_corrupt_until_full_save);
    RUN(test_save_after_load);
    RUN(test_corrupt_report_across_resets);
    RUN(test_corrupt_set_emcy_after_stopped);
    RUN(test_read_fault_in_group_save_alone);
    RUN(test_group_save);
    RUN(test_group_load);
    RUN(test_group_save_after_load);
    RUN(test_unchanged_lss_set_not_rewritten);
    RUN(test_record_of_other_class_refused);
    RUN(test_read_fault_at_every_read_of_power_on);
    RUN(test_read_fault_in_reset_communication);
    RUN(test_read_fault_in_group_save);
    RUN(test_read_fault_in_save_all);
    return h_finish();
}
