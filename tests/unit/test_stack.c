/*
 * test_stack.c - the portable stack against a test dictionary that uses
 * every feature (long strings, writable PDO parameters, inhibit time,
 * limits of signed and unsigned types), frame-exact, on a virtual clock.
 */
#include "co_filter.h"
#include "dst.h"
#include "harness.h"

typedef struct t_para {
    uint32_t sync_cob;
    uint32_t emcy_cob;
    uint16_t hb;
    uint32_t cob[2];
    uint8_t type[2];
    uint16_t inhibit[2];
    uint16_t event[2];
    uint32_t u32;
    int16_t i16;
    uint16_t guard_ms;
    uint8_t life_factor;
    uint8_t map1_count;
    uint32_t map1[2];
} t_para_t;

typedef struct t_vol {
    uint32_t scratch;
    uint32_t counter;
} t_vol_t;

typedef struct t_dev {
    co_node_t node;
    t_para_t para;
    t_vol_t vol;
    co_lss_para_t lss;
} t_dev_t;

#define P(f) CO_AT(CO_CLS_PARA, t_para_t, f)
#define V(f) CO_AT(CO_CLS_VOL, t_vol_t, f)
#define TPW CO_EXT(.write = co_tpdo_write_comm)

/* clang-format off */
static const co_od_entry_t t_entries[] = {
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_CONST, .def = 0x12345678u},
    {.index = 0x1001, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, CO_EXT(.read = co_emcy_read_register)},
    {.index = 0x1003, .sub = 0, CO_TYPE_U8, .attr = CO_A_RW, CO_EXT(.write = co_emcy_write_hist, .read = co_emcy_read_hist)},
    {.index = 0x1003, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, CO_EXT(.read = co_emcy_read_hist)},
    {.index = 0x1003, .sub = 2, CO_TYPE_U32, .attr = CO_A_R, CO_EXT(.read = co_emcy_read_hist)},
    {.index = 0x1005, .sub = 0, CO_TYPE_U32, .attr = CO_A_RW, P(sync_cob), .def = 0x80, CO_EXT(.write = co_sync_write_cobid)},
    {.index = 0x1008, .sub = 0, CO_TYPE_STR("A long device name for segmented transfer"), .attr = CO_A_R | CO_A_CONST},
    {.index = 0x100C, .sub = 0, CO_TYPE_U16, .attr = CO_A_RW, P(guard_ms), .def = 0},
    {.index = 0x100D, .sub = 0, CO_TYPE_U8, .attr = CO_A_RW, P(life_factor), .def = 0},
    {.index = 0x1010, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 1},
    {.index = 0x1010, .sub = 1, CO_TYPE_U32, .attr = CO_A_W, CO_EXT(.write = co_store_write_save)},
    {.index = 0x1011, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 1},
    {.index = 0x1011, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW, .def = 1, CO_EXT(.write = co_store_write_load)},
    {.index = 0x1014, .sub = 0, CO_TYPE_U32, .attr = CO_A_RW | CO_A_NODEID, P(emcy_cob), .def = 0x80, CO_EXT(.write = co_emcy_write_cobid)},
    {.index = 0x1017, .sub = 0, CO_TYPE_U16, .attr = CO_A_RW, P(hb), .def = 0, CO_EXT(.write = co_hb_write_time)},
    {.index = 0x1800, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 5},
    {.index = 0x1800, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW | CO_A_NODEID, TPW, P(cob[0]), .def = 0x180},
    {.index = 0x1800, .sub = 2, CO_TYPE_U8, .attr = CO_A_RW, TPW, P(type[0]), .def = 254},
    {.index = 0x1800, .sub = 3, CO_TYPE_U16, .attr = CO_A_RW, TPW, P(inhibit[0]), .def = 0},
    {.index = 0x1800, .sub = 5, CO_TYPE_U16, .attr = CO_A_RW, TPW, P(event[0]), .def = 100},
    {.index = 0x1801, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 5},
    {.index = 0x1801, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW | CO_A_NODEID, P(cob[1]), .def = 0x280, CO_EXT(.write = co_tpdo_write_cobid)},
    {.index = 0x1801, .sub = 2, CO_TYPE_U8, .attr = CO_A_RW, TPW, P(type[1]), .def = 1},
    {.index = 0x1801, .sub = 3, CO_TYPE_U16, .attr = CO_A_RW, TPW, P(inhibit[1]), .def = 0},
    {.index = 0x1801, .sub = 5, CO_TYPE_U16, .attr = CO_A_RW, TPW, P(event[1]), .def = 0},
    {.index = 0x1A00, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 2},
    {.index = 0x1A00, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, .def = 0x21000020u},
    {.index = 0x1A00, .sub = 2, CO_TYPE_U32, .attr = CO_A_R, .def = 0x20010010u},
    {.index = 0x1A01, .sub = 0, CO_TYPE_U8, .attr = CO_A_RW, P(map1_count), .def = 1, CO_EXT(.write = co_tpdo_write_map)},
    {.index = 0x1A01, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW, P(map1[0]), .def = 0x20020020u, CO_EXT(.write = co_tpdo_write_map)}, /* not mappable */
    {.index = 0x1A01, .sub = 2, CO_TYPE_U32, .attr = CO_A_RW, P(map1[1]), .def = 0, CO_EXT(.write = co_tpdo_write_map)},
    {.index = 0x2000, .sub = 0, CO_TYPE_U32, .attr = CO_A_RW, P(u32), .def = 100, CO_EXT(.min = 10, .max = 1000)},
    {.index = 0x2001, .sub = 0, CO_TYPE_I16, .attr = CO_A_RW | CO_A_PDO, P(i16), .def = (uint32_t)-5, CO_EXT(.min = -100, .max = 100)},
    {.index = 0x2002, .sub = 0, CO_TYPE_U32, .attr = CO_A_RW, V(scratch), .def = 7},
    {.index = 0x2100, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_PDO, V(counter), .def = 0},
};
/* clang-format on */

static const co_od_t t_od = {.entries = t_entries,
                             .count = sizeof(t_entries) / sizeof(t_entries[0])};

static const co_service_t *const t_services[] = {&co_guard_service, &co_rtr_service, NULL};

static const co_node_cfg_t t_cfg = {
    .od = &t_od,
    .services = t_services,
    .sdo_segmented = co_sdo_segmented,
    .sdo_block = co_sdo_block,
    .ram_size = {0, sizeof(t_vol_t), sizeof(t_para_t), sizeof(co_lss_para_t)},
    .default_node_id = 0x10,
};

static void t_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    (void)p;
    t_dev_t *t = mem;
    memset(t, 0, sizeof(*t));
    void *const ram[CO_CLS_COUNT] = {NULL, &t->vol, &t->para, &t->lss};
    co_node_init(&t->node, &t_cfg, ports[0], t, ram, 0);
    nodes[0] = &t->node;
}

static void t_sample(void *mem, const int32_t v[], uint32_t fault)
{
    (void)v;
    (void)fault;
    ((t_dev_t *)mem)->vol.counter++;
}

static const product_t t_prod = {.id = "test",
                                 .inputs = {{NULL, NULL, 0, 0}},
                                 .nodes = 1,
                                 .inst_size = sizeof(t_dev_t),
                                 .create = t_create,
                                 .sample = t_sample};

static h_dev_t dev;
static h_dev_t *const d = &dev;

static void boot(void)
{
    h_boot(d, &t_prod, false);
    EXPECT(d, 0x710, "00");
}

static void test_od_find(void)
{
    co_res_t r;
    CHECK(co_od_find(&t_od, 0x1000, 0, &r) != NULL && r == CO_OK);
    CHECK(co_od_find(&t_od, 0x1000, 1, &r) == NULL && r == CO_E_NO_SUB);
    CHECK(co_od_find(&t_od, 0x1800, 4, &r) == NULL && r == CO_E_NO_SUB);
    CHECK(co_od_find(&t_od, 0x1802, 0, &r) == NULL && r == CO_E_NO_OBJ);
    CHECK(co_od_find(&t_od, 0x0000, 0, &r) == NULL && r == CO_E_NO_OBJ);
    CHECK(co_od_find(&t_od, 0xFFFF, 0xFF, &r) == NULL && r == CO_E_NO_OBJ);
    /* Every table of the product registry is sorted: the search relies on it. */
    for (size_t i = 0; product_list[i] != NULL; i++) {
        h_boot(d, product_list[i], false);
        const co_od_t *od = d->node->cfg->od;
        /* Without segmented transfer every object must fit an expedited one. */
        for (uint16_t k = 0; k < od->count && d->node->cfg->sdo_segmented == NULL; k++) {
            CHECK(od->entries[k].size <= 4u);
        }
        for (uint16_t k = 1; k < od->count; k++) {
            uint32_t a = ((uint32_t)od->entries[k - 1].index << 8) | od->entries[k - 1].sub;
            uint32_t b = ((uint32_t)od->entries[k].index << 8) | od->entries[k].sub;
            CHECK(a < b);
        }
        /* The search against a linear scan: every sub-index of every index
         * the table has, and of the indices next to them. */
        unsigned wrong = 0;
        for (uint16_t k = 0; k < od->count; k++) {
            for (int near = -1; near <= 1; near++) {
                uint16_t index = (uint16_t)(od->entries[k].index + near);
                for (unsigned sub = 0; sub < 256u; sub++) {
                    const co_od_entry_t *want = NULL;
                    co_res_t want_r = CO_E_NO_OBJ;
                    for (uint16_t j = 0; j < od->count; j++) {
                        if (od->entries[j].index == index) {
                            want_r = want == NULL ? CO_E_NO_SUB : CO_OK;
                            if (od->entries[j].sub == sub) {
                                want = &od->entries[j];
                                want_r = CO_OK;
                            }
                        }
                    }
                    const co_od_entry_t *got = co_od_find(od, index, (uint8_t)sub, &r);
                    wrong += got != want || r != want_r;
                }
            }
        }
        CHECK_EQ(wrong, 0);
    }
}

