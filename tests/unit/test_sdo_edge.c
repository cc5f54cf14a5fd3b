/*
 * test_sdo_edge.c - the SDO server's and the dictionary's answers to
 * requests the manuals' examples never make: objects the buffer cannot
 * hold, too many or too few bytes, write-only and writable-string objects,
 * out-of-turn block frames, signed 8-bit limits, the 0x1003 history past its
 * depth. Every answer is the CiA 301 abort code (7.2.4.3.17), frame by frame.
 */
#include "dst.h"
#include "harness.h"

#define LONG_NAME "A device name of seventy bytes, longer than the SDO transfer buffer..."
#define BUF_NAME "A string of sixty-four bytes: exactly the SDO transfer buffer..."

typedef struct e_para {
    uint32_t u32;
    int8_t i8;
    uint16_t hb;
    uint16_t ro;
    uint32_t cob;
} e_para_t;

typedef struct e_dev {
    co_node_t node;
    e_para_t para;
} e_dev_t;

#define P(f) CO_AT(CO_CLS_PARA, e_para_t, f)
#define HIST CO_EXT(.read = co_emcy_read_hist)

/* clang-format off */
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
    /* Read-only, with a value in RAM (the product sets it). */
    {.index = 0x2001, .sub = 0, CO_TYPE_U16, .attr = CO_A_R, P(ro), .def = 7},
    {.index = 0x2003, .sub = 0, CO_TYPE_I8, .attr = CO_A_RW, P(i8), .def = (uint32_t)-3, CO_EXT(.min = -10, .max = 10)},
    /* A writable string: the stack stores no strings yet (co_od_write). */
    {.index = 0x2004, .sub = 0, CO_TYPE_STR("12345678"), .attr = CO_A_RW},
    /* A write-only object of more than 4 bytes: the segmented upload's check. */
    {.index = 0x2005, .sub = 0, CO_TYPE_STR("secret!!"), .attr = CO_A_W},
    /* Writable, but with no RAM to keep a value in. */
    {.index = 0x2006, .sub = 0, CO_TYPE_U32, .attr = CO_A_RW, .def = 5},
    /* Writable and longer than the transfer buffer. */
    {.index = 0x2007, .sub = 0, CO_TYPE_STR(LONG_NAME), .attr = CO_A_RW},
    /* In a class this node keeps no RAM for (no LSS record), not at offset 0. */
    {.index = 0x2008, .sub = 0, CO_TYPE_U8, .attr = CO_A_RW, CO_AT(CO_CLS_LSS, co_lss_para_t, bitrate), .def = 3},
    /* A COB-ID of the manufacturer's that follows the node-ID from an odd base. */
    {.index = 0x2009, .sub = 0, CO_TYPE_U32, .attr = CO_A_RW | CO_A_NODEID, P(cob), .def = 0x381},
    /* Writable strings of exactly the transfer buffer, and of 5 bytes. */
    {.index = 0x200A, .sub = 0, CO_TYPE_STR(BUF_NAME), .attr = CO_A_RW},
    {.index = 0x200B, .sub = 0, CO_TYPE_STR("12345"), .attr = CO_A_RW},
    /* A string of one whole segment. */
    {.index = 0x200C, .sub = 0, CO_TYPE_STR("7 bytes"), .attr = CO_A_R},
};
/* clang-format on */

static const co_od_t e_od = {.entries = e_entries,
                             .count = sizeof(e_entries) / sizeof(e_entries[0])};

