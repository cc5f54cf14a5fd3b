/*
 * test_sdo_edge.c - the SDO server's and the dictionary's answers to
 * requests the manuals' examples never make: objects the buffer cannot
 * hold, too many or too few bytes, write-only and writable-string objects,
 * out-of-turn block frames, signed 8-bit limits, the 0x1003 history past its
 * depth. Every answer is the CiA 301 abort code (7.2.4.3.17), frame by frame.
 */
#include "harness.h"

#define LONG_NAME "A device name of seventy bytes, longer than the SDO transfer buffer..."

typedef struct e_para {
    uint32_t u32;
    int8_t i8;
    uint16_t hb;
} e_para_t;

typedef struct e_dev {
    co_node_t node;
    e_para_t para;
} e_dev_t;

#define P(f) CO_AT(CO_CLS_PARA, e_para_t, f)
#define HIST CO_EXT(.read = co_emcy_read_hist)

static const co_od_entry_t e_entries[] = {
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = CO_A_R | CO_A_CONST, .def = 0x00000191u},
    {.index = 0x1001, .sub = 0, CO_TYPE_U8, .attr = CO_A_R, CO_EXT(.read = co_emcy_read_register)},
    {.index = 0x1003, .sub = 0, CO_TYPE_U8, .attr = CO_A_RW, CO_EXT(.write = co_emcy_write_hist, .read = co_emcy_read_hist)},
    {.index = 0x1003, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, HIST},
    {.index = 0x1003, .sub = 2, CO_TYPE_U32, .attr = CO_A_R, HIST},
    {.index = 0x1003, .sub = 3, CO_TYPE_U32, .attr = CO_A_R, HIST},
    {.index = 0x1008, .sub = 0, CO_TYPE_STR(LONG_NAME), .attr = CO_A_R | CO_A_CONST},
    {.index = 0x1017, .sub = 0, CO_TYPE_U16, .attr = CO_A_RW, P(hb), .def = 0, CO_EXT(.write = co_hb_write_time)},
    {.index = 0x2000, .sub = 0, CO_TYPE_U32, .attr = CO_A_RW, P(u32), .def = 100, CO_EXT(.min = 10, .max = 1000)},
    {.index = 0x2003, .sub = 0, CO_TYPE_I8, .attr = CO_A_RW, P(i8), .def = (uint32_t)-3, CO_EXT(.min = -10, .max = 10)},
    /* A writable string: the stack stores no strings yet (co_od_write). */
    {.index = 0x2004, .sub = 0, CO_TYPE_STR("12345678"), .attr = CO_A_RW},
    /* A write-only object of more than 4 bytes: the segmented upload's check. */
    {.index = 0x2005, .sub = 0, CO_TYPE_STR("secret!!"), .attr = CO_A_W},
    /* Writable, but with no RAM to keep a value in. */
    {.index = 0x2006, .sub = 0, CO_TYPE_U32, .attr = CO_A_RW, .def = 5},
    /* Writable and longer than the transfer buffer. */
    {.index = 0x2007, .sub = 0, CO_TYPE_STR(LONG_NAME), .attr = CO_A_RW},
};

static const co_od_t e_od = {.entries = e_entries, .count = sizeof(e_entries) / sizeof(e_entries[0])};

static const co_node_cfg_t e_cfg = {
    .od = &e_od,
    .sdo_segmented = co_sdo_segmented, .sdo_block = co_sdo_block,
    .ram_size = {0, 0, sizeof(e_para_t), 0},
    .default_node_id = 0x20,
};

static void e_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    (void)p;
    e_dev_t *t = mem;
    memset(t, 0, sizeof(*t));
    void *const ram[CO_CLS_COUNT] = {NULL, NULL, &t->para, NULL};
    co_node_init(&t->node, &e_cfg, ports[0], t, ram, 0);
    nodes[0] = &t->node;
}

static void e_sample(void *mem, const int32_t v[], uint32_t fault)
{
    (void)mem;
    (void)v;
    (void)fault;
}

static const product_t e_prod = {.id = "sdo-edge", .inputs = {{NULL, NULL, 0, 0}}, .nodes = 1,
                                  .inst_size = sizeof(e_dev_t), .create = e_create,
                                  .sample = e_sample};

static h_dev_t dev;
static h_dev_t *const d = &dev;

static void boot(void)
{
    h_boot(d, &e_prod, false);
    EXPECT(d, 0x720, "00");
}