static void test_sdo_expedited(void)
{
    boot();
    SDO(d, "40 00 10 00 00 00 00 00", "43 00 10 00 78 56 34 12");
    SDO(d, "40 01 20 00 00 00 00 00", "4B 01 20 00 FB FF 00 00"); /* -5 */
    SDO(d, "2B 01 20 00 9C FF 00 00", "60 01 20 00 00 00 00 00"); /* -100 */
    SDO(d, "2B 01 20 00 9B FF 00 00", "80 01 20 00 32 00 09 06"); /* -101 low */
    SDO(d, "2B 01 20 00 65 00 00 00", "80 01 20 00 31 00 09 06"); /* 101 high */
    SDO(d, "23 00 20 00 09 00 00 00", "80 00 20 00 32 00 09 06");
    SDO(d, "23 00 20 00 E9 03 00 00", "80 00 20 00 31 00 09 06");
    SDO(d, "23 00 20 00 E8 03 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "22 00 20 00 0A 00 00 00", "60 00 20 00 00 00 00 00"); /* size not indicated */
    CHECK_EQ(h_read(d, 0x2000, 0), 10);
    SDO(d, "2F 00 20 00 0A 00 00 00", "80 00 20 00 13 00 07 06"); /* length too low */
    SDO(d, "2B 02 10 00 00 00 00 00", "80 02 10 00 00 00 02 06");
    SDO(d, "40 00 10 05 00 00 00 00", "80 00 10 05 11 00 09 06");
    SDO(d, "A0 00 10 00 00 00 00 00", "80 00 10 00 02 00 04 05"); /* block size 0 */
    SDO(d, "C0 00 10 00 00 00 00 00", "80 00 10 00 02 00 01 06"); /* block write to ro */
    SDO(d, "C1 00 10 00 00 00 00 00", "80 00 00 00 01 00 04 05"); /* block end, none open */
    SDO(d, "E0 00 10 00 00 00 00 00", "80 00 00 00 01 00 04 05");
    SDO(d, "00 00 00 00 00 00 00 00", "80 00 00 00 01 00 04 05"); /* segment, none open */
    /* Not 8 bytes: ignored. A client abort: no answer. */
    h_drain(d);
    h_rx(d, 0x610, "40 00 10 00");
    h_rx(d, 0x610, "80 00 10 00 00 00 00 00");
    EXPECT_NONE(d);
    /* Another node's SDO is not ours. */
    h_rx(d, 0x611, "40 00 10 00 00 00 00 00");
    EXPECT_NONE(d);
}

static void test_sdo_segmented_upload(void)
{
    boot();
    const char *name = "A long device name for segmented transfer"; /* 41 bytes */
    SDO(d, "40 08 10 00 00 00 00 00", "41 08 10 00 29 00 00 00");
    char got[64] = {0};
    unsigned at = 0;
    uint8_t toggle = 0;
    for (int seg = 0; seg < 10; seg++) {
        uint8_t req[8] = {(uint8_t)(0x60u | toggle)};
        co_frame_t f = {.id = 0x610, .dlc = 8};
        memcpy(f.data, req, 8);
        h_drain(d);
        h_rx_frame(d, &f);
        const co_frame_t *r = h_next(d);
        CHECK(r != NULL);
        if (r == NULL) {
            return;
        }
        CHECK_EQ(r->data[0] & 0x10u, toggle);
        unsigned n = 7u - ((r->data[0] >> 1) & 7u);
        memcpy(&got[at], &r->data[1], n);
        at += n;
        toggle ^= 0x10u;
        if (r->data[0] & 1u) {
            break;
        }
    }
    CHECK_EQ(at, 41);
    CHECK(strcmp(got, name) == 0);
    /* Toggle error aborts with 0x05030000. */
    SDO(d, "40 08 10 00 00 00 00 00", "41 08 10 00 29 00 00 00");
    SDO(d, "60 00 00 00 00 00 00 00", "00 41 20 6C 6F 6E 67 20");
    SDO(d, "60 00 00 00 00 00 00 00", "80 08 10 00 00 00 03 05");
    /* SDO timeout: one second without the next segment request. */
    SDO(d, "40 08 10 00 00 00 00 00", "41 08 10 00 29 00 00 00");
    h_drain(d);
    h_advance(d, 999000);
    EXPECT_NONE(d);
    h_advance(d, 2000);
    EXPECT(d, 0x590, "80 08 10 00 00 00 04 05");
}

static void test_sdo_segmented_download(void)
{
    boot();
    SDO(d, "21 00 20 00 04 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "07 C8 00 00 00 00 00 00", "20 00 00 00 00 00 00 00"); /* 200, last (n=3) */
    CHECK_EQ(h_read(d, 0x2000, 0), 200);
    /* Two segments. */
    SDO(d, "21 00 20 00 04 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "0A 2C 01 00 00 00 00 00", "20 00 00 00 00 00 00 00"); /* 2 bytes, more */
    SDO(d, "1B 00 00 00 00 00 00 00", "30 00 00 00 00 00 00 00"); /* 2 bytes, last */
    CHECK_EQ(h_read(d, 0x2000, 0), 300);
    /* Indicated size above the object: length too high, at once. */
    SDO(d, "21 00 20 00 05 00 00 00", "80 00 20 00 12 00 07 06");
    SDO(d, "21 00 20 00 02 00 00 00", "80 00 20 00 13 00 07 06");
    /* Fewer bytes than the object: too low at the last segment. */
    SDO(d, "20 00 20 00 00 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "0B 01 02 00 00 00 00 00", "80 00 20 00 13 00 07 06");
    /* Toggle wrong on the first segment. */
    SDO(d, "21 00 20 00 04 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "17 C8 00 00 00 00 00 00", "80 00 20 00 00 00 03 05");
    /* Value out of range reported at the end. */
    SDO(d, "21 00 20 00 04 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "07 01 00 00 00 00 00 00", "80 00 20 00 32 00 09 06");
    /* Read-only and constant objects refuse at initiate. */
    SDO(d, "21 08 10 00 05 00 00 00", "80 08 10 00 02 00 01 06");
    SDO(d, "21 00 21 00 04 00 00 00", "80 00 21 00 02 00 01 06");
    CHECK_EQ(h_read(d, 0x2000, 0), 300);
}

static void test_sdo_block_download(void)
{
    boot();
    /* Initiate with CRC and size 4; the server offers CRC and its block size. */
    SDO(d, "C6 00 20 00 04 00 00 00", "A4 00 20 00 0A 00 00 00");
    h_drain(d);
    h_rx(d, 0x610, "81 F4 01 00 00 00 00 00"); /* seq 1, last: 500 */
    EXPECT(d, 0x590, "A2 01 0A 00 00 00 00 00");
    uint8_t v[4] = {0xF4, 0x01, 0x00, 0x00};
    uint16_t crc = co_crc16_ccitt(0, v, 4);
    char end[64];
    snprintf(end, sizeof(end), "CD %02X %02X 00 00 00 00 00", crc & 0xFF, crc >> 8); /* n = 3 */
    SDO(d, end, "A1 00 00 00 00 00 00 00");
    CHECK_EQ(h_read(d, 0x2000, 0), 500);
    /* Wrong CRC: abort 0x05040004, nothing written. */
    SDO(d, "C6 00 20 00 04 00 00 00", "A4 00 20 00 0A 00 00 00");
    h_rx(d, 0x610, "81 2C 01 00 00 00 00 00");
    SDO(d, "CD 12 34 00 00 00 00 00", "80 00 20 00 04 00 04 05");
    CHECK_EQ(h_read(d, 0x2000, 0), 500);
    /* No CRC (client without it), value out of range: the object's abort. */
    SDO(d, "C2 00 20 00 04 00 00 00", "A4 00 20 00 0A 00 00 00");
    h_rx(d, 0x610, "81 05 00 00 00 00 00 00");
    SDO(d, "CD 00 00 00 00 00 00 00", "80 00 20 00 32 00 09 06");
    /* A segment out of sequence is acknowledged with the last good one. */
    SDO(d, "C2 01 20 00 02 00 00 00", "A4 01 20 00 0A 00 00 00");
    h_drain(d);
    h_rx(d, 0x610, "82 07 00 00 00 00 00 00"); /* seq 2, last, but seq 1 was lost */
    EXPECT(d, 0x590, "A2 00 0A 00 00 00 00 00");
    h_rx(d, 0x610, "81 07 00 00 00 00 00 00");
    EXPECT(d, 0x590, "A2 01 0A 00 00 00 00 00");
    SDO(d, "D5 00 00 00 00 00 00 00", "A1 00 00 00 00 00 00 00"); /* n = 5: 2 bytes */
    CHECK_EQ(h_read(d, 0x2001, 0), 7);
}

/* A block download's abort is its last word: nothing is written and
 * nothing follows it (tools/mutate's survivors: the returns after the
 * aborts of a wrong end command, a wrong length and an overflow). */
static void test_sdo_block_download_abort_is_final(void)
{
    boot();
    CHECK_EQ(h_read(d, 0x2000, 0), 100);
    /* Size 4 announced, 2 bytes given (n = 5 of the last 7 unused). */
    SDO(d, "C2 00 20 00 04 00 00 00", "A4 00 20 00 0A 00 00 00");
    h_rx(d, 0x610, "81 F4 01 00 00 00 00 00");
    SDO(d, "D5 00 00 00 00 00 00 00", "80 00 20 00 10 00 07 06");
    EXPECT_NONE(d);
    CHECK_EQ(h_read(d, 0x2000, 0), 100);
    /* An end without its end bit: command unknown. */
    SDO(d, "C2 00 20 00 04 00 00 00", "A4 00 20 00 0A 00 00 00");
    h_rx(d, 0x610, "81 F4 01 00 00 00 00 00");
    SDO(d, "C4 00 00 00 00 00 00 00", "80 00 20 00 01 00 04 05");
    EXPECT_NONE(d);
    CHECK_EQ(h_read(d, 0x2000, 0), 100);
    /* More than the buffer: a full block of 10 segments (70 bytes) is
     * acknowledged, the next segment aborts, even as the last one. */
    SDO(d, "C0 00 20 00 00 00 00 00", "A4 00 20 00 0A 00 00 00");
    h_drain(d);
    for (unsigned k = 1; k <= 10u; k++) {
        co_frame_t f = {.id = 0x610, .dlc = 8, .data = {(uint8_t)k, 1, 2, 3, 4, 5, 6, 7}};
        h_rx_frame(d, &f);
    }
    EXPECT(d, 0x590, "A2 0A 0A 00 00 00 00 00");
    h_rx(d, 0x610, "81 01 02 03 04 05 06 07");
    EXPECT(d, 0x590, "80 00 20 00 12 00 07 06");
    EXPECT_NONE(d);
    CHECK_EQ(h_read(d, 0x2000, 0), 100);
    /* The object refuses the value (above its 1000): its abort alone. */
    SDO(d, "C2 00 20 00 04 00 00 00", "A4 00 20 00 0A 00 00 00");
    h_rx(d, 0x610, "81 D0 07 00 00 00 00 00");
    SDO(d, "CD 00 00 00 00 00 00 00", "80 00 20 00 31 00 09 06");
    EXPECT_NONE(d);
    CHECK_EQ(h_read(d, 0x2000, 0), 100);
    /* A block upload of an object that does not exist, or of a write-only
     * one: its abort alone. */
    SDO(d, "A0 99 29 00 0A 00 00 00", "80 99 29 00 00 00 02 06");
    EXPECT_NONE(d);
    SDO(d, "A0 10 10 01 0A 00 00 00", "80 10 10 01 01 00 01 06");
    EXPECT_NONE(d);
    /* The client's next block size: 127 segments at most (CiA 301). */
    for (unsigned blk = 127; blk <= 128u; blk++) {
        SDO(d, "A0 00 20 00 0A 00 00 00", "C6 00 20 00 04 00 00 00");
        h_rx(d, 0x610, "A3 00 00 00 00 00 00 00");
        const co_frame_t *seg = h_next(d);
        CHECK(seg != NULL && seg->data[0] == 0x81);
        co_frame_t ack = {.id = 0x610, .dlc = 8, .data = {0xA2, 1, (uint8_t)blk}};
        h_rx_frame(d, &ack);
        const co_frame_t *f = h_next(d);
        CHECK(f != NULL && f->data[0] == (blk == 127u ? 0xCD : 0x80));
        if (blk == 128u) {
            CHECK(f != NULL && co_get_u32(&f->data[4]) == 0x05040002u);
            EXPECT_NONE(d);
        } else {
            h_rx(d, 0x610, "A1 00 00 00 00 00 00 00");
            EXPECT_NONE(d);
        }
    }
    /* A block upload answered with another command: one abort. */
    SDO(d, "A0 00 20 00 0A 00 00 00", "C6 00 20 00 04 00 00 00");
    SDO(d, "20 00 20 00 00 00 00 00", "80 00 20 00 01 00 04 05");
    EXPECT_NONE(d);
}

static void test_sdo_block_upload(void)
{
    boot();
    const char *name = "A long device name for segmented transfer"; /* 41 bytes */
    /* Blocks of 2 segments: 41 bytes take 6 segments, three blocks. */
    SDO(d, "A4 08 10 00 02 00 00 00", "C6 08 10 00 29 00 00 00");
    char got[64] = {0};
    unsigned at = 0;
    h_drain(d);
    h_rx(d, 0x610, "A3 00 00 00 00 00 00 00");
    for (int block = 0; block < 3; block++) {
        for (int seg = 1; seg <= 2; seg++) {
            const co_frame_t *f = h_next(d);
            CHECK(f != NULL && (f->data[0] & 0x7F) == seg);
            if (f == NULL) {
                return;
            }
            memcpy(&got[at], &f->data[1], 7);
            at += 7;
            CHECK_EQ((f->data[0] & 0x80) != 0, block == 2 && seg == 2);
        }
        EXPECT_NONE(d);
        h_rx(d, 0x610, "A2 02 02 00 00 00 00 00");
    }
    const co_frame_t *f = h_next(d); /* end: n = 1 unused byte, CRC */
    CHECK(f != NULL && f->data[0] == (0xC1 | (1u << 2)));
    if (f != NULL) {
        CHECK_EQ(co_get_u16(&f->data[1]), co_crc16_ccitt(0, (const uint8_t *)name, 41));
    }
    CHECK(memcmp(got, name, 41) == 0);
    h_rx(d, 0x610, "A1 00 00 00 00 00 00 00");
    EXPECT_NONE(d);
    /* A lost segment: acknowledging 1 of 2 sends the rest again. */
    SDO(d, "A4 00 10 00 02 00 00 00", "C6 00 10 00 04 00 00 00");
    h_drain(d);
    h_rx(d, 0x610, "A3 00 00 00 00 00 00 00");
    EXPECT(d, 0x590, "81 78 56 34 12 00 00 00");
    h_rx(d, 0x610, "A2 00 02 00 00 00 00 00"); /* nothing arrived: again */
    EXPECT(d, 0x590, "81 78 56 34 12 00 00 00");
    h_rx(d, 0x610, "A2 01 02 00 00 00 00 00");
    f = h_next(d);
    CHECK(f != NULL && f->data[0] == (0xC1 | (3u << 2)));
    h_rx(d, 0x610, "A1 00 00 00 00 00 00 00");
    /* Acknowledging more than was sent: abort, invalid sequence number. */
    SDO(d, "A4 00 10 00 02 00 00 00", "C6 00 10 00 04 00 00 00");
    h_rx(d, 0x610, "A3 00 00 00 00 00 00 00");
    SDO(d, "A2 05 02 00 00 00 00 00", "80 00 10 00 03 00 04 05");
    /* Write-only object. */
    SDO(d, "A4 10 10 01 10 00 00 00", "80 10 10 01 01 00 01 06");
}

static void test_nmt(void)
{
    boot();
    h_rx(d, 0x000, "01 11"); /* another node */
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
    h_rx(d, 0x000, "01 10 00"); /* DLC 3 */
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
    h_rx(d, 0x000, "01");
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
    h_rx(d, 0x000, "55 10"); /* unknown command */
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
    h_rx(d, 0x000, "01 00"); /* broadcast */
    CHECK_EQ(d->node->nmt.state, CO_NMT_OPERATIONAL);
    h_rx(d, 0x000, "02 10");
    CHECK_EQ(d->node->nmt.state, CO_NMT_STOPPED);
}

static void test_nmt_stopped_is_silent(void)
{
    boot();
    h_rx(d, 0x000, "02 10");
    h_drain(d);
    h_rx(d, 0x610, "40 00 10 00 00 00 00 00");
    h_advance(d, 1000000);
    EXPECT_NONE(d); /* no SDO, no TPDO, no heartbeat (off) */
    h_rx(d, 0x000, "80 10");
    SDO(d, "40 00 10 00 00 00 00 00", "43 00 10 00 78 56 34 12");
}

static void test_reset_comm_keeps_application(void)
{
    boot();
    SDO(d, "2B 17 10 00 64 00 00 00", "60 17 10 00 00 00 00 00");
    SDO(d, "23 02 20 00 09 00 00 00", "60 02 20 00 00 00 00 00"); /* volatile, app area */
    SDO(d, "2B 01 20 00 03 00 00 00", "60 01 20 00 00 00 00 00"); /* PARA, app area */
    h_rx(d, 0x000, "82 10");
    EXPECT(d, 0x710, "00");
    CHECK_EQ(h_read(d, 0x1017, 0), 0); /* communication: back to stored */
    CHECK_EQ(h_read(d, 0x2002, 0), 9); /* application: untouched */
    CHECK_EQ(h_read(d, 0x2001, 0), 3);
    h_rx(d, 0x000, "81 10");
    EXPECT(d, 0x710, "00");
    CHECK_EQ(h_read(d, 0x2002, 0), 7);
    CHECK_EQ(h_read(d, 0x2001, 0), -5 & 0xFFFF);
}

/* The idle poll: between events co_node_poll only counts down to the
 * deadline the last full poll found; a frame or co_node_wake() ends that. */
static void test_idle_poll(void)
{
    boot();
    co_node_t *n = d->node;
    uint32_t t = d->now;
    CHECK_EQ(co_node_poll(n, t), CO_NEVER); /* heartbeat off, no PDO: nothing due */
    CHECK_EQ(co_node_poll(n, t + 5000000u), CO_NEVER);
    h_rx(d, 0x610, "2B 17 10 00 32 00 00 00"); /* heartbeat 50 ms: a frame wakes */
    t = d->now;
    CHECK_EQ(co_node_poll(n, t), 50000);
    CHECK_EQ(co_node_poll(n, t + 20000u), 30000);
    h_drain(d);
    CHECK_EQ(co_node_poll(n, t + 50000u), 50000); /* due: a full poll sends it */
    EXPECT(d, 0x710, "7F");
    /* A change the poll cannot see (here: the heartbeat period poked
     * directly) is ignored until something wakes the node. */
    n->hb.period_ms = 0;
    CHECK_EQ(co_node_poll(n, t + 60000u), 40000);
    co_node_wake(n);
    CHECK_EQ(co_node_poll(n, t + 60000u), CO_NEVER);
}

static void test_heartbeat_timing(void)
{
    boot();
    SDO(d, "2B 17 10 00 32 00 00 00", "60 17 10 00 00 00 00 00"); /* 50 ms */
    uint32_t t0 = d->now;
    h_drain(d);
    h_advance(d, 49999);
    EXPECT_NONE(d);
    h_advance(d, 1);
    EXPECT(d, 0x710, "7F");
    CHECK_EQ(d->now - t0, 50000);
    h_advance(d, 50000);
    EXPECT(d, 0x710, "7F");
    SDO(d, "2B 17 10 00 00 00 00 00", "60 17 10 00 00 00 00 00");
    h_advance(d, 500000);
    EXPECT_NONE(d);
}

/* A heartbeat polled late keeps its cadence: the next one is due a period
 * after the last deadline, not after the late poll (tools/mutate's
 * survivor: hb->next += period removed). The board's polls by hand. */
static void test_heartbeat_late_poll_keeps_cadence(void)
{
    boot();
    SDO(d, "2B 17 10 00 32 00 00 00", "60 17 10 00 00 00 00 00"); /* 50 ms */
    uint32_t t0 = d->now;
    h_drain(d);
    CHECK_EQ(co_node_poll(d->node, t0 + 50300u), 49700); /* 300 us late: sent */
    EXPECT(d, 0x710, "7F");
    CHECK_EQ(co_node_poll(d->node, t0 + 100100u), 49900); /* the next deadline: t0 + 100 ms */
    EXPECT(d, 0x710, "7F");
    CHECK_EQ(co_node_poll(d->node, t0 + 160000u), 40000); /* 10 ms late: still t0 + 200 ms */
    EXPECT(d, 0x710, "7F");
    CHECK_EQ(co_node_poll(d->node, t0 + 199999u), 1);
    EXPECT_NONE(d);
    /* More than a period late: one heartbeat, the next a period after it
     * (no burst to catch up). */
    CHECK_EQ(co_node_poll(d->node, t0 + 260000u), 50000);
    EXPECT(d, 0x710, "7F");
    CHECK_EQ(co_node_poll(d->node, t0 + 309999u), 1);
    EXPECT_NONE(d);
    d->now = t0 + 309999u;
}

static unsigned count_id(h_dev_t *x, uint16_t id)
{
    unsigned n = 0;
    const co_frame_t *f;
    while ((f = h_next(x)) != NULL) {
        n += f->id == id;
    }
    return n;
}

static void test_tpdo_event_and_inhibit(void)
{
    boot();
    h_rx(d, 0x000, "01 10");
    h_advance(d, 0);
    const co_frame_t *f = h_next(d);
    CHECK(f != NULL && f->id == 0x190 && f->dlc == 6); /* 4 + 2 bytes, no padding */
    if (f != NULL) {
        CHECK_EQ(f->data[4], 0xFB); /* 0x2001 = -5 */
        CHECK_EQ(f->data[5], 0xFF);
    }
    h_advance(d, 1000000 - 1);
    CHECK_EQ(count_id(d, 0x190), 9); /* 100 ms period */
    /* Event timer 10 ms with inhibit 25 ms (250 x 100 us): one per 25 ms. */
    SDO(d, "2B 00 18 03 FA 00 00 00", "60 00 18 03 00 00 00 00");
    SDO(d, "2B 00 18 05 0A 00 00 00", "60 00 18 05 00 00 00 00");
    h_drain(d);
    h_advance(d, 1000000);
    unsigned n = count_id(d, 0x190);
    CHECK(n >= 39 && n <= 41);
    /* Disabled by COB-ID bit 31: silence. */
    SDO(d, "23 00 18 01 90 01 00 80", "60 00 18 01 00 00 00 00");
    h_drain(d);
    h_advance(d, 300000);
    CHECK_EQ(count_id(d, 0x190), 0);
    /* COB-ID written as 0x180 + node-ID is stored as following the ID. */
    SDO(d, "23 00 18 01 90 01 00 00", "60 00 18 01 00 00 00 00");
    CHECK_EQ(((t_dev_t *)h_inst(d))->para.cob[0], 0x180);
    SDO(d, "23 00 18 01 85 03 00 00", "60 00 18 01 00 00 00 00");
    CHECK_EQ(h_read(d, 0x1800, 1), 0x385);
    h_drain(d);
    h_advance(d, 100000);
    CHECK(count_id(d, 0x385) >= 1);
    /* Leaving operational stops them. */
    h_rx(d, 0x000, "80 10");
    h_drain(d);
    h_advance(d, 500000);
    EXPECT_NONE(d);
}

static void test_tpdo_sync_and_bad_mapping(void)
{
    boot();
    /* TPDO2 maps a non-mappable object: it stays silent on SYNC. */
    h_rx(d, 0x000, "01 10");
    SDO(d, "2B 00 18 05 00 00 00 00", "60 00 18 05 00 00 00 00");
    SDO(d, "2F 00 18 02 02 00 00 00", "60 00 18 02 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x080, "");
    EXPECT_NONE(d);
    h_rx(d, 0x080, "");
    const co_frame_t *f = h_next(d);
    CHECK(f != NULL && f->id == 0x190);
    EXPECT_NONE(d);
    /* A SYNC with a counter byte counts; with 2+ bytes it is not a SYNC. */
    h_rx(d, 0x080, "01");
    h_rx(d, 0x080, "01 02");
    EXPECT_NONE(d);
    h_rx(d, 0x080, "");
    f = h_next(d);
    CHECK(f != NULL && f->id == 0x190);
    /* SYNC COB-ID from 0x1005, effective at once. */
    SDO(d, "23 05 10 00 81 00 00 00", "60 05 10 00 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x080, "");
    h_rx(d, 0x080, "");
    EXPECT_NONE(d);
    h_rx(d, 0x081, "");
    h_rx(d, 0x081, "");
    f = h_next(d);
    CHECK(f != NULL && f->id == 0x190);
    /* All 11 bits of it: a SYNC on 1A1h, not on its low byte's A1h. */
    SDO(d, "23 05 10 00 A1 01 00 00", "60 05 10 00 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x0A1, "");
    h_rx(d, 0x0A1, "");
    EXPECT_NONE(d);
    h_rx(d, 0x1A1, "");
    h_rx(d, 0x1A1, "");
    f = h_next(d);
    CHECK(f != NULL && f->id == 0x190);
    SDO(d, "23 05 10 00 81 00 00 00", "60 05 10 00 00 00 00 00");
    h_drain(d);
    /* Never a restricted CAN-ID (CiA 301 7.3.5): this node's SDO, NMT. */
    SDO(d, "23 05 10 00 10 06 00 00", "80 05 10 00 30 00 09 06");
    SDO(d, "23 05 10 00 00 00 00 00", "80 05 10 00 30 00 09 06");
    SDO(d, "40 05 10 00 00 00 00 00", "43 05 10 00 81 00 00 00");
}

/* co_tpdo_reconfig() of a TPDO this build has no room for (a product's
 * index past CO_TPDO_MAX): a broken contract, reported by CO_CHECK, and
 * nothing written (before the check it cleared the bytes after tpdo[]). */
static void test_tpdo_reconfig_out_of_range(void)
{
    boot();
    h_rx(d, 0x000, "01 10");
    SDO(d, "2F 00 18 02 01 00 00 00", "60 00 18 02 00 00 00 00"); /* TPDO1 at every SYNC */
    h_drain(d);
    co_node_t *n = d->nodes[0];
    static co_node_t before;
    memcpy(&before, n, sizeof(before));
    unsigned seen = h_asserts;
    h_expect_assert(2);
    co_tpdo_reconfig(n, CO_TPDO_MAX);
    co_tpdo_reconfig(n, 0xFFFFFFFFu);
    CHECK_EQ(h_asserts, seen + 2u);
    CHECK(memcmp(&before, n, sizeof(before)) == 0);
    /* TPDOs there are: no report; TPDO1 still sends at a SYNC. */
    co_tpdo_reconfig(n, 0);
    co_tpdo_reconfig(n, CO_TPDO_MAX - 1u);
    CHECK_EQ(h_asserts, seen + 2u);
    h_drain(d);
    h_rx(d, 0x080, "");
    const co_frame_t *f = h_next(d);
    CHECK(f != NULL && f->id == 0x190);
}

/* The contract's setters (co_node.h): node-ID, bit rate and automatic
 * start only from the reset hook; a TPDO's byte order, event and change
 * check, a store status and a corrupt mark only for what exists (TPDO
 * number CO_TPDO_MAX is the first that does not). Anything else: a
 * CO_CHECK report, nothing changed. */
static void test_contract_broken_changes_nothing(void)
{
    boot();
    co_node_t *n = d->nodes[0];
    static co_node_t before;
    memcpy(&before, n, sizeof(before));
    unsigned seen = h_asserts;
    h_expect_assert(9);
    co_node_set_id(n, 0x20); /* pre-operational: not in a reset */
    co_node_set_bitrate(n, 1);
    co_node_set_autostart(n, true);
    co_tpdo_set_msb_first(n, CO_TPDO_MAX, true);
    co_tpdo_event(n, CO_TPDO_MAX);
    CHECK(!co_tpdo_changed(n, CO_TPDO_MAX));
    CHECK_EQ(co_node_store_status(n, CO_CLS_VOL), CO_STORE_BLANK);
    CHECK_EQ(co_node_store_status(n, CO_CLS_COUNT), CO_STORE_BLANK);
    co_store_mark_corrupt(n, CO_CLS_COUNT);
    CHECK_EQ(h_asserts, seen + 9u);
    CHECK(memcmp(&before, n, sizeof(before)) == 0);
    CHECK_EQ(co_node_id(n), 0x10);
    CHECK_EQ(co_node_nmt_state(n), CO_NMT_PREOP);
    /* What exists: no report. */
    CHECK_EQ(co_node_store_status(n, CO_CLS_PARA), CO_STORE_BLANK); /* a fresh EEPROM */
    co_tpdo_set_msb_first(n, CO_TPDO_MAX - 1u, false);
    co_tpdo_event(n, CO_TPDO_MAX - 1u);
    (void)co_tpdo_changed(n, CO_TPDO_MAX - 1u);
    CHECK_EQ(h_asserts, seen + 9u);
}

static void test_emcy(void)
{
    boot();
    uint8_t m[5] = {1, 2, 3, 4, 5};
    h_drain(d);
    CHECK(co_emcy_send(d->node, 0x5530, 0x81, m));
    EXPECT(d, 0x90, "30 55 81 01 02 03 04 05");
    SDO(d, "23 14 10 00 90 00 00 80", "60 14 10 00 00 00 00 00");
    CHECK(!co_emcy_send(d->node, 0x5530, 0x81, m));
    EXPECT_NONE(d);
    SDO(d, "23 14 10 00 A0 00 00 00", "60 14 10 00 00 00 00 00");
    CHECK(co_emcy_send(d->node, 0x1000, 0x01, NULL));
    EXPECT(d, 0xA0, "00 10 01 00 00 00 00 00");
    h_rx(d, 0x000, "02 10");
    CHECK(!co_emcy_send(d->node, 0x1000, 0x01, NULL)); /* not in stopped */
}

static void test_tx_full_is_counted(void)
{
    boot();
    d->port.tx_full = true;
    h_rx(d, 0x610, "40 00 10 00 00 00 00 00");
    CHECK_EQ(d->node->tx_dropped, 1);
    d->port.tx_full = false;
    SDO(d, "40 00 10 00 00 00 00 00", "43 00 10 00 78 56 34 12");
}

static void test_two_nodes_one_process(void)
{
    /* Two devices: the file's own and one more (16 KB of RAM under qemu). */
    h_dev_t *a = d;
    static h_dev_t other;
    h_dev_t *b = &other;
    h_boot(a, &t_prod, false);
    h_boot(b, &dst_x730_xy30, false);
    SDO(a, "2B 17 10 00 64 00 00 00", "60 17 10 00 00 00 00 00");
    SDO(b, "2B 17 10 00 C8 00 00 00", "60 17 10 00 00 00 00 00");
    CHECK_EQ(h_read(a, 0x1017, 0), 100);
    CHECK_EQ(h_read(b, 0x1017, 0), 200);
    h_rx(a, 0x000, "01 10");
    CHECK_EQ(a->node->nmt.state, CO_NMT_OPERATIONAL);
    CHECK_EQ(b->node->nmt.state, CO_NMT_PREOP);
    SDO(a, "2B 01 20 00 05 00 00 00", "60 01 20 00 00 00 00 00");
    SDO(a, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    h_power_cycle(b);
    CHECK_EQ(h_read(b, 0x1017, 0), 0); /* b's save never happened */
    h_power_cycle(a);
    CHECK_EQ(h_read(a, 0x2001, 0), 5);
}

static void test_node_guarding(void)
{
    boot();
    h_drain(d);
    co_frame_t rtr = {.id = 0x710, .rtr = true, .dlc = 1};
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x710, "7F"); /* toggle 0 first */
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x710, "FF");
    h_rx(d, 0x000, "01 10");
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x710, "05");
    h_rx(d, 0x000, "82 10"); /* reset communication: toggle back to 0 */
    SDO(d, "2B 00 18 05 00 00 00 00", "60 00 18 05 00 00 00 00"); /* TPDO1 quiet */
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x710, "7F");
    /* Life guarding: 100 ms x 3. */
    SDO(d, "2B 0C 10 00 64 00 00 00", "60 0C 10 00 00 00 00 00");
    SDO(d, "2F 0D 10 00 03 00 00 00", "60 0D 10 00 00 00 00 00");
    h_rx(d, 0x000, "01 10");
    h_rx_frame(d, &rtr);
    h_drain(d);
    h_advance(d, 299000);
    EXPECT_NONE(d);
    h_advance(d, 2000);
    EXPECT(d, 0x90, "30 81 11 00 00 00 00 00"); /* life guard event */
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
    CHECK_EQ(h_read(d, 0x1001, 0), 0x11);
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x710, "7F");                     /* toggles on from the answer before the loss */
    EXPECT(d, 0x90, "00 00 00 00 00 00 00 00"); /* error reset */
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP); /* no way back by itself */
    /* With the heartbeat on, guard requests get no answer (CiA 301). */
    SDO(d, "2B 17 10 00 E8 03 00 00", "60 17 10 00 00 00 00 00");
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT_NONE(d);
}

static void test_emcy_table_and_history(void)
{
    boot();
    h_drain(d);
    uint8_t info[5] = {0x34, 0x12, 0, 0, 0};
    CHECK(co_emcy_error(d->node, 0x5010, CO_ER_COMM, true, info));
    EXPECT(d, 0x90, "10 50 11 34 12 00 00 00");
    CHECK(!co_emcy_error(d->node, 0x5010, CO_ER_COMM, true, NULL)); /* already active */
    EXPECT_NONE(d);
    CHECK(co_emcy_error(d->node, 0x3100, CO_ER_VOLTAGE, true, NULL));
    EXPECT(d, 0x90, "00 31 15 00 00 00 00 00");
    CHECK_EQ(h_read(d, 0x1001, 0), 0x15);
    CHECK(co_emcy_error(d->node, 0x5010, 0, false, NULL));
    EXPECT_NONE(d); /* 0x3100 still active */
    CHECK_EQ(h_read(d, 0x1001, 0), 0x05);
    CHECK(co_emcy_error(d->node, 0x3100, 0, false, NULL));
    EXPECT(d, 0x90, "00 00 00 00 00 00 00 00");
    CHECK_EQ(h_read(d, 0x1001, 0), 0);
    /* History: newest first; code in the low word, info in the high word. */
    SDO(d, "40 03 10 00 00 00 00 00", "4F 03 10 00 02 00 00 00");
    SDO(d, "40 03 10 01 00 00 00 00", "43 03 10 01 00 31 00 00");
    SDO(d, "40 03 10 02 00 00 00 00", "43 03 10 02 10 50 34 12");
    SDO(d, "2F 03 10 00 01 00 00 00", "80 03 10 00 30 00 09 06");
    SDO(d, "2F 03 10 00 00 00 00 00", "60 03 10 00 00 00 00 00");
    SDO(d, "40 03 10 01 00 00 00 00", "80 03 10 01 24 00 00 08"); /* empty */
    /* EMCY COB-ID: the CAN-ID changes only while disabled. */
    SDO(d, "23 14 10 00 A0 00 00 00", "80 14 10 00 30 00 09 06");
    SDO(d, "23 14 10 00 90 00 00 80", "60 14 10 00 00 00 00 00"); /* disable */
    SDO(d, "23 14 10 00 A0 00 00 80", "60 14 10 00 00 00 00 00"); /* new ID, still off */
    SDO(d, "23 14 10 00 A0 00 00 00", "60 14 10 00 00 00 00 00"); /* enable */
    SDO(d, "23 14 10 00 B0 00 00 00", "80 14 10 00 30 00 09 06"); /* valid: no change */
    SDO(d, "23 14 10 00 A0 01 00 00", "80 14 10 00 30 00 09 06"); /* 1A0h: all 11 bits count */
    SDO(d, "23 14 10 00 A0 01 00 80", "60 14 10 00 00 00 00 00"); /* to 1A0h, disabled */
    SDO(d, "23 14 10 00 A0 01 00 00", "60 14 10 00 00 00 00 00");
    SDO(d, "23 14 10 00 A0 01 00 00", "60 14 10 00 00 00 00 00"); /* valid, the same ID */
    SDO(d, "23 14 10 00 A0 00 00 80", "60 14 10 00 00 00 00 00");
    SDO(d, "23 14 10 00 A0 00 00 00", "60 14 10 00 00 00 00 00");
    CHECK(co_emcy_send(d->node, 0x1234, 0, NULL));
    EXPECT(d, 0xA0, "34 12 00 00 00 00 00 00");
}

/* The error table cleared out of order, and the history kept within its
 * CO_EMCY_HIST_MAX entries however many errors come (tools/mutate's
 * survivors: find() answering index 0, the history's bounds). */
static void test_emcy_clear_order_and_history_bound(void)
{
    boot();
    h_drain(d);
    CHECK(co_emcy_error(d->node, 0x4210, CO_ER_TEMPERATURE, true, NULL));
    CHECK(co_emcy_error(d->node, 0x2310, CO_ER_CURRENT, true, NULL));
    h_drain(d);
    CHECK(!co_emcy_error(d->node, 0x2310, CO_ER_CURRENT, true, NULL)); /* active already */
    CHECK(!co_emcy_error(d->node, 0x6000, 0, false, NULL)); /* never active: nothing to clear */
    /* The second entry cleared first: the first one's bit stays. */
    CHECK(co_emcy_error(d->node, 0x2310, 0, false, NULL));
    CHECK(co_emcy_active(d->node, 0x4210));
    CHECK(!co_emcy_active(d->node, 0x2310));
    CHECK_EQ(h_read(d, 0x1001, 0), CO_ER_GENERIC | CO_ER_TEMPERATURE);
    EXPECT_NONE(d);
    CHECK(co_emcy_error(d->node, 0x4210, 0, false, NULL));
    EXPECT(d, 0x90, "00 00 00 00 00 00 00 00");

    /* More errors than the history holds: the newest CO_EMCY_HIST_MAX,
     * newest first, and nothing written past the history (the guarding
     * state behind it in the node stays as it was). */
    SDO(d, "2F 03 10 00 00 00 00 00", "60 03 10 00 00 00 00 00");
    co_guard_t guard = d->node->guard;
    unsigned n = CO_EMCY_HIST_MAX + 3u;
    for (unsigned i = 0; i < n; i++) {
        CHECK(co_emcy_send(d->node, (uint16_t)(0x1000u + i), 0, NULL));
    }
    h_drain(d);
    CHECK_EQ(d->node->emcy.nhist, CO_EMCY_HIST_MAX);
    for (unsigned k = 0; k < CO_EMCY_HIST_MAX; k++) {
        CHECK_EQ(d->node->emcy.hist[k], 0x1000u + n - 1u - k);
    }
    CHECK(memcmp(&guard, &d->node->guard, sizeof(guard)) == 0);
    CHECK_EQ(h_read(d, 0x1003, 0), 2); /* as deep as the dictionary */
    CHECK_EQ(h_read(d, 0x1003, 2), 0x1000u + n - 2u);
}

/* The EMCY COB-ID's CAN-ID may not change while valid, odd CAN-IDs too
 * (only bit 31 says valid). */
static void test_emcy_cobid_odd_id(void)
{
    boot();
    SDO(d, "23 14 10 00 91 00 00 00", "80 14 10 00 30 00 09 06"); /* valid: no change */
    SDO(d, "23 14 10 00 91 00 00 80", "60 14 10 00 00 00 00 00");
    SDO(d, "23 14 10 00 91 00 00 00", "60 14 10 00 00 00 00 00"); /* 0x91, valid */
    SDO(d, "23 14 10 00 A1 00 00 00", "80 14 10 00 30 00 09 06"); /* odd to odd: refused */
    SDO(d, "23 14 10 00 A0 00 00 00", "80 14 10 00 30 00 09 06"); /* odd to even: refused */
    CHECK_EQ(h_read(d, 0x1014, 0), 0x91);
}

/* The TPDO loops (start, SYNC, RTR, poll) stay within the TPDO
 * table: the active EMCY errors, kept right behind it in the node, are
 * intact through every NMT change (tools/mutate's survivors: the loops
 * running to n <= CO_TPDO_MAX). */
static void codes_intact(void)
{
    CHECK(co_emcy_active(d->node, 0x2222));
    CHECK(co_emcy_active(d->node, 0x3333));
    CHECK(co_emcy_active(d->node, 0x5555));
    CHECK_EQ(d->node->emcy.nactive, 3);
    CHECK_EQ(co_emcy_register(d->node), CO_ER_GENERIC | CO_ER_CURRENT | CO_ER_TEMPERATURE);
}

static void test_tpdo_loops_stay_in_the_table(void)
{
    boot();
    CHECK(co_emcy_error(d->node, 0x2222, CO_ER_CURRENT, true, NULL));
    CHECK(co_emcy_error(d->node, 0x3333, CO_ER_TEMPERATURE, true, NULL));
    CHECK(co_emcy_error(d->node, 0x5555, 0, true, NULL));
    h_drain(d);
    codes_intact();
    for (unsigned k = 0; k < 2u; k++) {
        h_rx(d, 0x000, "01 10"); /* start */
        h_advance(d, 5000);
        h_rx(d, 0x080, ""); /* SYNC */
        co_frame_t rtr = {.id = 0x190, .rtr = true, .dlc = 0};
        h_rx_frame(d, &rtr);
        h_advance(d, 5000);
        codes_intact();
        h_rx(d, 0x000, "02 10"); /* stop */
        codes_intact();
        h_rx(d, 0x000, "80 10"); /* pre-operational */
        h_advance(d, 5000);
        codes_intact();
        h_drain(d);
    }
}

/* Two event-driven TPDOs: each keeps its own timer through start, stop
 * and start again (tools/mutate's survivors: a TPDO loop handling the
 * first TPDO only). */
static void test_tpdo_two_event_timers(void)
{
    boot();
    SDO(d, "23 01 18 01 90 02 00 80", "60 01 18 01 00 00 00 00"); /* off to remap */
    SDO(d, "2F 01 1A 00 00 00 00 00", "60 01 1A 00 00 00 00 00");
    SDO(d, "23 01 1A 01 10 00 01 20", "60 01 1A 01 00 00 00 00"); /* 0x2001, 16 bits */
    SDO(d, "2F 01 1A 00 01 00 00 00", "60 01 1A 00 00 00 00 00");
    SDO(d, "23 01 18 01 90 02 00 00", "60 01 18 01 00 00 00 00");
    SDO(d, "2F 01 18 02 FE 00 00 00", "60 01 18 02 00 00 00 00"); /* event-driven */
    SDO(d, "2B 01 18 05 1E 00 00 00", "60 01 18 05 00 00 00 00"); /* 30 ms */
    for (unsigned k = 0; k < 2u; k++) {
        h_drain(d);
        h_rx(d, 0x000, "01 10");
        h_advance(d, 299999);
        uint32_t n190 = 0, n290 = 0;
        const co_frame_t *f;
        while ((f = h_next(d)) != NULL) {
            n190 += f->id == 0x190;
            n290 += f->id == 0x290;
        }
        CHECK_EQ(n190, 3);  /* at the start, 100 and 200 ms */
        CHECK_EQ(n290, 10); /* at the start and every 30 ms */
        co_frame_t rtr = {.id = 0x290, .rtr = true, .dlc = 2};
        h_rx_frame(d, &rtr); /* the second TPDO answers its RTR */
        f = h_next(d);
        CHECK(f != NULL && f->id == 0x290 && !f->rtr && f->dlc == 2);
        h_rx(d, 0x000, "02 10"); /* stop */
        h_advance(d, 100000);
        h_drain(d);
    }
}

/* The event timer polled late keeps its cadence: the next send a period
 * after the last deadline, not after the late poll; more than a period
 * late, one send and the next a period after it (tools/mutate's
 * survivors: the deadline from the poll's time). */
static void test_tpdo_event_timer_cadence(void)
{
    boot();
    h_drain(d);
    uint32_t t0 = d->now;
    h_rx(d, 0x000, "01 10"); /* TPDO1: event timer 100 ms, sent at the start */
    CHECK_EQ(count_id(d, 0x190), 1);
    co_node_poll(d->node, t0 + 100300u);
    CHECK_EQ(count_id(d, 0x190), 1);
    co_node_poll(d->node, t0 + 200100u);
    CHECK_EQ(count_id(d, 0x190), 1); /* due at t0 + 200 ms, not 200.3 */
    co_node_poll(d->node, t0 + 299999u);
    CHECK_EQ(count_id(d, 0x190), 0);
    co_node_poll(d->node, t0 + 450000u); /* 150 ms late */
    CHECK_EQ(count_id(d, 0x190), 1);
    co_node_poll(d->node, t0 + 549999u);
    CHECK_EQ(count_id(d, 0x190), 0);
    co_node_poll(d->node, t0 + 550000u);
    CHECK_EQ(count_id(d, 0x190), 1);
    d->now = t0 + 550000u;
}

static void test_tpdo_rtr_and_types(void)
{
    boot();
    h_rx(d, 0x000, "01 10");
    SDO(d, "2B 00 18 05 00 00 00 00", "60 00 18 05 00 00 00 00");
    co_frame_t rtr = {.id = 0x190, .rtr = true, .dlc = 6};
    h_drain(d);
    h_rx_frame(d, &rtr); /* type 254: an RTR is an extra trigger */
    const co_frame_t *f = h_next(d);
    CHECK(f != NULL && f->id == 0x190 && !f->rtr && f->dlc == 6);
    /* 253: only on request. */
    SDO(d, "2F 00 18 02 FD 00 00 00", "60 00 18 02 00 00 00 00");
    h_rx(d, 0x080, "");
    co_tpdo_event(d->node, 0);
    h_advance(d, 10000);
    EXPECT_NONE(d);
    h_rx_frame(d, &rtr);
    f = h_next(d);
    CHECK(f != NULL && f->id == 0x190);
    /* 252: sampled at SYNC, sent on request with the sampled data. */
    SDO(d, "2F 00 18 02 FC 00 00 00", "60 00 18 02 00 00 00 00");
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT_NONE(d); /* nothing sampled yet */
    h_rx(d, 0x080, "");
    uint32_t sampled = ((t_dev_t *)h_inst(d))->vol.counter;
    h_advance(d, 50000); /* the counter moves on */
    EXPECT_NONE(d);
    h_rx_frame(d, &rtr);
    f = h_next(d);
    CHECK(f != NULL && co_get_u32(f->data) == sampled);
    /* 0: at a SYNC, only if the data changed. */
    SDO(d, "2F 00 18 02 00 00 00 00", "60 00 18 02 00 00 00 00");
    SDO(d, "2F 00 18 02 F1 00 00 00", "80 00 18 02 30 00 09 06"); /* reserved: 241..251 */
    SDO(d, "2F 00 18 02 FB 00 00 00", "80 00 18 02 30 00 09 06");
    SDO(d, "2F 00 18 02 F0 00 00 00", "60 00 18 02 00 00 00 00"); /* every 240th SYNC */
    SDO(d, "2F 00 18 02 00 00 00 00", "60 00 18 02 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x080, "");
    CHECK(h_next(d) != NULL);
    h_rx(d, 0x080, "");
    EXPECT_NONE(d); /* no sample in between: same data */
    h_advance(d, 5000);
    h_rx(d, 0x080, "");
    CHECK(h_next(d) != NULL);
    /* RTR not allowed (bit 30), and not outside operational. */
    SDO(d, "2F 00 18 02 FD 00 00 00", "60 00 18 02 00 00 00 00");
    SDO(d, "23 00 18 01 90 01 00 40", "60 00 18 01 00 00 00 00");
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT_NONE(d);
    SDO(d, "23 00 18 01 90 01 00 00", "60 00 18 01 00 00 00 00");
    h_rx(d, 0x000, "80 10");
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT_NONE(d);
}

static void test_tpdo_events_and_inhibit(void)
{
    boot();
    SDO(d, "2B 00 18 05 00 00 00 00", "60 00 18 05 00 00 00 00"); /* no timer */
    SDO(d, "2B 00 18 03 E8 03 00 00", "60 00 18 03 00 00 00 00"); /* 100 ms */
    h_rx(d, 0x000, "01 10");
    h_drain(d);
    h_advance(d, 500000);
    EXPECT_NONE(d); /* no event, no timer: silence */
    co_tpdo_event(d->node, 0);
    h_advance(d, 1);
    CHECK(h_next(d) != NULL);
    uint32_t t0 = d->now;
    co_tpdo_event(d->node, 0); /* inside the inhibit time: deferred, not lost */
    co_tpdo_event(d->node, 0);
    h_advance(d, 99000);
    EXPECT_NONE(d);
    h_advance(d, 2000);
    CHECK(h_next(d) != NULL);
    EXPECT_NONE(d); /* the two events went out as one */
    CHECK(d->now - t0 >= 100000);
    unsigned seen = h_asserts;
    h_expect_assert(1);
    co_tpdo_event(d->node, 5); /* no such TPDO: ignored (a broken contract, CO_CHECK) */
    CHECK_EQ(h_asserts, seen + 1u);
}

/*
 * Regression (found by tests/fuzz/fuzz_node.c): the end of the inhibit time
 * is a time stamp compared wrap-around; after more than 2^31 us (35.8 min)
 * without a send it read as still ahead, and the next event was held back
 * for up to 35.8 minutes (an event-driven PDO of a sensor at rest).
 */
static void test_tpdo_event_after_a_long_quiet_spell(void)
{
    boot();
    SDO(d, "2B 00 18 05 00 00 00 00", "60 00 18 05 00 00 00 00"); /* no timer */
    SDO(d, "2B 00 18 03 E8 03 00 00", "60 00 18 03 00 00 00 00"); /* 100 ms */
    h_rx(d, 0x000, "01 10");
    h_drain(d);
    co_tpdo_event(d->node, 0);
    h_advance(d, 1);
    const co_frame_t *f = h_next(d);
    CHECK(f != NULL && f->id == 0x190);
    /* 40 minutes without an event. The board's samples change nothing
     * that matters here, so the clock jumps (as an MCU's does asleep). */
    d->now += 40u * 60u * 1000000u;
    d->next_sample = d->now + CO_FILTER_PERIOD_US;
    h_advance(d, 10000);
    EXPECT_NONE(d);
    co_tpdo_event(d->node, 0);
    h_advance(d, 1);
    f = h_next(d);
    CHECK(f != NULL && f->id == 0x190); /* at once: the inhibit time ended long ago */
    /* And the inhibit time works as before right after it. */
    co_tpdo_event(d->node, 0);
    h_advance(d, 99000);
    EXPECT_NONE(d);
    h_advance(d, 2000);
    f = h_next(d);
    CHECK(f != NULL && f->id == 0x190);
}

static void test_tpdo_cobid_and_mapping_rules(void)
{
    boot();
    /* TPDO2 (0x1801): strict COB-ID; mapping 0x1A01 writable. */
    SDO(d, "23 01 18 01 85 02 00 00", "80 01 18 01 30 00 09 06"); /* valid: no change */
    SDO(d, "23 01 18 01 90 02 00 80", "60 01 18 01 00 00 00 00"); /* invalidate */
    SDO(d, "23 01 18 01 85 05 00 00", "80 01 18 01 30 00 09 06"); /* valid in the SDO range */
    SDO(d, "23 01 18 01 00 00 00 80", "60 01 18 01 00 00 00 00"); /* invalid: any CAN-ID */
    SDO(d, "23 01 18 01 00 00 00 A0", "80 01 18 01 30 00 09 06"); /* bit 29 */
    SDO(d, "2F 01 1A 00 01 00 00 00", "80 01 1A 00 41 00 04 06"); /* sub 0 = 1 with bad entry */
    SDO(d, "23 01 1A 01 20 00 00 21", "80 01 1A 01 00 00 01 06"); /* sub 0 != 0 */
    SDO(d, "2F 01 1A 00 00 00 00 00", "60 01 1A 00 00 00 00 00");
    SDO(d, "23 01 1A 01 20 00 00 20", "80 01 1A 01 41 00 04 06"); /* 0x2000 not mappable */
    SDO(d, "23 01 1A 01 20 00 05 21", "80 01 1A 01 00 00 02 06"); /* no 0x2105 */
    SDO(d, "23 01 1A 01 28 00 00 21", "80 01 1A 01 41 00 04 06"); /* 40 bits of a U32 */
    SDO(d, "23 01 1A 01 21 00 00 21", "80 01 1A 01 41 00 04 06"); /* 33 bits: no whole bytes */
    SDO(d, "23 01 1A 01 00 00 00 21", "80 01 1A 01 41 00 04 06"); /* 0 bits */
    SDO(d, "23 01 1A 01 11 00 01 20", "80 01 1A 01 41 00 04 06"); /* 17 bits of an I16 */
    SDO(d, "23 01 1A 01 20 00 00 21", "60 01 1A 01 00 00 00 00");
    SDO(d, "23 01 1A 02 20 00 00 21", "60 01 1A 02 00 00 00 00");
    SDO(d, "2F 01 1A 00 02 00 00 00", "60 01 1A 00 00 00 00 00"); /* 64 bits: ok */
    SDO(d, "2F 01 1A 00 03 00 00 00", "80 01 1A 00 00 00 02 06"); /* no sub 3: no object */
    SDO(d, "2F 01 1A 00 41 00 00 00", "80 01 1A 00 31 00 09 06"); /* beyond 64 */
    SDO(d, "2F 01 1A 00 40 00 00 00", "80 01 1A 00 00 00 02 06"); /* 64: no sub 3 */
    SDO(d, "2F 01 1A 00 00 00 00 00", "60 01 1A 00 00 00 00 00");
    SDO(d, "23 01 1A 02 10 00 01 20", "60 01 1A 02 00 00 00 00"); /* 0x2001, 16 bits */
    SDO(d, "2F 01 1A 00 02 00 00 00", "60 01 1A 00 00 00 00 00");
    SDO(d, "23 01 18 01 90 02 00 00", "60 01 18 01 00 00 00 00"); /* valid again */
    SDO(d, "2F 01 1A 00 01 00 00 00", "80 01 1A 00 00 00 01 06"); /* valid: no mapping change */
    h_rx(d, 0x000, "01 10");
    SDO(d, "2B 00 18 05 00 00 00 00", "60 00 18 05 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x080, ""); /* TPDO2 type 1 */
    const co_frame_t *f = h_next(d);
    CHECK(f != NULL && f->id == 0x290 && f->dlc == 6);
    if (f != NULL) {
        CHECK_EQ(f->data[4], 0xFB); /* 0x2001 = -5 after the counter */
    }
    /* 241..251 are reserved values of the transmission type only. */
    SDO(d, "2B 00 18 03 F5 00 00 00", "60 00 18 03 00 00 00 00"); /* inhibit 245 x 100 us */
    SDO(d, "23 00 18 01 F5 00 00 00", "60 00 18 01 00 00 00 00"); /* CAN-ID 0x0F5 */
    SDO(d, "40 00 18 01 00 00 00 00", "43 00 18 01 F5 00 00 00");
    SDO(d, "40 00 18 03 00 00 00 00", "4B 00 18 03 F5 00 00 00");
}

/* The next sent frame has this CAN-ID (its data vary with the clock). */
#define NEXT_IS(id_)                                                                               \
    do {                                                                                           \
        const co_frame_t *f_ = h_next(d);                                                          \
        CHECK(f_ != NULL && f_->id == (id_));                                                      \
    } while (0)

/* Let time pass without sensor samples (long spans: hours of virtual time
 * in a few polls). The node is polled when it asks to be. */
static void run_for(uint64_t us)
{
    while (us > 0u) {
        uint32_t delay = co_node_poll(d->node, d->now);
        uint64_t step = delay == 0u ? 1u : delay;
        step = step < us ? step : us;
        step = step < 0x40000000u ? step : 0x40000000u;
        d->now += (uint32_t)step;
        us -= step;
    }
    co_node_poll(d->node, d->now);
}

/* Life time = guard time x life time factor, exactly, for every accepted
 * pair: up to 65535 ms x 255 = 4.6 h, past the 2^31 us of a wrap-safe
 * deadline and the 2^32 us of the clock itself. */
static void check_life_time(uint16_t guard_ms, uint8_t factor)
{
    boot();
    char req[64];
    snprintf(req, sizeof(req), "2B 0C 10 00 %02X %02X 00 00", guard_ms & 0xFFu, guard_ms >> 8);
    SDO(d, req, "60 0C 10 00 00 00 00 00");
    snprintf(req, sizeof(req), "2F 0D 10 00 %02X 00 00 00", factor);
    SDO(d, req, "60 0D 10 00 00 00 00 00");
    SDO(d, "2B 00 18 05 00 00 00 00", "60 00 18 05 00 00 00 00"); /* TPDO1 quiet */
    h_rx(d, 0x000, "01 10");
    co_frame_t rtr = {.id = 0x710, .rtr = true, .dlc = 1};
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x710, "05"); /* toggle 0 first */
    h_drain(d);
    uint64_t life_us = (uint64_t)guard_ms * factor * 1000u;
    run_for(life_us - 1u);
    EXPECT_NONE(d);
    CHECK_EQ(d->node->nmt.state, CO_NMT_OPERATIONAL);
    run_for(1);
    EXPECT(d, 0x90, "30 81 11 00 00 00 00 00"); /* life guard event, on time */
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
}

/*
 * Regression (found by tests/fuzz/fuzz_node.c): a guard request answered
 * while the life time was 0 was kept, and the life time counted from it
 * once guard time and life factor were set; set more than 2^31 us after
 * the request, its stale time stamp read as ahead, and the event came 32
 * minutes later out of nothing. The same after the heartbeat was switched
 * off again. Life guarding now starts with the first request answered while
 * it is on (a life time, no heartbeat).
 */
static void test_life_guarding_waits_for_a_request(void)
{
    boot();
    SDO(d, "2B 00 18 05 00 00 00 00", "60 00 18 05 00 00 00 00"); /* TPDO1 quiet */
    co_frame_t rtr = {.id = 0x710, .rtr = true, .dlc = 1};
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x710, "7F"); /* node guarding answers without a life time */
    run_for(40u * 60u * 1000000ull);
    SDO(d, "2B 0C 10 00 E8 03 00 00", "60 0C 10 00 00 00 00 00"); /* 1 s */
    SDO(d, "2F 0D 10 00 05 00 00 00", "60 0D 10 00 00 00 00 00"); /* x 5 */
    h_drain(d);
    run_for(2u * 3600u * 1000000ull); /* no request since: no event */
    EXPECT_NONE(d);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x710, "FF");
    run_for(4999999);
    EXPECT_NONE(d);
    run_for(1);
    EXPECT(d, 0x90, "30 81 11 00 00 00 00 00");
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x710, "7F");
    EXPECT(d, 0x90, "00 00 00 00 00 00 00 00"); /* error reset */
    /* The heartbeat on for 40 minutes (one a minute), then off: no event
     * until a request. */
    SDO(d, "2B 17 10 00 60 EA 00 00", "60 17 10 00 00 00 00 00");
    run_for(40u * 60u * 1000000ull);
    SDO(d, "2B 17 10 00 00 00 00 00", "60 17 10 00 00 00 00 00");
    h_drain(d);
    run_for(2u * 3600u * 1000000ull);
    EXPECT_NONE(d);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x710, "FF");
    run_for(5000000);
    EXPECT(d, 0x90, "30 81 11 00 00 00 00 00");
}

static void test_life_guarding_long_times(void)
{
    check_life_time(100, 3);     /* 300 ms */
    check_life_time(8422, 255);  /* 2 147 610 ms: just past 2^31 us */
    check_life_time(16844, 255); /* past 2^32 us: the clock wraps once */
    check_life_time(65535, 255); /* the largest: 4.6 h */
    /* A guard request before the life time is over starts it again. */
    check_life_time(10000, 255);
    co_frame_t rtr = {.id = 0x710, .rtr = true, .dlc = 1};
    h_rx_frame(d, &rtr);
    h_drain(d);
    run_for(2000000000ull);
    h_rx_frame(d, &rtr);
    h_drain(d);
    run_for(2549999999ull);
    EXPECT_NONE(d);
    run_for(1);
    EXPECT(d, 0x90, "30 81 11 00 00 00 00 00");
}

/* The other "period x unit" computations at their largest: 65535 ms event
 * timer and heartbeat, 65535 x 100 us inhibit time. */
static void test_largest_periods(void)
{
    boot();
    SDO(d, "2B 00 18 05 FF FF 00 00", "60 00 18 05 00 00 00 00");
    SDO(d, "2B 00 18 03 FF FF 00 00", "60 00 18 03 00 00 00 00");
    SDO(d, "2B 17 10 00 FF FF 00 00", "60 17 10 00 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x000, "01 10");
    NEXT_IS(0x190); /* the first event PDO at once */
    run_for(65535000u - 1u);
    EXPECT_NONE(d);
    run_for(1);
    EXPECT(d, 0x710, "05");
    NEXT_IS(0x190);
    /* An event inside the inhibit time waits for its end: 6.5535 s. */
    co_tpdo_event(d->node, 0);
    run_for(6553500u - 1u);
    EXPECT_NONE(d);
    run_for(1);
    NEXT_IS(0x190);
}

/* SYNC COB-ID (CiA 301 7.5.2.5): bit 30 "generate" is refused (no product
 * produces SYNC), bit 29 too (11-bit only); bit 31 means nothing to a
 * consumer and is kept. */
static void test_sync_cobid_bits(void)
{
    boot();
    SDO(d, "23 05 10 00 80 00 00 40", "80 05 10 00 30 00 09 06");
    SDO(d, "23 05 10 00 80 00 00 20", "80 05 10 00 30 00 09 06");
    SDO(d, "23 05 10 00 80 00 00 C0", "80 05 10 00 30 00 09 06");
    SDO(d, "40 05 10 00 00 00 00 00", "43 05 10 00 80 00 00 00");
    SDO(d, "23 05 10 00 81 00 00 80", "60 05 10 00 00 00 00 00");
    SDO(d, "40 05 10 00 00 00 00 00", "43 05 10 00 81 00 00 80");
    SDO(d, "2F 00 18 02 01 00 00 00", "60 00 18 02 00 00 00 00"); /* TPDO1 on every SYNC */
    h_rx(d, 0x000, "01 10");
    h_drain(d);
    h_rx(d, 0x081, "");
    NEXT_IS(0x190);
}

/* EMCY COB-ID (CiA 301 7.5.2.21): never a restricted CAN-ID while valid,
 * and a written value reads back and acts as written, the base 0x80 too. */
static void test_emcy_cobid_restricted_and_as_written(void)
{
    boot();
    static const char *const restricted[] = {"64 07", "01 06", "00 00", "7F 00", "01 01",
                                             "80 01", "E0 06", "FF 05", "81 05", "FF 07"};
    for (size_t i = 0; i < sizeof(restricted) / sizeof(restricted[0]); i++) {
        char req[64];
        snprintf(req, sizeof(req), "23 14 10 00 %s 00 80", restricted[i]);
        SDO(d, req, "60 14 10 00 00 00 00 00"); /* invalid: any CAN-ID may be named */
        snprintf(req, sizeof(req), "23 14 10 00 %s 00 00", restricted[i]);
        SDO(d, req, "80 14 10 00 30 00 09 06");
    }
    SDO(d, "23 14 10 00 80 00 00 80", "60 14 10 00 00 00 00 00");
    SDO(d, "23 14 10 00 80 00 00 00", "60 14 10 00 00 00 00 00"); /* 0x080 exactly */
    SDO(d, "40 14 10 00 00 00 00 00", "43 14 10 00 80 00 00 00");
    h_drain(d);
    CHECK(co_emcy_error(d->node, 0x5010, CO_ER_COMM, true, NULL));
    EXPECT(d, 0x080, "10 50 11 00 00 00 00 00");
    /* Kept as written across a save and a power cycle. */
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    h_power_cycle(d);
    EXPECT(d, 0x710, "00");
    SDO(d, "40 14 10 00 00 00 00 00", "43 14 10 00 80 00 00 00");
    /* "0x80 + node-ID" follows the node-ID again. */
    SDO(d, "23 14 10 00 80 00 00 80", "60 14 10 00 00 00 00 00");
    SDO(d, "23 14 10 00 90 00 00 00", "60 14 10 00 00 00 00 00");
    SDO(d, "40 14 10 00 00 00 00 00", "43 14 10 00 90 00 00 00");
    CHECK_EQ(((t_dev_t *)h_inst(d))->para.emcy_cob, 0x80); /* the base, stored */
    /* The same rule for a TPDO's default COB-ID base (0x280 for TPDO2). */
    SDO(d, "23 01 18 01 90 02 00 80", "60 01 18 01 00 00 00 00");
    SDO(d, "23 01 18 01 80 02 00 00", "60 01 18 01 00 00 00 00");
    SDO(d, "40 01 18 01 00 00 00 00", "43 01 18 01 80 02 00 00");
}

/*
 * A node with only what CiA 301 requires and node guarding instead of a
 * heartbeat: no 0x1005 (SYNC on its default CAN-ID 0x080), no 0x1017 (no
 * heartbeat: guard requests are answered), TPDO1 with its COB-ID only
 * (transmission type 254, no inhibit time, no event timer: sent on each
 * application event), TPDO2 with a transmission type of 1 mapping two
 * sub-indices of a record.
 */
typedef struct b_vol {
    uint32_t counter;
    uint8_t type3;    /* 0x1802 sub 2 */
    uint8_t count3;   /* 0x1A02 sub 0 */
    uint32_t map3[3]; /* 0x1A02 sub 1..3 */
    uint32_t w[2];    /* 0x2300, 0x2301 */
} b_vol_t;

typedef struct b_dev {
    co_node_t node;
    b_vol_t vol;
} b_dev_t;

/* clang-format off */
static const co_od_entry_t b_entries[] = {
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_CONST, .def = 0},
    {.index = 0x1001, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, CO_EXT(.read = co_emcy_read_register)},
    {.index = 0x100C, .sub = 0, CO_TYPE_U16, .attr = CO_A_R | CO_A_CONST, .def = 0},
    {.index = 0x100D, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_CONST, .def = 0},
    {.index = 0x1800, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_CONST, .def = 1},
    {.index = 0x1800, .sub = 1, CO_TYPE_U32, .attr = CO_A_R | CO_A_NODEID, .def = 0x180},
    {.index = 0x1801, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_CONST, .def = 2},
    {.index = 0x1801, .sub = 1, CO_TYPE_U32, .attr = CO_A_R | CO_A_NODEID, .def = 0x280},
    {.index = 0x1801, .sub = 2, CO_TYPE_U8, .attr = CO_A_R, .def = 1},
    {.index = 0x1A00, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 1},
    {.index = 0x1A00, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, .def = 0x21000020u},
    {.index = 0x1A01, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 2},
    {.index = 0x1A01, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, .def = 0x22000108u},
    {.index = 0x1A01, .sub = 2, CO_TYPE_U32, .attr = CO_A_R, .def = 0x22000210u},
    {.index = 0x2100, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_PDO, CO_AT(CO_CLS_VOL, b_vol_t, counter)},
    {.index = 0x2200, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_CONST, .def = 2},
    {.index = 0x2200, .sub = 1, CO_TYPE_U8, .attr = CO_A_R | CO_A_PDO, .def = 0x11},
    {.index = 0x2200, .sub = 2, CO_TYPE_U16, .attr = CO_A_R | CO_A_PDO, .def = 0x2233},
};
/* clang-format on */

static const co_od_t b_od = {.entries = b_entries,
                             .count = sizeof(b_entries) / sizeof(b_entries[0])};

static uint32_t quiet_poll(co_node_t *node, uint32_t now)
{
    (void)node;
    (void)now;
    return CO_NEVER;
}

/* A service that only polls (no receive, no reset), as a product's own may. */
static const co_service_t quiet_service = {.poll = quiet_poll};

static const co_service_t *const b_services[] = {&co_guard_service, &quiet_service, NULL};

static const co_node_cfg_t b_cfg = {
    .od = &b_od,
    .services = b_services,
    .ram_size = {0, sizeof(b_vol_t), 0, 0},
    .default_node_id = 0x20,
};

/* The small test nodes below: their configuration is the product's. */
static void b_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    b_dev_t *b = mem;
    memset(b, 0, sizeof(*b));
    void *const ram[CO_CLS_COUNT] = {NULL, &b->vol, NULL, NULL};
    co_node_init(&b->node, p->cfg, ports[0], b, ram, 0);
    nodes[0] = &b->node;
}