static const co_node_cfg_t e_cfg = {
    .od = &e_od,
    .sdo_segmented = co_sdo_segmented,
    .sdo_block = co_sdo_block,
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

static const product_t e_prod = {.id = "sdo-edge",
                                 .inputs = {{NULL, NULL, 0, 0}},
                                 .nodes = 1,
                                 .inst_size = sizeof(e_dev_t),
                                 .create = e_create,
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
    EXPECT_NONE(d);
    CHECK_EQ(h_read(d, 0x2000, 0), 100);
    /* Fewer bytes than the object (06070013h), a value the object refuses
     * (06090032h): the abort alone, the value kept. */
    SDO(d, "20 00 20 00 00 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "0B 01 02 00 00 00 00 00", "80 00 20 00 13 00 07 06");
    EXPECT_NONE(d);
    SDO(d, "21 00 20 00 04 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "07 05 00 00 00 00 00 00", "80 00 20 00 32 00 09 06");
    EXPECT_NONE(d);
    CHECK_EQ(h_read(d, 0x2000, 0), 100);
    /* An upload segment while a download is in progress: wrong command. */
    SDO(d, "21 00 20 00 04 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "60 00 00 00 00 00 00 00", "80 00 20 00 01 00 04 05");
    /* and that ended the transfer: its segment is now out of turn too. (A
     * segment has no multiplexer: only the abort code is checked.) */
    h_drain(d);
    h_rx(d, 0x620, "07 C8 00 00 00 00 00 00");
    const co_frame_t *f = h_next(d);
    CHECK(f != NULL && f->id == 0x5A0 && f->data[0] == 0x80u &&
          co_get_u32(&f->data[4]) == CO_E_CMD);
    CHECK_EQ(h_read(d, 0x2000, 0), 100);
    /* An expedited upload request replaces an unfinished download: its
     * segment is then out of turn, and no timeout follows. */
    SDO(d, "21 00 20 00 04 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "40 00 10 00 00 00 00 00", "43 00 10 00 91 01 00 00");
    SDO(d, "0B E8 03 00 00 00 00 00", "80 00 00 00 01 00 04 05");
    h_advance(d, 2u * CO_SDO_TIMEOUT_US);
    EXPECT_NONE(d);
    CHECK_EQ(h_read(d, 0x2000, 0), 100);
}

/* A request that names no object (a segment or block sub-command outside
 * its transfer, a reserved command specifier) is aborted with the
 * multiplexer of the transfer it ends, or 0000h sub 00h with none (CiA
 * 301): its bytes 1..3 are data, never echoed as an object. */
static void test_stray_aborts_name_the_transfer(void)
{
    boot();
    /* None in progress: 0000h sub 00h, whatever the bytes. */
    SDO(d, "E0 11 22 33 44 55 66 77", "80 00 00 00 01 00 04 05"); /* reserved (7) */
    SDO(d, "FF 11 22 33 44 55 66 77", "80 00 00 00 01 00 04 05");
    SDO(d, "0B E8 03 00 00 00 00 00", "80 00 00 00 01 00 04 05"); /* download segment */
    SDO(d, "70 11 22 33 00 00 00 00", "80 00 00 00 01 00 04 05"); /* upload segment */
    SDO(d, "C1 11 22 33 00 00 00 00", "80 00 00 00 01 00 04 05"); /* block download end */
    SDO(d, "A3 11 22 33 00 00 00 00", "80 00 00 00 01 00 04 05"); /* block upload start */
    /* During a segmented download of 2000h: its multiplexer, and the
     * transfer is over (its next segment is a stray itself). */
    SDO(d, "21 00 20 00 04 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "E0 11 22 33 44 55 66 77", "80 00 20 00 01 00 04 05");
    SDO(d, "07 C8 00 00 00 00 00 00", "80 00 00 00 01 00 04 05");
    SDO(d, "21 00 20 00 04 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "C1 11 22 33 00 00 00 00", "80 00 20 00 01 00 04 05");
    /* During a segmented upload of 1008h; during a block download of 2000h. */
    SDO(d, "40 08 10 00 00 00 00 00", "41 08 10 00 46 00 00 00");
    SDO(d, "01 11 22 33 00 00 00 00", "80 08 10 00 01 00 04 05");
    SDO(d, "C6 00 20 00 04 00 00 00", "A4 00 20 00 0A 00 00 00");
    SDO(d, "81 F4 01 00 00 00 00 00", "A2 01 0A 00 00 00 00 00");
    SDO(d, "E0 11 22 33 00 00 00 00", "80 00 20 00 01 00 04 05");
    CHECK_EQ(h_read(d, 0x2000, 0), 100);
    /* An initiate names its object, refused or not. */
    SDO(d, "C6 00 30 00 04 00 00 00", "80 00 30 00 00 00 02 06");
}

/* An object of exactly the transfer buffer's 64 bytes is taken, segmented
 * and block (only the write refuses a string); an expedited download
 * without size carries 4 bytes, too few for a 5-byte object. */
static void test_buffer_sized_object(void)
{
    boot();
    CHECK_EQ(sizeof(BUF_NAME) - 1u, CO_SDO_BUF);
    SDO(d, "21 0A 20 00 40 00 00 00", "60 0A 20 00 00 00 00 00");
    SDO(d, "20 0A 20 00 00 00 00 00", "60 0A 20 00 00 00 00 00");
    SDO(d, "C6 0A 20 00 40 00 00 00", "A4 0A 20 00 0A 00 00 00");
    h_rx(d, 0x620, "80 0A 20 00 00 00 04 05"); /* the client aborts */
    EXPECT_NONE(d);
    SDO(d, "22 0B 20 00 31 32 33 34", "80 0B 20 00 13 00 07 06");
    /* An upload of those 5 bytes is segmented (size indicated). */
    SDO(d, "40 0B 20 00 00 00 00 00", "41 0B 20 00 05 00 00 00");
    SDO(d, "60 00 00 00 00 00 00 00", "05 31 32 33 34 35 00 00");
}

/* A segmented download where the product links no segmented protocol
 * (the DST X730 takes at most 4 bytes so): the toggle bit alternates
 * through every segment, segments without data included (CiA 301). */
static void test_short_segmented_download_toggles(void)
{
    h_boot(d, &dst_x730_xy30, false);
    EXPECT(d, 0x77F, "00");
    SDO(d, "20 17 10 00 00 00 00 00", "60 17 10 00 00 00 00 00");
    SDO(d, "0E 00 00 00 00 00 00 00", "20 00 00 00 00 00 00 00"); /* no data */
    SDO(d, "1C F4 00 00 00 00 00 00", "30 00 00 00 00 00 00 00");
    SDO(d, "0E 00 00 00 00 00 00 00", "20 00 00 00 00 00 00 00");
    SDO(d, "1D 01 00 00 00 00 00 00", "30 00 00 00 00 00 00 00"); /* last */
    SDO(d, "40 17 10 00 00 00 00 00", "4B 17 10 00 F4 01 00 00");
    /* The transfer is over: a segment more is out of turn, and no timeout
     * follows. */
    SDO(d, "0E 00 00 00 00 00 00 00", "80 00 00 00 01 00 04 05");
    SDO(d, "20 17 10 00 00 00 00 00", "60 17 10 00 00 00 00 00");
    SDO(d, "0B 00 00 00 00 00 00 00", "20 00 00 00 00 00 00 00"); /* heartbeat off */
    h_advance(d, 2u * CO_SDO_TIMEOUT_US);
    for (const co_frame_t *f = h_next(d); f != NULL; f = h_next(d)) {
        CHECK_EQ(f->id, 0x77F);
    }
    /* 5 bytes in a segment that is not the last: 06070012h at once. */
    SDO(d, "20 17 10 00 00 00 00 00", "60 17 10 00 00 00 00 00");
    SDO(d, "04 01 02 03 04 05 00 00", "80 17 10 00 12 00 07 06");
    SDO(d, "40 17 10 00 00 00 00 00", "4B 17 10 00 00 00 00 00");
}

/* Writable strings are refused whole (co_od_write: none is stored yet),
 * after all their segments, with 0x06010002; the object keeps its value. */
static void test_writable_string_refused(void)
{
    boot();
    /* Three segments: the toggle alternates 0, 1, 0; each segment restarts
     * the timeout (0.9 s apart); the last one, empty, ends the transfer. */
    SDO(d, "21 04 20 00 08 00 00 00", "60 04 20 00 00 00 00 00");
    h_advance(d, 900000);
    SDO(d, "00 41 42 43 44 45 46 47", "20 00 00 00 00 00 00 00");
    h_advance(d, 900000);
    SDO(d, "1C 48 00 00 00 00 00 00", "30 00 00 00 00 00 00 00");
    h_advance(d, 900000);
    EXPECT_NONE(d);
    SDO(d, "0F 00 00 00 00 00 00 00", "80 04 20 00 02 00 01 06");
    /* A completed transfer is over: no timeout, its segments out of turn. */
    SDO(d, "21 00 20 00 04 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "07 C8 00 00 00 00 00 00", "20 00 00 00 00 00 00 00");
    h_advance(d, 2u * CO_SDO_TIMEOUT_US);
    EXPECT_NONE(d);
    SDO(d, "17 C8 00 00 00 00 00 00", "80 00 00 00 01 00 04 05");
    EXPECT_NONE(d);
    CHECK_EQ(h_read(d, 0x2000, 0), 200);
    /* Segmented upload the same way: each segment restarts the timeout,
     * the last one ends the transfer. */
    SDO(d, "40 04 20 00 00 00 00 00", "41 04 20 00 08 00 00 00");
    h_advance(d, 900000);
    SDO(d, "60 00 00 00 00 00 00 00", "00 31 32 33 34 35 36 37");
    h_advance(d, 900000);
    EXPECT_NONE(d);
    SDO(d, "70 00 00 00 00 00 00 00", "1D 38 00 00 00 00 00 00");
    h_advance(d, 2u * CO_SDO_TIMEOUT_US);
    EXPECT_NONE(d);
    SDO(d, "60 00 00 00 00 00 00 00", "80 00 00 00 01 00 04 05");
    EXPECT_NONE(d);
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
    EXPECT_NONE(d);
    SDO(d, "A4 05 20 00 10 00 00 00", "80 05 20 00 01 00 01 06");
    SDO(d, "A4 05 20 00 00 00 00 00", "80 05 20 00 01 00 01 06"); /* before the block size */
    /* Writable without RAM: 0x06010002, and it still reads its constant. */
    SDO(d, "23 06 20 00 07 00 00 00", "80 06 20 00 02 00 01 06");
    SDO(d, "40 06 20 00 00 00 00 00", "43 06 20 00 05 00 00 00");
    /* So is an object of a class the node was given no RAM for. */
    SDO(d, "2F 08 20 00 07 00 00 00", "80 08 20 00 02 00 01 06");
    SDO(d, "40 08 20 00 00 00 00 00", "4F 08 20 00 03 00 00 00");
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
    SDO(d, "2F 03 20 00 0A 00 00 00", "60 03 20 00 00 00 00 00"); /* 10 */
    SDO(d, "40 03 20 00 00 00 00 00", "4F 03 20 00 0A 00 00 00");
    SDO(d, "2F 03 20 00 F6 00 00 00", "60 03 20 00 00 00 00 00");
    SDO(d, "2B 03 20 00 F6 00 00 00", "80 03 20 00 12 00 07 06"); /* 2 bytes to 1 */
    SDO(d, "40 03 20 00 00 00 00 00", "4F 03 20 00 F6 00 00 00");
    uint32_t v = 0;
    CHECK(co_od_get(d->node, co_node_entry(d->node, 0x2003, 0), &v) == CO_OK);
    CHECK_EQ((int32_t)v, -10); /* sign-extended to 32 bits for the stack */
}

/* A COB-ID that follows the node-ID (co_od.h) from any base, here 0x381
 * on node 0x20: its default reads 0x3A1, and written back it keeps
 * following; the base itself and the CAN-IDs next to the default are
 * CAN-IDs of their own and read back as written. */
static void test_cobid_odd_base(void)
{
    boot();
    SDO(d, "40 09 20 00 00 00 00 00", "43 09 20 00 A1 03 00 00");
    SDO(d, "23 09 20 00 A1 03 00 00", "60 09 20 00 00 00 00 00");
    CHECK_EQ(((e_dev_t *)h_inst(d))->para.cob, 0x381);
    SDO(d, "23 09 20 00 81 03 00 00", "60 09 20 00 00 00 00 00");
    SDO(d, "40 09 20 00 00 00 00 00", "43 09 20 00 81 03 00 00");
    SDO(d, "23 09 20 00 A0 03 00 00", "60 09 20 00 00 00 00 00");
    SDO(d, "40 09 20 00 00 00 00 00", "43 09 20 00 A0 03 00 00");
    SDO(d, "23 09 20 00 A2 03 00 00", "60 09 20 00 00 00 00 00");
    SDO(d, "40 09 20 00 00 00 00 00", "43 09 20 00 A2 03 00 00");
    SDO(d, "23 09 20 00 80 03 00 00", "60 09 20 00 00 00 00 00");
    SDO(d, "40 09 20 00 00 00 00 00", "43 09 20 00 80 03 00 00");
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
    /* No size indicated: the end's count of unused bytes gives it (4). */
    SDO(d, "C0 00 20 00 00 00 00 00", "A4 00 20 00 0A 00 00 00");
    SDO(d, "81 2C 01 00 00 00 00 00", "A2 01 0A 00 00 00 00 00");
    SDO(d, "CD 00 00 00 00 00 00 00", "A1 00 00 00 00 00 00 00");
    CHECK_EQ(h_read(d, 0x2000, 0), 300);
    /* Two bytes, no size indicated: the write itself says "too low". */
    SDO(d, "C0 00 20 00 00 00 00 00", "A4 00 20 00 0A 00 00 00");
    SDO(d, "81 2C 01 00 00 00 00 00", "A2 01 0A 00 00 00 00 00");
    SDO(d, "D5 00 00 00 00 00 00 00", "80 00 20 00 13 00 07 06");
    CHECK_EQ(h_read(d, 0x2000, 0), 300);
}

/* Block upload: before the first block only "start upload" (cs 3) is the
 * client's turn; an ack (cs 2) or an end (cs 1) there is refused. */
static void test_block_upload_out_of_turn(void)
{
    boot();
    SDO(d, "A4 00 10 00 7F 00 00 00", "C6 00 10 00 04 00 00 00");
    SDO(d, "A2 00 7F 00 00 00 00 00", "80 00 10 00 01 00 04 05");
    SDO(d, "A4 00 10 00 7F 00 00 00", "C6 00 10 00 04 00 00 00");
    SDO(d, "A1 00 00 00 00 00 00 00", "80 00 10 00 01 00 04 05");
    SDO(d, "A4 00 10 00 7F 00 00 00", "C6 00 10 00 04 00 00 00");
    SDO(d, "A3 00 00 00 00 00 00 00", "81 91 01 00 00 00 00 00");
}

/* The block transfer's CRC (CiA 301: CRC-16-CCITT, x^16 + x^12 + x^5 + 1,
 * initial value 0): the check value of "123456789" is 31C3h, chained or
 * not; on the bus, frame by frame, both ways. */
static void test_block_crc(void)
{
    static const uint8_t digits[9] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
    CHECK_EQ(co_crc16_ccitt(0, digits, 9), 0x31C3);
    CHECK_EQ(co_crc16_ccitt(co_crc16_ccitt(0, digits, 4), digits + 4, 5), 0x31C3);
    CHECK_EQ(co_crc16_ccitt(0x1D0F, digits, 0), 0x1D0F);
    boot();
    /* Upload of 1000h (191h): the end carries CRC 871Bh of 91 01 00 00. */
    SDO(d, "A4 00 10 00 7F 00 00 00", "C6 00 10 00 04 00 00 00");
    SDO(d, "A3 00 00 00 00 00 00 00", "81 91 01 00 00 00 00 00");
    SDO(d, "A2 01 7F 00 00 00 00 00", "CD 1B 87 00 00 00 00 00");
    h_rx(d, 0x620, "A1 00 00 00 00 00 00 00");
    EXPECT_NONE(d);
    /* Download of 500 to 2000h: CRC 628Ch of F4 01 00 00 taken ... */
    SDO(d, "C6 00 20 00 04 00 00 00", "A4 00 20 00 0A 00 00 00");
    SDO(d, "81 F4 01 00 00 00 00 00", "A2 01 0A 00 00 00 00 00");
    SDO(d, "CD 8C 62 00 00 00 00 00", "A1 00 00 00 00 00 00 00");
    CHECK_EQ(h_read(d, 0x2000, 0), 500);
    /* ... and any other refused with 05040004h, the object unchanged. */
    SDO(d, "C6 00 20 00 04 00 00 00", "A4 00 20 00 0A 00 00 00");
    SDO(d, "81 20 03 00 00 00 00 00", "A2 01 0A 00 00 00 00 00");
    SDO(d, "CD 8C 62 00 00 00 00 00", "80 00 20 00 04 00 04 05");
    CHECK_EQ(h_read(d, 0x2000, 0), 500);
}

/* A block download's segments: a new transfer after one the client
 * aborted in mid-block starts at sequence number 1 again; each segment
 * restarts the SDO timeout; a download that fills the transfer buffer
 * leaves the rest of the node as it was. */
static void test_block_download_segments(void)
{
    boot();
    SDO(d, "C6 00 20 00 04 00 00 00", "A4 00 20 00 0A 00 00 00");
    h_rx(d, 0x620, "01 F4 01 00 00 00 00 00"); /* not the last: no answer */
    EXPECT_NONE(d);
    h_rx(d, 0x620, "80 00 20 00 00 00 04 05");
    EXPECT_NONE(d);
    SDO(d, "C6 00 20 00 04 00 00 00", "A4 00 20 00 0A 00 00 00");
    SDO(d, "81 C8 00 00 00 00 00 00", "A2 01 0A 00 00 00 00 00");
    SDO(d, "CD 67 36 00 00 00 00 00", "A1 00 00 00 00 00 00 00");
    CHECK_EQ(h_read(d, 0x2000, 0), 200);
    /* Segment and end each 0.9 s after the frame before. */
    SDO(d, "C6 00 20 00 04 00 00 00", "A4 00 20 00 0A 00 00 00");
    h_advance(d, 900000);
    SDO(d, "81 F4 01 00 00 00 00 00", "A2 01 0A 00 00 00 00 00");
    h_advance(d, 900000);
    EXPECT_NONE(d);
    SDO(d, "CD 8C 62 00 00 00 00 00", "A1 00 00 00 00 00 00 00");
    CHECK_EQ(h_read(d, 0x2000, 0), 500);
    /* 64 bytes of FFh into the 64-byte string: the buffer is full, the
     * string refuses the write, and the node runs on. */
    SDO(d, "C2 0A 20 00 40 00 00 00", "A4 0A 20 00 0A 00 00 00"); /* no CRC */
    for (unsigned k = 1; k <= 10u; k++) {
        co_frame_t f = {.id = 0x620,
                        .dlc = 8,
                        .data = {(uint8_t)(k | (k == 10u ? 0x80u : 0u)), 0xFF, 0xFF, 0xFF, 0xFF,
                                 0xFF, 0xFF, 0xFF}};
        h_rx_frame(d, &f);
    }
    EXPECT(d, 0x5A0, "A2 0A 0A 00 00 00 00 00");
    SDO(d, "D9 00 00 00 00 00 00 00", "80 0A 20 00 02 00 01 06"); /* 6 unused */
    /* "ABCDEFGH" into the 8-byte string, in two segments: every byte is
     * kept (the CRC, 10D1h, matches), then the string refuses the write. */
    SDO(d, "C6 04 20 00 08 00 00 00", "A4 04 20 00 0A 00 00 00");
    h_rx(d, 0x620, "01 41 42 43 44 45 46 47");
    EXPECT_NONE(d);
    SDO(d, "82 48 00 00 00 00 00 00", "A2 02 0A 00 00 00 00 00");
    SDO(d, "D9 D1 10 00 00 00 00 00", "80 04 20 00 02 00 01 06");
    h_rx(d, 0x000, "01 20");
    h_advance(d, 100000);
    h_rx(d, 0x080, "");
    h_advance(d, 100000);
    h_drain(d);
    CHECK_EQ(h_read(d, 0x2000, 0), 500);
}

/* Block upload: objects the buffer cannot hold or that have no data, bad
 * block sizes, and frames out of turn; a client without CRC gets none. */
static void test_block_upload_refusals(void)
{
    boot();
    /* Block upload frames other than the initiate while none is in
     * progress: 05040001h. */
    SDO(d, "A3 00 00 00 00 00 00 00", "80 00 00 00 01 00 04 05");
    SDO(d, "A1 00 10 00 04 00 00 00", "80 00 00 00 01 00 04 05");
    SDO(d, "A2 00 10 00 04 00 00 00", "80 00 00 00 01 00 04 05");
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

/* Block upload in more than one block, frame by frame: blocks of one
 * segment; blocks of two where the client got the first segment only and
 * is sent the rest again; an acknowledge of more segments than were sent
 * (05040003h); a new block size of 127 taken and of 128 refused
 * (05040002h); first, an object of the transfer buffer's 64 bytes in one block. */
static void test_block_upload_blocks(void)
{
    boot();
    SDO(d, "A4 0A 20 00 7F 00 00 00", "C6 0A 20 00 40 00 00 00");
    h_rx(d, 0x620, "A3 00 00 00 00 00 00 00");
    for (unsigned k = 1; k <= 10u; k++) {
        const co_frame_t *f = h_next(d);
        CHECK(f != NULL && f->data[0] == (k | (k == 10u ? 0x80u : 0u)) &&
              memcmp(&f->data[1], &BUF_NAME[7u * (k - 1u)], k == 10u ? 1u : 7u) == 0);
    }
    EXPECT_NONE(d);
    SDO(d, "A2 0A 7F 00 00 00 00 00", "D9 93 04 00 00 00 00 00");
    h_rx(d, 0x620, "A1 00 00 00 00 00 00 00");
    EXPECT_NONE(d);
    /* The same with blocks of one segment, then of three. */
    SDO(d, "A4 0A 20 00 01 00 00 00", "C6 0A 20 00 40 00 00 00");
    SDO(d, "A3 00 00 00 00 00 00 00", "01 41 20 73 74 72 69 6E");
    h_rx(d, 0x620, "A2 01 03 00 00 00 00 00");
    EXPECT(d, 0x5A0, "01 67 20 6F 66 20 73 69");
    EXPECT(d, 0x5A0, "02 78 74 79 2D 66 6F 75");
    EXPECT(d, 0x5A0, "03 72 20 62 79 74 65 73");
    EXPECT_NONE(d);
    /* A new upload request in the middle: 05040001h, and nothing else. */
    SDO(d, "A4 0A 20 00 7F 00 00 00", "80 0A 20 00 01 00 04 05");
    EXPECT_NONE(d);
    /* 7 bytes: one full segment, no byte of it unused. */
    SDO(d, "A0 0C 20 00 7F 00 00 00", "C6 0C 20 00 07 00 00 00");
    SDO(d, "A3 00 00 00 00 00 00 00", "81 37 20 62 79 74 65 73");
    SDO(d, "A2 01 7F 00 00 00 00 00", "C1 00 00 00 00 00 00 00");
    h_rx(d, 0x620, "A1 00 00 00 00 00 00 00");
    EXPECT_NONE(d);
    /* The 8-byte string: its last segment's bytes after the data are 0,
     * not what the longer one left in the buffer. */
    SDO(d, "A4 04 20 00 01 00 00 00", "C6 04 20 00 08 00 00 00");
    SDO(d, "A3 00 00 00 00 00 00 00", "01 31 32 33 34 35 36 37");
    SDO(d, "A2 01 01 00 00 00 00 00", "81 38 00 00 00 00 00 00");
    SDO(d, "A2 01 01 00 00 00 00 00", "D9 15 90 00 00 00 00 00"); /* 6 unused, CRC */
    h_rx(d, 0x620, "A1 00 00 00 00 00 00 00");
    EXPECT_NONE(d);
    SDO(d, "A4 04 20 00 02 00 00 00", "C6 04 20 00 08 00 00 00");
    h_rx(d, 0x620, "A3 00 00 00 00 00 00 00");
    EXPECT(d, 0x5A0, "01 31 32 33 34 35 36 37");
    EXPECT(d, 0x5A0, "82 38 00 00 00 00 00 00");
    SDO(d, "A2 01 02 00 00 00 00 00", "81 38 00 00 00 00 00 00");
    SDO(d, "A2 01 02 00 00 00 00 00", "D9 15 90 00 00 00 00 00");
    h_rx(d, 0x620, "A1 00 00 00 00 00 00 00");
    EXPECT_NONE(d);
    SDO(d, "A4 04 20 00 02 00 00 00", "C6 04 20 00 08 00 00 00");
    h_rx(d, 0x620, "A3 00 00 00 00 00 00 00");
    h_drain(d);
    SDO(d, "A2 03 02 00 00 00 00 00", "80 04 20 00 03 00 04 05");
    SDO(d, "A4 04 20 00 01 00 00 00", "C6 04 20 00 08 00 00 00");
    SDO(d, "A3 00 00 00 00 00 00 00", "01 31 32 33 34 35 36 37");
    SDO(d, "A2 01 7F 00 00 00 00 00", "81 38 00 00 00 00 00 00");
    SDO(d, "A2 01 7F 00 00 00 00 00", "D9 15 90 00 00 00 00 00");
    h_rx(d, 0x620, "A1 00 00 00 00 00 00 00");
    SDO(d, "A4 04 20 00 01 00 00 00", "C6 04 20 00 08 00 00 00");
    SDO(d, "A3 00 00 00 00 00 00 00", "01 31 32 33 34 35 36 37");
    SDO(d, "A2 01 80 00 00 00 00 00", "80 04 20 00 02 00 04 05");
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
    /* Every block sent and every answer restarts it: steps 0.9 s apart. */
    SDO(d, "A4 00 10 00 04 00 00 00", "C6 00 10 00 04 00 00 00");
    h_advance(d, 900000);
    SDO(d, "A3 00 00 00 00 00 00 00", "81 91 01 00 00 00 00 00");
    h_advance(d, 900000);
    EXPECT_NONE(d);
    SDO(d, "A2 00 04 00 00 00 00 00", "81 91 01 00 00 00 00 00"); /* sent again */
    h_advance(d, 900000);
    EXPECT_NONE(d);
    SDO(d, "A2 01 04 00 00 00 00 00", "CD 1B 87 00 00 00 00 00");
    h_advance(d, 900000);
    EXPECT_NONE(d);
    h_rx(d, 0x620, "A1 00 00 00 00 00 00 00");
    h_advance(d, 2u * CO_SDO_TIMEOUT_US);
    EXPECT_NONE(d);
}

/* While a transfer waits for the client, the node asks to be polled
 * again when the SDO timeout falls due, and after the timeout's abort,
 * with nothing else to time, never (co_node_poll's delay). */
static void test_poll_delay_of_a_transfer(void)
{
    boot();
    uint32_t t = d->now;
    CHECK_EQ(co_node_poll(d->node, t), CO_NEVER);
    SDO(d, "21 00 20 00 04 00 00 00", "60 00 20 00 00 00 00 00");
    CHECK_EQ(co_node_poll(d->node, t), CO_SDO_TIMEOUT_US);
    CHECK_EQ(co_node_poll(d->node, t + 400000u), CO_SDO_TIMEOUT_US - 400000u);
    CHECK_EQ(co_node_poll(d->node, t + CO_SDO_TIMEOUT_US - 1u), 1);
    EXPECT_NONE(d);
    CHECK_EQ(co_node_poll(d->node, t + CO_SDO_TIMEOUT_US), CO_NEVER);
    EXPECT(d, 0x5A0, "80 00 20 00 00 00 04 05");
    CHECK_EQ(co_node_poll(d->node, t + CO_SDO_TIMEOUT_US + 1u), CO_NEVER);
    EXPECT_NONE(d);
}

/* 0x1003: newest first, no deeper than the dictionary, only sub 0 writable. */
static void test_history_depth(void)
{
    boot();
    /* Empty: a read of an entry is aborted with 08000024h, and that alone. */
    SDO(d, "40 03 10 01 00 00 00 00", "80 03 10 01 24 00 00 08");
    EXPECT_NONE(d);
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
    CHECK(co_od_read(n, co_node_entry(n, 0x1000, 0), 4, buf, 8, &len) == CO_OK); /* at the end */
    CHECK_EQ(len, 0);
    len = 99;
    CHECK(co_od_read(n, co_node_entry(n, 0x1000, 0), 9, buf, 8, &len) == CO_OK); /* past it */
    CHECK_EQ(len, 0);
    len = 99;
    CHECK(co_od_read(n, co_node_entry(n, 0x1008, 0), 71, buf, 8, &len) == CO_OK);
    CHECK_EQ(len, 0);
    CHECK(co_od_read(n, co_node_entry(n, 0x1003, 2), 0, buf, 8, &len) == CO_E_NO_DATA);
    CHECK(co_od_read(n, co_node_entry(n, 0x1008, 0), 66, buf, 8, &len) == CO_OK);
    CHECK_EQ(len, 4);
    CHECK(memcmp(buf, "r...", 4) == 0); /* the last 4 of 70 bytes */
    uint8_t four[4] = {1, 0, 0, 0};
    CHECK(co_od_write(n, co_node_entry(n, 0x1000, 0), four, 4) == CO_E_RO);
    /* Read-only with RAM: refused by the dictionary itself, as by SDO. */
    CHECK(co_od_write(n, co_node_entry(n, 0x2001, 0), four, 2) == CO_E_RO);
    SDO(d, "2B 01 20 00 01 00 00 00", "80 01 20 00 02 00 01 06");
    SDO(d, "40 01 20 00 00 00 00 00", "4B 01 20 00 07 00 00 00");
    CHECK(co_od_store(n, co_node_entry(n, 0x1000, 0), 1) == CO_E_RO);
    /* Validation (co_od_validate): entries without RAM, strings and
     * entries of a class the node keeps no RAM for pass as they are. */
    CHECK(co_od_validate(n, co_node_entry(n, 0x2006, 0)));
    CHECK(co_od_validate(n, co_node_entry(n, 0x1008, 0)));
    CHECK(co_od_validate(n, co_node_entry(n, 0x2008, 0)));
    SDO(d, "40 06 20 00 00 00 00 00", "43 06 20 00 05 00 00 00");
    SDO(d, "40 08 20 00 00 00 00 00", "4F 08 20 00 03 00 00 00");
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

/* A table of every shape the lookup meets: a first object with a hole
 * after sub 0, a one-entry object followed by one with a hole (its sub 2
 * sits where the one-entry object's sub 2 would be), an object without
 * sub 0, and a record with holes at both ends of its sub-indices. */
/* clang-format off */
#define F(i, s) {.index = (i), .sub = (s), CO_TYPE_U8, .attr = CO_A_R}
static const co_od_entry_t f_entries[] = {
    F(0x1000, 0), F(0x1000, 2), F(0x1001, 0), F(0x1002, 0), F(0x1002, 2), F(0x1002, 3),
    F(0x1004, 1), F(0x1004, 2), F(0x1005, 0), F(0x1006, 0), F(0x1006, 1), F(0x1006, 3),
    F(0x1006, 5), F(0x1007, 0),
};
/* clang-format on */

/* co_od_find on every prefix of that table (each a table of its own, so
 * the search meets every shape at every place) finds exactly the entries
 * a plain scan finds, and tells a missing object (0x06020000) from a
 * missing sub-index (0x06090011). */
static void test_od_find_every_shape(void)
{
    const uint16_t n = (uint16_t)(sizeof(f_entries) / sizeof(f_entries[0]));
    for (uint16_t count = 0; count <= n; count++) {
        const co_od_t od = {.entries = f_entries, .count = count};
        for (uint16_t index = 0x0FFF; index <= 0x1008u; index++) {
            for (uint8_t sub = 0; sub <= 6u; sub++) {
                const co_od_entry_t *want = NULL;
                co_res_t want_r = CO_E_NO_OBJ;
                for (uint16_t k = 0; k < count; k++) {
                    if (f_entries[k].index == index && f_entries[k].sub == sub) {
                        want = &f_entries[k];
                        want_r = CO_OK;
                    } else if (f_entries[k].index == index && want == NULL) {
                        want_r = CO_E_NO_SUB;
                    }
                }
                co_res_t r = CO_E_HW;
                CHECK(co_od_find(&od, index, sub, &r) == want);
                CHECK(r == want_r);
                CHECK(co_od_find(&od, index, sub, NULL) == want);
            }
        }
    }
}

/* co_od_defaults sets every entry of the class whose index lies in
 * [lo, hi], both ends included, the table's first entry too, and no
 * other entry. A node of its own on a table of three PARA objects. */
/* clang-format off */
static const co_od_entry_t g_entries[] = {
    {.index = 0x2000, .sub = 0, CO_TYPE_U32, .attr = CO_A_RW, P(u32), .def = 100},
    {.index = 0x2001, .sub = 0, CO_TYPE_U16, .attr = CO_A_R, P(ro), .def = 7},
    {.index = 0x2003, .sub = 0, CO_TYPE_I8, .attr = CO_A_RW, P(i8), .def = (uint32_t)-3},
};
/* clang-format on */
static const co_od_t g_od = {.entries = g_entries, .count = 3};
static const co_node_cfg_t g_cfg = {
    .od = &g_od, .ram_size = {0, 0, sizeof(e_para_t), 0}, .default_node_id = 0x21};

static void test_od_defaults_range(void)
{
    static co_node_t node;
    static e_para_t para;
    void *const ram[CO_CLS_COUNT] = {NULL, NULL, &para, NULL};
    co_node_init(&node, &g_cfg, NULL, NULL, ram, 0);
    para = (e_para_t){.u32 = 500, .i8 = 4, .hb = 9, .ro = 8};
    co_od_defaults(&node, CO_CLS_VOL, 0x0000, 0xFFFF); /* another class */
    co_od_defaults(&node, CO_CLS_PARA, 0x2001, 0x2002);
    CHECK_EQ(para.u32, 500);
    CHECK_EQ(para.ro, 7);
    CHECK_EQ(para.i8, 4);
    para.ro = 8;
    co_od_defaults(&node, CO_CLS_PARA, 0x2002, 0x2003);
    CHECK_EQ(para.ro, 8);
    CHECK_EQ(para.i8, -3);
    co_od_defaults(&node, CO_CLS_PARA, 0x1000, 0x2000);
    CHECK_EQ(para.u32, 100);
    CHECK_EQ(para.ro, 8);
    CHECK_EQ(para.hb, 9); /* no entry holds it */
}

/* Paint the stack below the caller with ones: a field a frame built on
 * the stack is sent without would show. */
static CO_NOINLINE void paint_stack(void)
{
    volatile uint8_t junk[1024];
    for (size_t i = 0; i < sizeof(junk); i++) {
        junk[i] = 0xFF;
    }
}

/* SDO answers are data frames of 8 bytes, never remote frames: expedited,
 * segmented, block and abort answers alike. */
static void test_answers_are_data_frames(void)
{
    boot();
    static const char *const req[] = {
        "40 00 10 00 00 00 00 00", /* expedited upload */
        "40 08 10 00 00 00 00 00", /* segmented upload initiate */
        "60 00 00 00 00 00 00 00", /* its first segment */
        "40 00 30 00 00 00 00 00", /* abort: no object */
        "A4 00 10 00 04 00 00 00", /* block upload initiate */
        "A3 00 00 00 00 00 00 00", /* its block */
    };
    for (size_t i = 0; i < sizeof(req) / sizeof(req[0]); i++) {
        h_drain(d);
        paint_stack();
        h_rx(d, 0x620, req[i]);
        const co_frame_t *f = h_next(d);
        CHECK(f != NULL && f->id == 0x5A0 && f->dlc == 8u && !f->rtr);
    }
    h_rx(d, 0x620, "80 00 10 00 00 00 04 05"); /* the client ends the block upload */
    h_drain(d);
    /* A last upload segment's bytes after its data are 0 (CiA 301). */
    SDO(d, "40 04 20 00 00 00 00 00", "41 04 20 00 08 00 00 00");
    SDO(d, "60 00 00 00 00 00 00 00", "00 31 32 33 34 35 36 37");
    paint_stack();
    SDO(d, "70 00 00 00 00 00 00 00", "1D 38 00 00 00 00 00 00");
}

int main(void)
{
    RUN(test_segmented_download_refusals);
    RUN(test_stray_aborts_name_the_transfer);
    RUN(test_writable_string_refused);
    RUN(test_buffer_sized_object);
    RUN(test_short_segmented_download_toggles);
    RUN(test_write_only_reads);
    RUN(test_integer8_limits);
    RUN(test_cobid_odd_base);
    RUN(test_block_download_refusals);
    RUN(test_block_upload_out_of_turn);
    RUN(test_block_upload_refusals);
    RUN(test_block_crc);
    RUN(test_block_download_segments);
    RUN(test_block_upload_timeout);
    RUN(test_block_upload_blocks);
    RUN(test_poll_delay_of_a_transfer);
    RUN(test_history_depth);
    RUN(test_od_api_checks);
    RUN(test_od_find_every_shape);
    RUN(test_od_defaults_range);
    RUN(test_answers_are_data_frames);
    return h_finish();
}