/* Segmented download: objects that do not exist, do not fit, take more bytes. */
static void test_segmented_download_refusals(void)
{
    boot();
    SDO(d, "21 00 30 00 04 00 00 00", "80 00 30 00 00 00 02 06"); /* no object */
    SDO(d, "21 00 20 01 04 00 00 00", "80 00 20 01 11 00 09 06"); /* no sub-index */
    /* 70 bytes cannot be collected: out of memory, sized or not. */
    SDO(d, "21 07 20 00 46 00 00 00", "80 07 20 00 05 00 04 05");
    SDO(d, "20 07 20 00 00 00 00 00", "80 07 20 00 05 00 04 05");
    /* Size not indicated, then a 7-byte segment for a 4-byte object: too high. */
    SDO(d, "20 00 20 00 00 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "00 01 02 03 04 05 06 07", "80 00 20 00 12 00 07 06");
    CHECK_EQ(h_read(d, 0x2000, 0), 100);
    /* An upload segment while a download is in progress: wrong command. */
    SDO(d, "21 00 20 00 04 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "60 00 00 00 00 00 00 00", "80 00 00 00 01 00 04 05");
    /* and that ended the transfer: its segment is now out of turn too. (A
     * segment has no multiplexer: only the abort code is checked.) */
    h_drain(d);
    h_rx(d, 0x620, "07 C8 00 00 00 00 00 00");
    const co_frame_t *f = h_next(d);
    CHECK(f != NULL && f->id == 0x5A0 && f->data[0] == 0x80u &&
          co_get_u32(&f->data[4]) == CO_E_CMD);
    CHECK_EQ(h_read(d, 0x2000, 0), 100);
}

/* Writable strings are refused whole (co_od_write: none is stored yet),
 * after all their segments, with 0x06010002; the object keeps its value. */
static void test_writable_string_refused(void)
{
    boot();
    SDO(d, "21 04 20 00 08 00 00 00", "60 04 20 00 00 00 00 00");
    SDO(d, "00 41 42 43 44 45 46 47", "20 00 00 00 00 00 00 00");
    SDO(d, "1D 48 00 00 00 00 00 00", "80 04 20 00 02 00 01 06"); /* toggle 1, n = 6, last */
    SDO(d, "40 04 20 00 00 00 00 00", "41 04 20 00 08 00 00 00");
    SDO(d, "60 00 00 00 00 00 00 00", "00 31 32 33 34 35 36 37"); /* n = 0: 7 bytes */
    SDO(d, "70 00 00 00 00 00 00 00", "1D 38 00 00 00 00 00 00"); /* toggle 1, n = 6, last */
}

/* Reads of a write-only object, expedited, segmented and block: 0x06010001. */
static void test_write_only_reads(void)
{
    boot();
    SDO(d, "40 05 20 00 00 00 00 00", "80 05 20 00 01 00 01 06");
    SDO(d, "A4 05 20 00 10 00 00 00", "80 05 20 00 01 00 01 06");
    /* Writable without RAM: 0x06010002, and it still reads its constant. */
    SDO(d, "23 06 20 00 07 00 00 00", "80 06 20 00 02 00 01 06");
    SDO(d, "40 06 20 00 00 00 00 00", "43 06 20 00 05 00 00 00");
    /* An RTR on the SDO CAN-ID is no request: no answer. */
    h_drain(d);
    co_frame_t rtr = {.id = 0x620, .rtr = true, .dlc = 8};
    h_rx_frame(d, &rtr);
    EXPECT_NONE(d);
}

/* INTEGER8 with limits -10..10: too low / too high, sign-extended reads. */
static void test_integer8_limits(void)
{
    boot();
    SDO(d, "40 03 20 00 00 00 00 00", "4F 03 20 00 FD 00 00 00"); /* -3 */
    SDO(d, "2F 03 20 00 F5 00 00 00", "80 03 20 00 32 00 09 06"); /* -11 */
    SDO(d, "2F 03 20 00 0B 00 00 00", "80 03 20 00 31 00 09 06"); /* 11 */
    SDO(d, "2F 03 20 00 80 00 00 00", "80 03 20 00 32 00 09 06"); /* -128 */
    SDO(d, "2F 03 20 00 F6 00 00 00", "60 03 20 00 00 00 00 00"); /* -10 */
    SDO(d, "2B 03 20 00 F6 00 00 00", "80 03 20 00 12 00 07 06"); /* 2 bytes to 1 */
    SDO(d, "40 03 20 00 00 00 00 00", "4F 03 20 00 F6 00 00 00");
    uint32_t v = 0;
    CHECK(co_od_get(d->node, co_node_entry(d->node, 0x2003, 0), &v) == CO_OK);
    CHECK_EQ((int32_t)v, -10); /* sign-extended to 32 bits for the stack */
}

/* Block download: more segments than the buffer, sizes that disagree,
 * a wrong end request. */
static void test_block_download_refusals(void)
{
    boot();
    /* No size, no CRC: ten segments (70 bytes) fill the block; an 11th is too much. */
    SDO(d, "C0 00 20 00 00 00 00 00", "A4 00 20 00 0A 00 00 00");
    h_drain(d);
    for (unsigned s = 1; s <= 10; s++) {
        co_frame_t f = {.id = 0x620, .dlc = 8, .data = {(uint8_t)s, 1, 2, 3, 4, 5, 6, 7}};
        h_rx_frame(d, &f);
    }
    EXPECT(d, 0x5A0, "A2 0A 0A 00 00 00 00 00");
    SDO(d, "01 01 02 03 04 05 06 07", "80 00 20 00 12 00 07 06");
    /* Ten segments, the last one marked: 70 - 0 bytes for a 4-byte object. */
    SDO(d, "C0 00 20 00 00 00 00 00", "A4 00 20 00 0A 00 00 00");
    h_drain(d);
    for (unsigned s = 1; s <= 10; s++) {
        co_frame_t f = {.id = 0x620, .dlc = 8, .data = {(uint8_t)(s | (s == 10u ? 0x80u : 0u))}};
        h_rx_frame(d, &f);
    }
    EXPECT(d, 0x5A0, "A2 0A 0A 00 00 00 00 00");
    SDO(d, "C1 00 00 00 00 00 00 00", "80 00 20 00 10 00 07 06"); /* length mismatch */
    /* Size 4 indicated, one segment, but the end says no byte is unused. */
    SDO(d, "C6 00 20 00 04 00 00 00", "A4 00 20 00 0A 00 00 00");
    SDO(d, "81 F4 01 00 00 00 00 00", "A2 01 0A 00 00 00 00 00");
    SDO(d, "C1 00 00 00 00 00 00 00", "80 00 20 00 10 00 07 06");
    /* After the last segment, anything but "end block download": 0x05040001. */
    SDO(d, "C6 00 20 00 04 00 00 00", "A4 00 20 00 0A 00 00 00");
    SDO(d, "81 F4 01 00 00 00 00 00", "A2 01 0A 00 00 00 00 00");
    SDO(d, "A1 00 00 00 00 00 00 00", "80 00 20 00 01 00 04 05");
    CHECK_EQ(h_read(d, 0x2000, 0), 100);
    /* Block download to a 70-byte writable object: out of memory at once. */
    SDO(d, "C6 07 20 00 46 00 00 00", "80 07 20 00 05 00 04 05");
}

/* Block upload: objects the buffer cannot hold or that have no data, bad
 * block sizes, and frames out of turn; a client without CRC gets none. */
static void test_block_upload_refusals(void)
{
    boot();
    SDO(d, "A4 08 10 00 10 00 00 00", "80 08 10 00 05 00 04 05"); /* 70 bytes: no room */
    SDO(d, "A4 03 10 01 10 00 00 00", "80 03 10 01 24 00 00 08"); /* empty history */
    SDO(d, "A4 00 10 00 80 00 00 00", "80 00 10 00 02 00 04 05"); /* 128 segments */
    /* Start expected, an upload initiate came: the transfer's multiplexer. */
    SDO(d, "A4 00 10 00 04 00 00 00", "C6 00 10 00 04 00 00 00");
    SDO(d, "40 00 10 00 00 00 00 00", "80 00 10 00 01 00 04 05");
    /* Block size 0 in the acknowledge. */
    SDO(d, "A4 00 10 00 04 00 00 00", "C6 00 10 00 04 00 00 00");
    SDO(d, "A3 00 00 00 00 00 00 00", "81 91 01 00 00 00 00 00");
    SDO(d, "A2 01 00 00 00 00 00 00", "80 00 10 00 02 00 04 05");
    /* Without CRC (A0): the end carries no CRC; after it only the end is valid. */
    SDO(d, "A0 00 10 00 04 00 00 00", "C6 00 10 00 04 00 00 00");
    SDO(d, "A3 00 00 00 00 00 00 00", "81 91 01 00 00 00 00 00");
    SDO(d, "A2 01 04 00 00 00 00 00", "CD 00 00 00 00 00 00 00"); /* n = 3 */
    SDO(d, "A2 01 04 00 00 00 00 00", "80 00 10 00 01 00 04 05");
    /* A start request again while a block waits for its acknowledge. */
    SDO(d, "A0 00 10 00 04 00 00 00", "C6 00 10 00 04 00 00 00");
    SDO(d, "A3 00 00 00 00 00 00 00", "81 91 01 00 00 00 00 00");
    SDO(d, "A3 00 00 00 00 00 00 00", "80 00 10 00 01 00 04 05");
}

/* A block upload the client never acknowledges times out like any transfer. */
static void test_block_upload_timeout(void)
{
    boot();
    SDO(d, "A4 00 10 00 04 00 00 00", "C6 00 10 00 04 00 00 00");
    SDO(d, "A3 00 00 00 00 00 00 00", "81 91 01 00 00 00 00 00");
    h_drain(d);
    h_advance(d, CO_SDO_TIMEOUT_US - 1u);
    EXPECT_NONE(d);
    h_advance(d, 1);
    EXPECT(d, 0x5A0, "80 00 10 00 00 00 04 05");
}

/* 0x1003: newest first, no deeper than the dictionary, only sub 0 writable. */
static void test_history_depth(void)
{
    boot();
    for (uint16_t i = 1; i <= CO_EMCY_HIST_MAX + 2u; i++) {
        uint8_t info[5] = {(uint8_t)i, 0, 0, 0, 0};
        CHECK(co_emcy_error(d->node, (uint16_t)(0xFF00u + i), CO_ER_MANUFACTURER, true, info));
        CHECK(co_emcy_error(d->node, (uint16_t)(0xFF00u + i), 0, false, NULL));
    }
    SDO(d, "40 03 10 00 00 00 00 00", "4F 03 10 00 03 00 00 00"); /* 3 entries here */
    SDO(d, "40 03 10 01 00 00 00 00", "43 03 10 01 0A FF 0A 00"); /* the tenth */
    SDO(d, "40 03 10 03 00 00 00 00", "43 03 10 03 08 FF 08 00");
    SDO(d, "23 03 10 01 00 00 00 00", "80 03 10 01 02 00 01 06");
    CHECK(co_emcy_write_hist(d->node, co_node_entry(d->node, 0x1003, 1), 0) == CO_E_RO);
    SDO(d, "2F 03 10 00 00 00 00 00", "60 03 10 00 00 00 00 00");
    SDO(d, "40 03 10 00 00 00 00 00", "4F 03 10 00 00 00 00 00");
}

/* The dictionary API's own checks (co_od.h), below the SDO server. */
static void test_od_api_checks(void)
{
    boot();
    co_node_t *n = d->node;
    uint8_t buf[8];
    uint32_t len = 99;
    CHECK(co_od_read(n, co_node_entry(n, 0x2005, 0), 0, buf, 8, &len) == CO_E_WO);
    CHECK_EQ(len, 0);
    len = 99;
    CHECK(co_od_read(n, co_node_entry(n, 0x1000, 0), 4, buf, 8, &len) == CO_OK); /* past the end */
    CHECK_EQ(len, 0);
    CHECK(co_od_read(n, co_node_entry(n, 0x1003, 2), 0, buf, 8, &len) == CO_E_NO_DATA);
    CHECK(co_od_read(n, co_node_entry(n, 0x1008, 0), 66, buf, 8, &len) == CO_OK);
    CHECK_EQ(len, 4);
    CHECK(memcmp(buf, "r...", 4) == 0); /* the last 4 of 70 bytes */
    uint8_t four[4] = {1, 0, 0, 0};
    CHECK(co_od_write(n, co_node_entry(n, 0x1000, 0), four, 4) == CO_E_RO);
    CHECK(co_od_store(n, co_node_entry(n, 0x1000, 0), 1) == CO_E_RO);
    /* Restricted CAN-IDs (CiA 301 7.3.5), at both edges of every range. */
    static const uint16_t restricted[] = {0x000, 0x07F, 0x101, 0x180, 0x581, 0x5FF, 0x601,
                                          0x67F, 0x6E0, 0x6FF, 0x701, 0x77F, 0x780, 0x7FF};
    static const uint16_t free_ids[] = {0x080, 0x100, 0x181, 0x580, 0x600, 0x680, 0x6DF, 0x700};
    for (size_t i = 0; i < sizeof(restricted) / sizeof(restricted[0]); i++) {
        CHECK(co_cobid_restricted(restricted[i]));
    }
    for (size_t i = 0; i < sizeof(free_ids) / sizeof(free_ids[0]); i++) {
        CHECK(!co_cobid_restricted(free_ids[i]));
    }
}

int main(void)
{
    RUN(test_segmented_download_refusals);
    RUN(test_writable_string_refused);
    RUN(test_write_only_reads);
    RUN(test_integer8_limits);
    RUN(test_block_download_refusals);
    RUN(test_block_upload_refusals);
    RUN(test_block_upload_timeout);
    RUN(test_history_depth);
    RUN(test_od_api_checks);
    return h_finish();
}