static void b_sample(void *mem, const int32_t v[], uint32_t fault)
{
    (void)v;
    (void)fault;
    ((b_dev_t *)mem)->vol.counter++;
}

static const product_t b_prod = {.id = "bare",
                                 .inputs = {{NULL, NULL, 0, 0}},
                                 .nodes = 1,
                                 .inst_size = sizeof(b_dev_t),
                                 .create = b_create,
                                 .sample = b_sample,
                                 .cfg = &b_cfg};

static void test_bare_node_defaults(void)
{
    h_boot(d, &b_prod, false);
    EXPECT(d, 0x720, "00");
    h_advance(d, 2000000);
    EXPECT_NONE(d); /* no heartbeat */
    co_frame_t rtr = {.id = 0x720, .rtr = true, .dlc = 1};
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x720, "7F"); /* guarding answered: no heartbeat runs */
    h_rx(d, 0x000, "01 20");
    h_advance(d, 1000000);
    EXPECT_NONE(d); /* TPDO1: no event timer; TPDO2: no SYNC */
    co_tpdo_event(d->node, 0);
    h_advance(d, 1);
    NEXT_IS(0x1A0);
    co_tpdo_event(d->node, 0); /* no inhibit time: at once again */
    h_advance(d, 1);
    NEXT_IS(0x1A0);
    EXPECT_NONE(d);
    h_rx(d, 0x081, "");
    EXPECT_NONE(d);
    h_rx(d, 0x080, "");
    EXPECT(d, 0x2A0, "11 33 22"); /* SYNC on 0x080; 0x2200 sub 1 and 2 mapped */
    EXPECT_NONE(d);
    h_rx(d, 0x07F, "");
    EXPECT_NONE(d);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x720, "85");
    h_advance(d, 1000000);
    EXPECT_NONE(d);
    /* No product hooks (ops NULL): the CAN state and the LEDs are the stack's own. */
    co_node_set_can_state(d->node, CO_CAN_PASSIVE);
    co_led_pattern_t green;
    co_led_pattern_t red;
    co_node_led_patterns(d->node, &green, &red);
    CHECK_EQ(green, CO_LED_ON);
    CHECK_EQ(red, CO_LED_FLASH1);
}

/* Before co_node_start() (NMT state initialising) a node serves no SDO
 * and takes no NMT command or SYNC: what a board receives that early is
 * dropped. */
static void test_frames_before_start(void)
{
    static b_dev_t b;
    fake_port_t *port = &d->port; /* the device's, unused here: no second port in RAM */
    fake_port_init(port);
    memset(&b, 0, sizeof(b));
    void *const ram[CO_CLS_COUNT] = {NULL, &b.vol, NULL, NULL};
    co_node_init(&b.node, &b_cfg, port, &b, ram, 0);
    CHECK_EQ(co_node_nmt_state(&b.node), CO_NMT_INIT);
    co_frame_t sdo = {
        .id = (uint16_t)(0x600u + co_node_id(&b.node)), .dlc = 8, .data = {0x40, 0x00, 0x10, 0x00}};
    co_node_receive(&b.node, &sdo, 0);
    co_frame_t start = {.id = 0x000, .dlc = 2, .data = {0x01, 0x00}};
    co_node_receive(&b.node, &start, 0);
    co_frame_t sync = {.id = 0x080, .dlc = 0};
    co_node_receive(&b.node, &sync, 0);
    CHECK_EQ(port->ntx, 0u);
    CHECK_EQ(co_node_nmt_state(&b.node), CO_NMT_INIT);
}

/*
 * Communication parameters kept in no RAM (constants) yet given their
 * write hooks, as a product that fixes them might leave them: a write is
 * refused as to a read-only object (0x06010002), never confirmed, and the
 * node goes on with the constant. Its inhibit time unit is given as 5 ms:
 * more than the 1 ms co_node_cfg_t allows, so it counts as 1 ms. TPDO2
 * maps eight objects, the most a PDO holds.
 */
/* clang-format off */
static const co_od_entry_t c_entries[] = {
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_CONST, .def = 0},
    {.index = 0x1005, .sub = 0, CO_TYPE_U32, .attr = CO_A_RW, .def = 0x80, CO_EXT(.write = co_sync_write_cobid)},
    {.index = 0x1016, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_CONST, .def = 1},
    {.index = 0x1016, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW, .def = 0x00050064, CO_EXT(.write = co_hbc_write_time)},
    {.index = 0x1017, .sub = 0, CO_TYPE_U16, .attr = CO_A_RW, .def = 0, CO_EXT(.write = co_hb_write_time)},
    {.index = 0x1800, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_CONST, .def = 2},
    {.index = 0x1800, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW | CO_A_NODEID, .def = 0x80000180u, CO_EXT(.write = co_tpdo_write_cobid)},
    {.index = 0x1800, .sub = 2, CO_TYPE_U8, .attr = CO_A_RW, .def = 1, CO_EXT(.write = co_tpdo_write_comm)},
    {.index = 0x1801, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_CONST, .def = 3},
    {.index = 0x1801, .sub = 1, CO_TYPE_U32, .attr = CO_A_R | CO_A_NODEID, .def = 0x280},
    {.index = 0x1801, .sub = 2, CO_TYPE_U8, .attr = CO_A_R, .def = 254},
    {.index = 0x1801, .sub = 3, CO_TYPE_U16, .attr = CO_A_RW, .def = 10, CO_EXT(.write = co_tpdo_write_comm)},
    {.index = 0x1802, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_CONST, .def = 2},
    {.index = 0x1802, .sub = 2, CO_TYPE_U8, .attr = CO_A_RW, CO_AT(CO_CLS_VOL, b_vol_t, type3), .def = 254, CO_EXT(.write = co_tpdo_write_comm)},
    {.index = 0x1A00, .sub = 0, CO_TYPE_U8, .attr = CO_A_RW, .def = 1, CO_EXT(.write = co_tpdo_write_map)},
    {.index = 0x1A00, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW, .def = 0x21000020u, CO_EXT(.write = co_tpdo_write_map)},
    {.index = 0x1A01, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 8}, /* the most: 8 objects */
    {.index = 0x1A01, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, .def = 0x21010008u},
    {.index = 0x1A01, .sub = 2, CO_TYPE_U32, .attr = CO_A_R, .def = 0x21010008u},
    {.index = 0x1A01, .sub = 3, CO_TYPE_U32, .attr = CO_A_R, .def = 0x21010008u},
    {.index = 0x1A01, .sub = 4, CO_TYPE_U32, .attr = CO_A_R, .def = 0x21010008u},
    {.index = 0x1A01, .sub = 5, CO_TYPE_U32, .attr = CO_A_R, .def = 0x21010008u},
    {.index = 0x1A01, .sub = 6, CO_TYPE_U32, .attr = CO_A_R, .def = 0x21010008u},
    {.index = 0x1A01, .sub = 7, CO_TYPE_U32, .attr = CO_A_R, .def = 0x21010008u},
    {.index = 0x1A01, .sub = 8, CO_TYPE_U32, .attr = CO_A_R, .def = 0x21010008u},
    {.index = 0x1A02, .sub = 0, CO_TYPE_U8, .attr = CO_A_RW, CO_AT(CO_CLS_VOL, b_vol_t, count3), .def = 0, CO_EXT(.write = co_tpdo_write_map)},
    {.index = 0x1A02, .sub = 1, CO_TYPE_U32, .attr = CO_A_RW, CO_AT(CO_CLS_VOL, b_vol_t, map3[0]), .def = 0, CO_EXT(.write = co_tpdo_write_map)},
    {.index = 0x1A02, .sub = 2, CO_TYPE_U32, .attr = CO_A_RW, CO_AT(CO_CLS_VOL, b_vol_t, map3[1]), .def = 0, CO_EXT(.write = co_tpdo_write_map)},
    {.index = 0x1A02, .sub = 3, CO_TYPE_U32, .attr = CO_A_RW, CO_AT(CO_CLS_VOL, b_vol_t, map3[2]), .def = 0, CO_EXT(.write = co_tpdo_write_map)},
    {.index = 0x2100, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_PDO, CO_AT(CO_CLS_VOL, b_vol_t, counter)},
    {.index = 0x2101, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_PDO, .def = 0x5A},
};
/* clang-format on */

static const co_od_t c_od = {.entries = c_entries,
                             .count = sizeof(c_entries) / sizeof(c_entries[0])};

static const co_service_t *const c_services[] = {&co_hbc_service, NULL};

static const co_node_cfg_t c_cfg = {
    .od = &c_od,
    .services = c_services,
    .ram_size = {0, sizeof(b_vol_t), 0, 0},
    .default_node_id = 0x20,
    .inhibit_unit_us = 5000, /* counts as 1000 (co_node_cfg_t) */
};

static const product_t c_prod = {.id = "constants",
                                 .inputs = {{NULL, NULL, 0, 0}},
                                 .nodes = 1,
                                 .inst_size = sizeof(b_dev_t),
                                 .create = b_create,
                                 .sample = b_sample,
                                 .cfg = &c_cfg};

static void test_constant_parameters_refuse_writes(void)
{
    h_boot(d, &c_prod, false);
    EXPECT(d, 0x720, "00");
    SDO(d, "2B 17 10 00 64 00 00 00", "80 17 10 00 02 00 01 06");
    SDO(d, "23 05 10 00 81 00 00 00", "80 05 10 00 02 00 01 06");
    SDO(d, "23 00 18 01 A0 01 00 00", "80 00 18 01 02 00 01 06");
    SDO(d, "2F 00 18 02 02 00 00 00", "80 00 18 02 02 00 01 06");
    SDO(d, "2F 00 1A 00 00 00 00 00", "80 00 1A 00 02 00 01 06");
    CHECK_EQ(h_read(d, 0x1017, 0), 0);
    CHECK_EQ(h_read(d, 0x1005, 0), 0x80);
    CHECK_EQ(h_read(d, 0x1800, 1), 0x800001A0u);
    CHECK_EQ(h_read(d, 0x1800, 2), 1);
    CHECK_EQ(h_read(d, 0x1A00, 0), 1);
    h_rx(d, 0x000, "01 20");
    h_advance(d, 1000000);
    h_rx(d, 0x080, "");
    EXPECT_NONE(d); /* no heartbeat; TPDO1 stays invalid */
    co_tpdo_event(d->node, 1);
    h_advance(d, 0);
    EXPECT(d, 0x2A0, "5A 5A 5A 5A 5A 5A 5A 5A");
    uint32_t t0 = d->now;
    co_tpdo_event(d->node, 1); /* inhibit time 10 x 1 ms */
    h_advance(d, 5000);
    /* A refused write changes nothing: the event still waits for the end. */
    SDO(d, "2B 01 18 03 14 00 00 00", "80 01 18 03 02 00 01 06");
    h_advance(d, 4999);
    EXPECT_NONE(d);
    h_advance(d, 1);
    NEXT_IS(0x2A0);
    CHECK_EQ(d->now - t0, 10000);
    /* The parameters of a third TPDO, which this build has no room for
     * (CO_TPDO_MAX 2), are kept as any value: no TPDO, no contract broken. */
    SDO(d, "2F 02 18 02 01 00 00 00", "60 02 18 02 00 00 00 00");
    SDO(d, "2F 02 1A 00 00 00 00 00", "60 02 1A 00 00 00 00 00");
    CHECK_EQ(h_read(d, 0x1802, 2), 1);
    /* Its mapping's rules hold all the same: 4 + 4 + 1 bytes are too many. */
    SDO(d, "23 02 1A 01 20 00 00 21", "60 02 1A 01 00 00 00 00");
    SDO(d, "23 02 1A 02 20 00 00 21", "60 02 1A 02 00 00 00 00");
    SDO(d, "23 02 1A 03 08 00 01 21", "60 02 1A 03 00 00 00 00");
    SDO(d, "2F 02 1A 00 03 00 00 00", "80 02 1A 00 42 00 04 06");
    SDO(d, "2F 02 1A 00 02 00 00 00", "60 02 1A 00 00 00 00 00");
    h_rx(d, 0x080, "");
    EXPECT_NONE(d);
    /* The heartbeat consumer (node 5, 100 ms) runs on through a refused
     * write of its time: the heartbeat's absence is still an event. */
    h_rx(d, 0x705, "05");
    h_advance(d, 50000);
    SDO(d, "23 16 10 01 C8 00 05 00", "80 16 10 01 02 00 01 06");
    h_advance(d, 50000);
    EXPECT(d, 0xA0, "30 81 11 00 00 00 00 00");
}

static void nmt_restart(void)
{
    h_rx(d, 0x000, "80 10");
    h_rx(d, 0x000, "01 10");
}

/* Entering operational again, every TPDO starts afresh (co_tpdo.h): the
 * SYNC count from zero, the first change-driven (type 0) PDO sent whatever
 * was sent before, nothing sampled for type 252, no event kept from
 * before, no inhibit time running, the event timer's first send at once. */
static void test_tpdo_restart_is_afresh(void)
{
    boot();
    SDO(d, "2F 00 18 02 03 00 00 00", "60 00 18 02 00 00 00 00"); /* every 3rd SYNC */
    h_rx(d, 0x000, "01 10");
    h_drain(d);
    h_rx(d, 0x080, "");
    h_rx(d, 0x080, "");
    EXPECT_NONE(d);
    nmt_restart();
    h_rx(d, 0x080, "");
    h_rx(d, 0x080, "");
    EXPECT_NONE(d); /* two SYNCs since the start, not four */
    h_rx(d, 0x080, "");
    NEXT_IS(0x190);
    EXPECT_NONE(d);

    boot();
    SDO(d, "2F 00 18 02 00 00 00 00", "60 00 18 02 00 00 00 00"); /* on change */
    h_rx(d, 0x000, "01 10");
    h_drain(d);
    h_rx(d, 0x080, "");
    NEXT_IS(0x190);
    h_rx(d, 0x080, "");
    EXPECT_NONE(d); /* the same data */
    nmt_restart();
    h_rx(d, 0x080, "");
    NEXT_IS(0x190); /* the first since the start */
    EXPECT_NONE(d);

    boot();
    SDO(d, "2F 00 18 02 FC 00 00 00", "60 00 18 02 00 00 00 00"); /* sampled at SYNC */
    h_rx(d, 0x000, "01 10");
    h_rx(d, 0x080, "");
    h_drain(d);
    co_frame_t rtr = {.id = 0x190, .rtr = true, .dlc = 6};
    h_rx_frame(d, &rtr);
    NEXT_IS(0x190);
    nmt_restart();
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT_NONE(d); /* no SYNC since the start: nothing sampled */

    boot();
    SDO(d, "2B 00 18 05 00 00 00 00", "60 00 18 05 00 00 00 00"); /* no timer */
    SDO(d, "2B 00 18 03 E8 03 00 00", "60 00 18 03 00 00 00 00"); /* inhibit 100 ms */
    h_rx(d, 0x000, "01 10");
    h_drain(d);
    co_tpdo_event(d->node, 0);
    h_advance(d, 0);
    NEXT_IS(0x190);
    co_tpdo_event(d->node, 0); /* waits for the inhibit time */
    h_advance(d, 10000);
    h_rx(d, 0x000, "80 10");
    h_advance(d, 40000);
    h_rx(d, 0x000, "01 10");
    h_advance(d, 0);
    EXPECT_NONE(d); /* the event from before is gone */
    co_tpdo_event(d->node, 0);
    h_advance(d, 0);
    NEXT_IS(0x190); /* at once: no inhibit time from before */
    EXPECT_NONE(d);

    boot();
    h_rx(d, 0x000, "01 10"); /* event timer 100 ms: the first at once */
    NEXT_IS(0x190);
    h_advance(d, 30000);
    EXPECT_NONE(d);
    nmt_restart();
    h_advance(d, 0);
    NEXT_IS(0x190); /* at once again, not at the old deadline */
    h_advance(d, 99999);
    EXPECT_NONE(d);
    h_advance(d, 1);
    NEXT_IS(0x190);
}

/* Reset communication brings TPDO2's default mapping back, which names an
 * object that cannot be mapped: TPDO2, valid and sending before, is then
 * silent (co_tpdo.h: an unusable mapping leaves the PDO invalid). */
static void test_tpdo_unusable_default_mapping_after_reset(void)
{
    boot();
    SDO(d, "23 01 18 01 90 02 00 80", "60 01 18 01 00 00 00 00"); /* off to remap */
    SDO(d, "2F 01 1A 00 00 00 00 00", "60 01 1A 00 00 00 00 00");
    SDO(d, "23 01 1A 01 10 00 01 20", "60 01 1A 01 00 00 00 00"); /* 0x2001, 16 bits */
    SDO(d, "2F 01 1A 00 01 00 00 00", "60 01 1A 00 00 00 00 00");
    SDO(d, "23 01 18 01 90 02 00 00", "60 01 18 01 00 00 00 00");
    SDO(d, "2B 00 18 05 00 00 00 00", "60 00 18 05 00 00 00 00"); /* TPDO1 quiet */
    h_rx(d, 0x000, "01 10");
    h_drain(d);
    h_rx(d, 0x080, "");
    EXPECT(d, 0x290, "FB FF"); /* type 1: every SYNC */
    h_rx(d, 0x000, "82 10");
    EXPECT(d, 0x710, "00");
    h_rx(d, 0x000, "01 10");
    h_drain(d);
    for (unsigned k = 0; k < 3u; k++) {
        h_rx(d, 0x080, "");
    }
    CHECK_EQ(count_id(d, 0x290), 0);
}

/* A mapping without its communication parameters (no 0x1800) is no TPDO,
 * nor is one whose default mapping holds more than 8 bytes (TPDO2: 9):
 * nothing is sent on an event, a SYNC or a remote request. */
/* clang-format off */
static const co_od_entry_t m_entries[] = {
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_CONST, .def = 0},
    {.index = 0x1801, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_CONST, .def = 2},
    {.index = 0x1801, .sub = 1, CO_TYPE_U32, .attr = CO_A_R | CO_A_NODEID, .def = 0x280},
    {.index = 0x1801, .sub = 2, CO_TYPE_U8, .attr = CO_A_R, .def = 1},
    {.index = 0x1A00, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 1},
    {.index = 0x1A00, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, .def = 0x21000020u},
    {.index = 0x1A01, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 3},
    {.index = 0x1A01, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, .def = 0x21000020u},
    {.index = 0x1A01, .sub = 2, CO_TYPE_U32, .attr = CO_A_R, .def = 0x21000020u},
    {.index = 0x1A01, .sub = 3, CO_TYPE_U32, .attr = CO_A_R, .def = 0x21010008u},
    {.index = 0x2100, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_PDO, CO_AT(CO_CLS_VOL, b_vol_t, counter)},
    {.index = 0x2101, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_PDO, .def = 0x5A},
};
/* clang-format on */

static const co_od_t m_od = {.entries = m_entries,
                             .count = sizeof(m_entries) / sizeof(m_entries[0])};

static const co_service_t *const m_services[] = {&co_rtr_service, NULL};

static const co_node_cfg_t m_cfg = {
    .od = &m_od,
    .services = m_services,
    .ram_size = {0, sizeof(b_vol_t), 0, 0},
    .default_node_id = 0x20,
};

static const product_t m_prod = {.id = "mapping only",
                                 .inputs = {{NULL, NULL, 0, 0}},
                                 .nodes = 1,
                                 .inst_size = sizeof(b_dev_t),
                                 .create = b_create,
                                 .sample = b_sample,
                                 .cfg = &m_cfg};

static void test_mapping_without_tpdo(void)
{
    h_boot(d, &m_prod, false);
    EXPECT(d, 0x720, "00");
    h_rx(d, 0x000, "01 20");
    co_tpdo_event(d->node, 0);
    co_tpdo_event(d->node, 1);
    h_advance(d, 1000);
    h_rx(d, 0x080, "");
    co_frame_t rtr = {.id = 0x7FF, .rtr = true, .dlc = 4};
    h_rx_frame(d, &rtr);
    rtr.id = 0x2A0;
    h_rx_frame(d, &rtr);
    h_advance(d, 1000000);
    EXPECT_NONE(d);
}

/* A TPDO whose mapping holds no object (sub 0 = 0) sends nothing, valid
 * COB-ID or not: at a SYNC, on a remote request. */
static void test_tpdo_without_mapped_objects(void)
{
    boot();
    SDO(d, "2B 00 18 05 00 00 00 00", "60 00 18 05 00 00 00 00"); /* TPDO1 quiet */
    SDO(d, "23 01 18 01 90 02 00 80", "60 01 18 01 00 00 00 00");
    SDO(d, "2F 01 1A 00 00 00 00 00", "60 01 1A 00 00 00 00 00");
    SDO(d, "23 01 18 01 90 02 00 00", "60 01 18 01 00 00 00 00"); /* valid, type 1 */
    h_rx(d, 0x000, "01 10");
    h_drain(d);
    h_rx(d, 0x080, "");
    co_frame_t rtr = {.id = 0x290, .rtr = true, .dlc = 0};
    h_rx_frame(d, &rtr);
    h_advance(d, 100000);
    h_rx(d, 0x080, "");
    EXPECT_NONE(d);
}

/* A TPDO whose product codes its values big-endian (the DST's "PDO
 * coding") sends each mapped value most significant byte first: 32, 24
 * and 16 bits. */
static void test_tpdo_big_endian_values(void)
{
    boot();
    co_tpdo_set_msb_first(d->node, 0, true);
    co_tpdo_set_msb_first(d->node, 1, true);
    SDO(d, "2B 00 18 05 00 00 00 00", "60 00 18 05 00 00 00 00"); /* TPDO1 quiet */
    SDO(d, "23 01 18 01 90 02 00 80", "60 01 18 01 00 00 00 00"); /* TPDO2: remap */
    SDO(d, "2F 01 1A 00 00 00 00 00", "60 01 1A 00 00 00 00 00");
    SDO(d, "23 01 1A 01 18 00 00 21", "60 01 1A 01 00 00 00 00"); /* 24 bits of 0x2100 */
    SDO(d, "23 01 1A 02 10 00 01 20", "60 01 1A 02 00 00 00 00"); /* 0x2001 */
    SDO(d, "2F 01 1A 00 02 00 00 00", "60 01 1A 00 00 00 00 00");
    SDO(d, "23 01 18 01 90 02 00 00", "60 01 18 01 00 00 00 00");
    SDO(d, "2F 01 18 02 FD 00 00 00", "60 01 18 02 00 00 00 00"); /* on request only */
    h_rx(d, 0x000, "01 10");
    h_drain(d);
    /* Odd and even bytes in turn, so that no bit of one lands on another. */
    ((t_dev_t *)h_inst(d))->vol.counter = 0x12345779u;
    co_frame_t rtr = {.id = 0x190, .rtr = true, .dlc = 6};
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x190, "12 34 57 79 FF FB");
    ((t_dev_t *)h_inst(d))->vol.counter = 0x12355779u;
    rtr.id = 0x290;
    rtr.dlc = 5;
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x290, "35 57 79 FF FB");
    co_tpdo_set_msb_first(d->node, 0, false); /* CiA 301's order again */
    rtr.id = 0x190;
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x190, "79 57 35 12 FB FF");
}

/* Two TPDOs of eight data bytes, two U32 objects: TPDO1 sent at a SYNC
 * when its data changed (type 0), TPDO2 sampled at a SYNC and sent on
 * request (type 252). Every byte counts, the eighth too. */
/* clang-format off */
static const co_od_entry_t e_entries[] = {
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_CONST, .def = 0},
    {.index = 0x1800, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_CONST, .def = 2},
    {.index = 0x1800, .sub = 1, CO_TYPE_U32, .attr = CO_A_R | CO_A_NODEID, .def = 0x180},
    {.index = 0x1800, .sub = 2, CO_TYPE_U8, .attr = CO_A_R, .def = 0},
    {.index = 0x1801, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_CONST, .def = 2},
    {.index = 0x1801, .sub = 1, CO_TYPE_U32, .attr = CO_A_R | CO_A_NODEID, .def = 0x280},
    {.index = 0x1801, .sub = 2, CO_TYPE_U8, .attr = CO_A_R, .def = 252},
    {.index = 0x1A00, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 2},
    {.index = 0x1A00, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, .def = 0x23000020u},
    {.index = 0x1A00, .sub = 2, CO_TYPE_U32, .attr = CO_A_R, .def = 0x23010020u},
    {.index = 0x1A01, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 2},
    {.index = 0x1A01, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, .def = 0x23000020u},
    {.index = 0x1A01, .sub = 2, CO_TYPE_U32, .attr = CO_A_R, .def = 0x23010020u},
    {.index = 0x2300, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_PDO, CO_AT(CO_CLS_VOL, b_vol_t, w[0])},
    {.index = 0x2301, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_PDO, CO_AT(CO_CLS_VOL, b_vol_t, w[1])},
};
/* clang-format on */

static const co_od_t e_od = {.entries = e_entries,
                             .count = sizeof(e_entries) / sizeof(e_entries[0])};

static const co_service_t *const e_services[] = {&co_rtr_service, NULL};

static const co_node_cfg_t e_cfg = {
    .od = &e_od,
    .services = e_services,
    .ram_size = {0, sizeof(b_vol_t), 0, 0},
    .default_node_id = 0x20,
};

static const product_t e_prod = {.id = "eight bytes",
                                 .inputs = {{NULL, NULL, 0, 0}},
                                 .nodes = 1,
                                 .inst_size = sizeof(b_dev_t),
                                 .create = b_create,
                                 .sample = b_sample,
                                 .cfg = &e_cfg};

static void test_tpdo_eighth_byte(void)
{
    h_boot(d, &e_prod, false);
    EXPECT(d, 0x720, "00");
    b_vol_t *v = &((b_dev_t *)h_inst(d))->vol;
    v->w[0] = 0x44332211u;
    v->w[1] = 0x00776655u;
    h_rx(d, 0x000, "01 20");
    h_rx(d, 0x080, "");
    EXPECT(d, 0x1A0, "11 22 33 44 55 66 77 00");
    h_rx(d, 0x080, "");
    EXPECT_NONE(d); /* the same data */
    v->w[1] = 0x01776655u;
    h_rx(d, 0x080, ""); /* the eighth byte changed: sent; TPDO2 samples it */
    EXPECT(d, 0x1A0, "11 22 33 44 55 66 77 01");
    v->w[1] = 0x02776655u;
    co_frame_t rtr = {.id = 0x2A0, .rtr = true, .dlc = 8};
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x2A0, "11 22 33 44 55 66 77 01"); /* as sampled */
    EXPECT_NONE(d);
}

/* Transmission type 240, the largest synchronous one: every 240th SYNC. */
static void test_tpdo_every_240th_sync(void)
{
    boot();
    SDO(d, "2F 00 18 02 F0 00 00 00", "60 00 18 02 00 00 00 00");
    h_rx(d, 0x000, "01 10");
    h_drain(d);
    for (unsigned k = 0; k < 2u; k++) {
        for (unsigned i = 1; i < 240u; i++) {
            h_rx(d, 0x080, "");
        }
        EXPECT_NONE(d);
        h_rx(d, 0x080, "");
        NEXT_IS(0x190);
        EXPECT_NONE(d);
    }
}

/* The RTR service passes on every frame that is not a remote request for
 * one of its TPDOs: listed first, it leaves node guarding its requests and
 * the heartbeat consumer its heartbeats (here producer 5, 100 ms). */
/* clang-format off */
static const co_od_entry_t r_entries[] = {
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_CONST, .def = 0},
    {.index = 0x100C, .sub = 0, CO_TYPE_U16, .attr = CO_A_R | CO_A_CONST, .def = 0},
    {.index = 0x100D, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_CONST, .def = 0},
    {.index = 0x1016, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_CONST, .def = 1},
    {.index = 0x1016, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, .def = 0x00050064u},
    {.index = 0x1800, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_CONST, .def = 2},
    {.index = 0x1800, .sub = 1, CO_TYPE_U32, .attr = CO_A_R | CO_A_NODEID, .def = 0x180},
    {.index = 0x1800, .sub = 2, CO_TYPE_U8, .attr = CO_A_R, .def = 253},
    {.index = 0x1A00, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, .def = 1},
    {.index = 0x1A00, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, .def = 0x21010008u},
    {.index = 0x2101, .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_PDO, .def = 0x5A},
};
/* clang-format on */

static const co_od_t r_od = {.entries = r_entries,
                             .count = sizeof(r_entries) / sizeof(r_entries[0])};

static const co_service_t *const r_services[] = {&co_rtr_service, &co_guard_service,
                                                 &co_hbc_service, NULL};

static const co_node_cfg_t r_cfg = {
    .od = &r_od,
    .services = r_services,
    .ram_size = {0, sizeof(b_vol_t), 0, 0},
    .default_node_id = 0x20,
};

static const product_t r_prod = {.id = "rtr first",
                                 .inputs = {{NULL, NULL, 0, 0}},
                                 .nodes = 1,
                                 .inst_size = sizeof(b_dev_t),
                                 .create = b_create,
                                 .sample = b_sample,
                                 .cfg = &r_cfg};

static void test_rtr_service_passes_other_frames_on(void)
{
    h_boot(d, &r_prod, false);
    EXPECT(d, 0x720, "00");
    h_rx(d, 0x000, "01 20");
    co_frame_t rtr = {.id = 0x1A0, .rtr = true, .dlc = 1};
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x1A0, "5A");
    rtr.id = 0x720;
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x720, "05"); /* guarded */
    h_rx(d, 0x705, "05");   /* producer 5's heartbeat: the consumer runs */
    h_advance(d, 99000);
    CHECK_EQ(d->node->nmt.state, CO_NMT_OPERATIONAL);
    h_advance(d, 2000);
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP); /* producer 5 lost */
    /* The RTR service looks at its TPDOs only, never at what the node
     * keeps right behind them (the EMCY table, here with four errors, the
     * last of code 0720h): a guard request is still answered. */
    CHECK(co_emcy_error(d->node, 0x1000, 0, true, NULL));
    CHECK(co_emcy_error(d->node, 0x2000, 0, true, NULL));
    CHECK(co_emcy_error(d->node, 0x3000, 0, true, NULL));
    CHECK(co_emcy_error(d->node, 0x0720, 0, true, NULL));
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x720, "FF"); /* toggled, pre-operational */
}

/* Two TPDOs on one COB-ID: a remote request is answered once, by the
 * first. */
static void test_rtr_answered_once(void)
{
    boot();
    SDO(d, "2B 00 18 05 00 00 00 00", "60 00 18 05 00 00 00 00"); /* TPDO1 quiet */
    SDO(d, "23 01 18 01 90 02 00 80", "60 01 18 01 00 00 00 00");
    SDO(d, "2F 01 1A 00 00 00 00 00", "60 01 1A 00 00 00 00 00");
    SDO(d, "23 01 1A 01 10 00 01 20", "60 01 1A 01 00 00 00 00"); /* 0x2001, 16 bits */
    SDO(d, "2F 01 1A 00 01 00 00 00", "60 01 1A 00 00 00 00 00");
    SDO(d, "23 01 18 01 90 01 00 00", "60 01 18 01 00 00 00 00"); /* TPDO1's CAN-ID */
    h_rx(d, 0x000, "01 10");
    h_drain(d);
    co_frame_t rtr = {.id = 0x190, .rtr = true, .dlc = 6};
    h_rx_frame(d, &rtr);
    const co_frame_t *f = h_next(d);
    CHECK(f != NULL && f->id == 0x190 && f->dlc == 6);
    EXPECT_NONE(d);
}

/* co_tpdo_changed() (a product's change-of-state check, co_tpdo.h):
 * whether an event-driven TPDO's data differ from what it last sent; false
 * outside operational, for an invalid TPDO and for one that is not
 * event-driven. */
static void test_tpdo_changed(void)
{
    boot();
    CHECK(!co_tpdo_changed(d->node, 0)); /* pre-operational */
    h_rx(d, 0x000, "01 10");
    NEXT_IS(0x190); /* sent at once: the event timer */
    CHECK(!co_tpdo_changed(d->node, 0));
    CHECK(!co_tpdo_changed(d->node, 1)); /* TPDO2: its default mapping is unusable */
    SDO(d, "2B 01 20 00 03 00 00 00", "60 01 20 00 00 00 00 00");
    CHECK(co_tpdo_changed(d->node, 0));
    h_rx(d, 0x080, ""); /* a SYNC samples no event-driven TPDO: still changed */
    CHECK(co_tpdo_changed(d->node, 0));
    SDO(d, "2F 00 18 02 01 00 00 00", "60 00 18 02 00 00 00 00"); /* synchronous */
    CHECK(!co_tpdo_changed(d->node, 0));
}

/* An event send restarts the event timer (CiA 301: the timer counts from
 * the last send); a synchronous TPDO takes no event. */
static void test_tpdo_event_restarts_the_timer(void)
{
    boot();
    h_rx(d, 0x000, "01 10");
    NEXT_IS(0x190); /* the timer's first send (100 ms) */
    h_advance(d, 30000);
    EXPECT_NONE(d);
    co_tpdo_event(d->node, 0);
    h_advance(d, 0);
    NEXT_IS(0x190);
    h_advance(d, 99999);
    EXPECT_NONE(d); /* not at 100 ms: 100 ms after the event */
    h_advance(d, 1);
    NEXT_IS(0x190);
    SDO(d, "2F 00 18 02 01 00 00 00", "60 00 18 02 00 00 00 00"); /* synchronous */
    h_drain(d);
    co_tpdo_event(d->node, 0);
    h_advance(d, 1000);
    EXPECT_NONE(d);
    h_rx(d, 0x080, "");
    NEXT_IS(0x190);
}

/* The inhibit time runs while its end is 1 us .. the inhibit time ahead of
 * the clock (which wraps after 2^32 us). An event 2^32 - 1 us (71.6 min)
 * after the last send finds that end the inhibit time + 1 us "ahead":
 * outside the window, the event goes out at once. */
static void test_tpdo_event_a_clock_turn_later(void)
{
    boot();
    SDO(d, "2B 00 18 05 00 00 00 00", "60 00 18 05 00 00 00 00"); /* no timer */
    SDO(d, "2B 00 18 03 E8 03 00 00", "60 00 18 03 00 00 00 00"); /* 100 ms */
    h_rx(d, 0x000, "01 10");
    h_drain(d);
    co_tpdo_event(d->node, 0);
    h_advance(d, 0);
    NEXT_IS(0x190);
    d->now -= 1u; /* + 2^32 - 1 us */
    d->next_sample = d->now + CO_FILTER_PERIOD_US;
    co_tpdo_event(d->node, 0);
    h_advance(d, 0);
    NEXT_IS(0x190);
    co_tpdo_event(d->node, 0); /* and the inhibit time from this send on */
    h_advance(d, 99999);
    EXPECT_NONE(d);
    h_advance(d, 1);
    NEXT_IS(0x190);
}

int main(void)
{
    RUN(test_od_find);
    RUN(test_sdo_expedited);
    RUN(test_sdo_segmented_upload);
    RUN(test_sdo_segmented_download);
    RUN(test_sdo_block_download);
    RUN(test_sdo_block_upload);
    RUN(test_nmt);
    RUN(test_nmt_stopped_is_silent);
    RUN(test_reset_comm_keeps_application);
    RUN(test_idle_poll);
    RUN(test_heartbeat_timing);
    RUN(test_tpdo_event_and_inhibit);
    RUN(test_tpdo_sync_and_bad_mapping);
    RUN(test_tpdo_reconfig_out_of_range);
    RUN(test_contract_broken_changes_nothing);
    RUN(test_emcy);
    RUN(test_tx_full_is_counted);
    RUN(test_two_nodes_one_process);
    RUN(test_node_guarding);
    RUN(test_emcy_table_and_history);
    RUN(test_emcy_clear_order_and_history_bound);
    RUN(test_emcy_cobid_odd_id);
    RUN(test_tpdo_loops_stay_in_the_table);
    RUN(test_heartbeat_late_poll_keeps_cadence);
    RUN(test_tpdo_two_event_timers);
    RUN(test_tpdo_event_timer_cadence);
    RUN(test_sdo_block_download_abort_is_final);
    RUN(test_tpdo_rtr_and_types);
    RUN(test_tpdo_events_and_inhibit);
    RUN(test_tpdo_cobid_and_mapping_rules);
    RUN(test_tpdo_event_after_a_long_quiet_spell);
    RUN(test_life_guarding_long_times);
    RUN(test_life_guarding_waits_for_a_request);
    RUN(test_largest_periods);
    RUN(test_sync_cobid_bits);
    RUN(test_emcy_cobid_restricted_and_as_written);
    RUN(test_bare_node_defaults);
    RUN(test_frames_before_start);
    RUN(test_constant_parameters_refuse_writes);
    RUN(test_tpdo_restart_is_afresh);
    RUN(test_tpdo_unusable_default_mapping_after_reset);
    RUN(test_mapping_without_tpdo);
    RUN(test_tpdo_without_mapped_objects);
    RUN(test_tpdo_big_endian_values);
    RUN(test_tpdo_eighth_byte);
    RUN(test_tpdo_every_240th_sync);
    RUN(test_rtr_service_passes_other_frames_on);
    RUN(test_rtr_answered_once);
    RUN(test_tpdo_changed);
    RUN(test_tpdo_event_restarts_the_timer);
    RUN(test_tpdo_event_a_clock_turn_later);
    return h_finish();
}
