/*
 * test_jd_manual.c - the frames of the ifm JD1xxx/JD2xxx manual and the
 * replies and follow-ups derived from them, on node 10. Labels: N are its
 * NMT frames (section 6.1), BU the boot-up; A to E its worked examples in
 * the order printed (A: a TPDO every 100 ms, B: gyro and acceleration on
 * TPDO2, C: node number 50, D: bit rate and 2300h, E: preset), each step
 * numbered; T single frames of its object sections; D-... the frames
 * derived here. Every manual write uses 22h (size not indicated) with 4
 * data bytes, also to 1- and 2-byte objects: the object's length counts.
 * Frames the manual misprints are tested corrected and say so on their
 * line.
 */
#include "harness.h"
#include "jd.h"

static h_dev_t dev;
static h_dev_t *const d = &dev;

/* A unit whose board gives it serial number D001h (co_node_set_serial;
 * the LSS vectors below are written with it). */
static void boot(const product_t *p)
{
    h_boot(d, p, false);
    d->serial[0] = 0xD001u;
    h_power_cycle(d);
    EXPECT(d, 0x70A, "00"); /* BU */
}

static void test_nmt_frames(void)
{
    boot(&jd2xxx);
    h_rx(d, 0x000, "01 0A"); /* N4 */
    CHECK_EQ(d->node->nmt.state, CO_NMT_OPERATIONAL);
    h_rx(d, 0x000, "80 0A"); /* N2 */
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
    h_rx(d, 0x000, "01 00"); /* N3 */
    h_rx(d, 0x000, "02 0A"); /* N6 */
    CHECK_EQ(d->node->nmt.state, CO_NMT_STOPPED);
    h_rx(d, 0x000, "02 00"); /* N5 */
    h_rx(d, 0x000, "80 00"); /* N1 */
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
    h_drain(d);
    h_rx(d, 0x000, "82 00"); /* N7 */
    EXPECT(d, 0x70A, "00");
    h_rx(d, 0x000, "81 0A"); /* N8, as CiA 301 codes reset node (the manual prints 82h) */
    EXPECT(d, 0x70A, "00");
}

static void test_a_event_timer_example(void)
{
    boot(&jd2xxx);
    h_rx(d, 0x000, "80 00");                                      /* A1 */
    SDO(d, "22 00 18 05 64 00 00 00", "60 00 18 05 00 00 00 00"); /* A2, D-A2 */
    SDO(d, "40 01 18 05 00 00 00 00", "4B 01 18 05 64 00 00 00"); /* side effect on TPDO2 */
    SDO(d, "40 00 22 00 00 00 00 00", "4B 00 22 00 64 00 00 00"); /* and 2200h */
    SDO(d, "22 00 18 02 FE 00 00 00", "60 00 18 02 00 00 00 00"); /* A3, D-A3 */
    h_rx(d, 0x000, "01 00");                                      /* A4 */
    h_drain(d);
    h_advance(d, 1000000 - 1);
    unsigned n1 = 0;
    unsigned n2 = 0;
    const co_frame_t *f;
    while ((f = h_next(d)) != NULL) {
        n1 += f->id == 0x18A;
        n2 += f->id == 0x28A;
    }
    CHECK_EQ(n1, 9); /* D-A5: every 100 ms; the first went out with the start, drained */
    CHECK_EQ(n2, 0); /* TPDO2 is type 1: only on SYNC */
    h_rx(d, 0x080, "");
    f = h_next(d);
    CHECK(f != NULL && f->id == 0x28A && f->dlc == 4);
    /* Change of state: a new angle goes out at once, not at the next tick. */
    h_advance(d, 20000);
    h_drain(d);
    d->truth[0] = 12340;
    h_advance(d, 6000);
    f = h_next(d);
    CHECK(f != NULL && f->id == 0x18A && co_get_u16(f->data) == 1234);
}

static void test_b_tpdo2_mapping_example(void)
{
    boot(&jd2xxx);
    SDO(d, "22 01 18 01 00 00 00 80", "60 01 18 01 00 00 00 00"); /* B1, D-B1 */
    SDO(d, "22 01 1A 00 00 00 00 80",
        "60 01 1A 00 00 00 00 00"); /* B2 as printed: its stray 80 is beyond the 1-byte object */
    /* B3 as printed writes sub 0 (meant: sub 1) with 0x10 entries: entry 3 names no
     * object (the mapping has two), CiA 301's 0x06020000. */
    SDO(d, "22 01 1A 00 10 00 00 34", "80 01 1A 00 00 00 02 06");
    SDO(d, "22 01 1A 01 10 00 00 34", "60 01 1A 01 00 00 00 00"); /* B3 corrected, D-B3 */
    SDO(d, "22 01 1A 02 10 00 03 34", "60 01 1A 02 00 00 00 00"); /* B4, D-B4 */
    SDO(d, "22 01 1A 00 02 00 00 00", "60 01 1A 00 00 00 00 00"); /* B5, D-B5 */
    SDO(d, "22 01 18 01 82 02 00 00", "60 01 18 01 00 00 00 00"); /* B6, D-B6 */
    SDO(d, "22 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00"); /* B7, D-B7 */
    h_power_cycle(d);
    d->truth[0] = 30000;
    h_rx(d, 0x000, "01 0A");
    h_advance(d, 20000);
    h_drain(d);
    h_rx(d, 0x080, ""); /* D-B8 */
    const co_frame_t *f = h_next(d);
    CHECK(f != NULL && f->id == 0x18A && f->dlc == 4 && co_get_u16(f->data) == 3000); /* D-B9 */
    f = h_next(d);
    CHECK(f != NULL && f->id == 0x282 && f->dlc == 4);
    if (f != NULL) {
        CHECK_EQ(co_get_u16(&f->data[2]), 500); /* accel X = 1000 mg x sin 30 */
    }
}

static void test_c_node_number_example(void)
{
    boot(&jd2xxx);
    SDO(d, "40 00 30 00 00 00 00 00", "4F 00 30 00 09 00 00 00"); /* D-S5 */
    /* C1 corrected: 31h for node 50, as the text says; the printed 09 keeps node 10. */
    SDO(d, "22 00 30 00 31 00 00 00", "60 00 30 00 00 00 00 00"); /* D-C1 */
    SDO(d, "22 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00"); /* C2 */
    h_drain(d);
    h_rx(d, 0x000, "81 0A");                                      /* D-C3a */
    EXPECT(d, 0x732, "00");                                       /* D-C3b: node 50 */
    SDO(d, "22 00 30 00 7F 00 00 00", "80 00 30 00 31 00 09 06"); /* > 0x7E */
    SDO(d, "22 00 30 00 1F 00 00 00", "60 00 30 00 00 00 00 00"); /* T2 */
    h_power_cycle(d);
    EXPECT(d, 0x732, "00"); /* not saved: still 50 */
}

static void test_d_bitrate_save_with_reset(void)
{
    boot(&jd2xxx);
    CHECK_EQ(d->port.kbps, 125); /* the default code 3 reached the board */
    SDO(d, "22 01 30 00 05 00 00 00", "60 01 30 00 00 00 00 00"); /* D1 */
    h_drain(d);
    CHECK_EQ(d->port.kbps, 125); /* a new code waits for the reset */
    /* D2 with the code of section 9.17 (55AAAA55h; the example prints
     * "Article type" in its middle bytes); confirmation first, then the reset. */
    h_rx(d, 0x60A, "22 00 23 00 55 AA AA 55");
    EXPECT(d, 0x58A, "60 00 23 00 00 00 00 00"); /* D-D2 */
    h_advance(d, 1);
    EXPECT(d, 0x70A, "00");      /* D-D3: boot-up (at 500 kbit/s) */
    CHECK_EQ(d->port.kbps, 500); /* the board was told before the boot-up */
    SDO(d, "40 01 30 00 00 00 00 00", "4F 01 30 00 05 00 00 00");
    SDO(d, "22 00 23 00 55 AA AA 56", "80 00 23 00 20 00 00 08");
    SDO(d, "40 00 23 00 00 00 00 00", "80 00 23 00 01 00 01 06");
}

static void test_e_preset_example(void)
{
    boot(&jd2xxx);
    d->truth[0] = 5000;
    h_advance(d, 20000);
    SDO(d, "22 00 26 00 64 00 00 00", "60 00 26 00 00 00 00 00"); /* E1, D-E1 */
    SDO(d, "40 12 60 00 00 00 00 00", "4B 12 60 00 64 00 00 00"); /* hard-wired */
    SDO(d, "40 12 61 00 00 00 00 00", "43 12 61 00 64 00 00 00");
    SDO(d, "40 13 60 00 00 00 00 00", "4B 13 60 00 70 FE 00 00"); /* 100 - 500 */
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 F4 01 00 00"); /* bit 1 off: 500 */
    SDO(d, "22 11 60 00 02 00 00 00", "60 11 60 00 00 00 00 00");
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 64 00 00 00"); /* now the preset */
    SDO(d, "22 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00"); /* E2 */
    h_power_cycle(d);
    SDO(d, "40 00 26 00 00 00 00 00", "4B 00 26 00 64 00 00 00");
    SDO(d, "22 00 26 00 29 23 00 00", "80 00 26 00 30 00 09 06"); /* 9001 > +-90 deg */
}

static void test_t1_inhibit_only_while_invalid(void)
{
    boot(&jd2xxx);
    SDO(d, "22 00 18 03 E8 03 00 00", "80 00 18 03 30 00 09 06"); /* T1 while valid */
    SDO(d, "22 00 18 01 8A 01 00 80", "60 00 18 01 00 00 00 00"); /* D-T1 */
    SDO(d, "22 00 18 03 E8 03 00 00", "60 00 18 03 00 00 00 00");
    SDO(d, "22 00 18 01 8A 01 00 00", "60 00 18 01 00 00 00 00");
    SDO(d, "40 00 18 03 00 00 00 00", "4B 00 18 03 E8 03 00 00");
    SDO(d, "40 01 18 03 00 00 00 00",
        "4B 01 18 03 01 00 00 00"); /* TPDO2 default 1, as printed (8.9.2) */
    /* Valid is bit 31 clear, whatever the CAN-ID: an odd one too. */
    SDO(d, "22 00 18 01 A1 01 00 80", "60 00 18 01 00 00 00 00");
    SDO(d, "22 00 18 01 A1 01 00 00", "60 00 18 01 00 00 00 00");
    SDO(d, "22 00 18 03 64 00 00 00", "80 00 18 03 30 00 09 06");
}

static void test_derived_s_vectors(void)
{
    boot(&jd2xxx);
    SDO(d, "40 00 10 00 00 00 00 00", "43 00 10 00 9A 01 02 00"); /* D-S2 JD2 */
    SDO(d, "40 18 10 01 00 00 00 00", "43 18 10 01 6D 66 69 00"); /* D-S3 */
    d->truth[0] = 12340;
    h_advance(d, 20000);
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 D2 04 00 00"); /* D-S4 */
    SDO(d, "40 10 61 00 00 00 00 00", "43 10 61 00 D2 04 00 00"); /* 32-bit twin */
    SDO(d, "22 00 60 00 05 00 00 00", "80 00 60 00 30 00 09 06"); /* D-S6 */
    SDO(d, "22 17 10 00 E8 03 00 00", "60 17 10 00 00 00 00 00"); /* D-S7 */
    h_drain(d);
    h_advance(d, 1000000);
    EXPECT_ID(d, 0x70A, "7F");
    /* D-S1: factory default, both TPDOs on every SYNC, TPDO1 first. */
    h_rx(d, 0x000, "01 0A");
    h_drain(d);
    h_rx(d, 0x080, "");
    EXPECT(d, 0x18A, "D2 04 00 00");
    EXPECT(d, 0x28A, "D2 04 00 00");
    boot(&jd1xxx);
    SDO(d, "40 00 10 00 00 00 00 00", "43 00 10 00 9A 01 01 00"); /* D-S2 JD1 */
    SDO(d, "40 21 60 00 00 00 00 00", "80 21 60 00 00 00 02 06"); /* no 6021h on JD1 */
    SDO(d, "40 20 60 00 00 00 00 00", "4B 20 60 00 00 00 00 00"); /* 6020h reads 0 */
}

static void test_s8_guarding_and_life_guard(void)
{
    boot(&jd2xxx);
    co_frame_t rtr = {.id = 0x70A, .rtr = true, .dlc = 1};
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x70A, "7F"); /* D-S8 */
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x70A, "FF");
    SDO(d, "22 0C 10 00 64 00 00 00", "60 0C 10 00 00 00 00 00");
    SDO(d, "22 0D 10 00 03 00 00 00", "60 0D 10 00 00 00 00 00");
    h_rx(d, 0x000, "01 0A");
    h_rx_frame(d, &rtr);
    h_drain(d);
    h_advance(d, 310000);
    EXPECT_ID(d, 0x08A, "30 81 11 00 00 00 00 00");
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
    co_led_pattern_t g;
    co_led_pattern_t r;
    co_node_led_patterns(d->node, &g, &r);
    CHECK(r == CO_LED_FLASH2 && g == CO_LED_OFF);                 /* guard event; only red shown */
    SDO(d, "40 03 10 00 00 00 00 00", "4F 03 10 00 01 00 00 00"); /* in 1003h */
    SDO(d, "40 03 10 01 00 00 00 00", "43 03 10 01 30 81 00 00");
    h_rx_frame(d, &rtr); /* the error ends; a second one comes */
    h_rx(d, 0x000, "01 0A");
    h_rx_frame(d, &rtr);
    h_advance(d, 310000);
    SDO(d, "40 03 10 00 00 00 00 00", "4F 03 10 00 01 00 00 00"); /* depth 1 */
}

static void test_heartbeat_consumer(void)
{
    boot(&jd2xxx);
    SDO(d, "23 16 10 01 C8 00 05 00", "60 16 10 01 00 00 00 00"); /* node 5, 200 ms */
    SDO(d, "23 16 10 01 C8 00 05 01", "80 16 10 01 30 00 09 06"); /* reserved bits */
    h_rx(d, 0x000, "01 0A");
    h_drain(d);
    h_advance(d, 1000000);
    CHECK_EQ(d->node->nmt.state, CO_NMT_OPERATIONAL); /* not started before a first heartbeat */
    h_rx(d, 0x705, "05");
    h_advance(d, 150000);
    h_rx(d, 0x705, "05");
    h_advance(d, 150000);
    CHECK_EQ(d->node->nmt.state, CO_NMT_OPERATIONAL);
    h_drain(d);
    h_advance(d, 60000);
    EXPECT_ID(d, 0x08A, "30 81 11 00 00 00 00 00"); /* heartbeat event (manual, section 9.13) */
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
    h_rx(d, 0x705, "05");
    EXPECT_ID(d, 0x08A, "00 00 00 00 00 00 00 00");
}

static void test_resolution_rescales(void)
{
    boot(&jd2xxx);
    SDO(d, "22 14 60 00 E8 03 00 00", "60 14 60 00 00 00 00 00"); /* 10.00 deg */
    SDO(d, "22 00 26 00 64 00 00 00", "60 00 26 00 00 00 00 00"); /* preset 1.00 deg */
    SDO(d, "22 00 60 00 64 00 00 00", "60 00 60 00 00 00 00 00"); /* 0.1 deg */
    SDO(d, "40 14 60 00 00 00 00 00", "4B 14 60 00 64 00 00 00"); /* 100 x 0.1 */
    SDO(d, "40 12 60 00 00 00 00 00", "4B 12 60 00 0A 00 00 00");
}

static void test_jd1_full_turn_and_fold(void)
{
    boot(&jd1xxx);
    d->truth[0] = 350000;
    h_advance(d, 20000);
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 B8 88 00 00"); /* 35000, UNSIGNED16 */
    SDO(d, "22 11 60 00 01 00 00 00", "60 11 60 00 00 00 00 00"); /* invert */
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 E8 03 00 00"); /* -35000 mod 36000 */
    /* JD2 folds beyond 90: 100 deg reads 80. */
    boot(&jd2xxx);
    d->truth[0] = 100000;
    h_advance(d, 20000);
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 40 1F 00 00");
}

static void test_moving_average(void)
{
    boot(&jd2xxx);
    SDO(d, "22 00 31 00 0A 00 00 00", "60 00 31 00 00 00 00 00"); /* N = 10 */
    SDO(d, "22 00 31 00 FB 00 00 00", "80 00 31 00 31 00 09 06"); /* > 250 */
    h_advance(d, 100000);
    d->truth[0] = 10000;
    h_advance(d, 25000); /* 5 of 10 samples at 10 deg */
    long long v = h_read(d, 0x6010, 0);
    CHECK(v >= 400 && v <= 600);
    h_advance(d, 50000);
    CHECK_EQ(h_read(d, 0x6010, 0), 1000);
}

/* ---- LSS (manual, section 6.3; D-S9..D-S11) ---------------------------- */

static void lss(const char *req, const char *resp, int line)
{
    h_drain(d);
    h_rx(d, 0x7E5, req);
    if (resp == NULL) {
        h_expect_none(d, "test_jd_manual.c", line);
    } else {
        h_expect(d, 0x7E4, resp, "test_jd_manual.c", line);
    }
}
#define LSS(req, resp) lss((req), (resp), __LINE__)

static void test_lss_services(void)
{
    boot(&jd2xxx);
    LSS("5A 00 00 00 00 00 00 00", NULL); /* waiting: no inquiry */
    LSS("04 01 00 00 00 00 00 00", NULL); /* D-S9 */
    LSS("5A 00 00 00 00 00 00 00", "5A 6D 66 69 00 00 00 00");
    LSS("5D 00 00 00 00 00 00 00", "5D 01 D0 00 00 00 00 00");
    LSS("5E 00 00 00 00 00 00 00", "5E 0A 00 00 00 00 00 00");
    LSS("11 20 00 00 00 00 00 00", "11 00 00 00 00 00 00 00"); /* D-S10 */
    LSS("11 80 00 00 00 00 00 00", "11 01 00 00 00 00 00 00"); /* out of range */
    LSS("13 00 02 00 00 00 00 00", "13 00 00 00 00 00 00 00"); /* 500 k */
    LSS("13 00 08 00 00 00 00 00", "13 01 00 00 00 00 00 00"); /* D-S11: 10 k */
    LSS("13 00 05 00 00 00 00 00", "13 01 00 00 00 00 00 00"); /* reserved */
    LSS("17 00 00 00 00 00 00 00", "17 00 00 00 00 00 00 00");
    LSS("04 00 00 00 00 00 00 00", NULL);
    SDO(d, "40 00 30 00 00 00 00 00", "4F 00 30 00 1F 00 00 00"); /* 3000h = 32 - 1 */
    SDO(d, "40 01 30 00 00 00 00 00", "4F 01 30 00 05 00 00 00"); /* 500 k code */
    h_drain(d);
    h_rx(d, 0x000, "82 0A"); /* the LSS node-ID is active at reset communication */
    EXPECT(d, 0x720, "00");
    h_power_cycle(d); /* and stored */
    EXPECT(d, 0x720, "00");
}

static void test_lss_selective_and_identify(void)
{
    boot(&jd2xxx);
    LSS("40 6D 66 69 00 00 00 00", NULL);
    LSS("41 00 00 00 00 00 00 00", NULL);
    LSS("42 00 00 01 00 00 00 00", NULL);
    LSS("43 01 D0 00 00 00 00 00", "44 00 00 00 00 00 00 00"); /* selected */
    LSS("5E 00 00 00 00 00 00 00", "5E 0A 00 00 00 00 00 00");
    LSS("04 00 00 00 00 00 00 00", NULL);
    LSS("40 6D 66 69 00 00 00 00", NULL);
    LSS("41 01 00 00 00 00 00 00", NULL); /* wrong product code */
    LSS("42 00 00 01 00 00 00 00", NULL);
    LSS("43 01 D0 00 00 00 00 00", NULL);
    /* Identify remote slave: vendor, product, revision and serial ranges. */
    LSS("46 6D 66 69 00 00 00 00", NULL);
    LSS("47 00 00 00 00 00 00 00", NULL);
    LSS("48 00 00 00 00 00 00 00", NULL);
    LSS("49 FF FF FF FF 00 00 00", NULL);
    LSS("4A 00 D0 00 00 00 00 00", NULL);
    LSS("4B 00 D1 00 00 00 00 00", "4F 00 00 00 00 00 00 00");
    LSS("46 6D 66 69 00 00 00 00", NULL);
    LSS("47 00 00 00 00 00 00 00", NULL);
    LSS("48 00 00 00 00 00 00 00", NULL);
    LSS("49 FF FF FF FF 00 00 00", NULL);
    LSS("4A 02 D0 00 00 00 00 00", NULL); /* serial below the range */
    LSS("4B 00 D1 00 00 00 00 00", NULL);
    /* Each sequence starts afresh at its vendor request: a matching one is
     * answered after a mismatch, and again after that. */
    for (unsigned k = 0; k < 2u; k++) {
        LSS("46 6D 66 69 00 00 00 00", NULL);
        LSS("47 00 00 00 00 00 00 00", NULL);
        LSS("48 00 00 00 00 00 00 00", NULL);
        LSS("49 FF FF FF FF 00 00 00", NULL);
        LSS("4A 00 D0 00 00 00 00 00", NULL);
        LSS("4B 00 D1 00 00 00 00 00", "4F 00 00 00 00 00 00 00");
    }
    /* A mismatch ends the sequence: the master repeating the step with a
     * matching value gets no answer either, until a new vendor request. */
    LSS("46 6D 66 69 00 00 00 00", NULL);
    LSS("47 01 00 00 00 00 00 00", NULL); /* wrong product code */
    LSS("47 00 00 00 00 00 00 00", NULL); /* the right one, too late */
    LSS("48 00 00 00 00 00 00 00", NULL);
    LSS("49 FF FF FF FF 00 00 00", NULL);
    LSS("4A 00 D0 00 00 00 00 00", NULL);
    LSS("4B 00 D1 00 00 00 00 00", NULL);
    /* Out of order (product before vendor): no answer, whatever follows. */
    LSS("47 00 00 00 00 00 00 00", NULL);
    LSS("48 00 00 00 00 00 00 00", NULL);
    LSS("49 FF FF FF FF 00 00 00", NULL);
    LSS("4A 00 D0 00 00 00 00 00", NULL);
    LSS("4B 00 D1 00 00 00 00 00", NULL);
    LSS("4C 00 00 00 00 00 00 00", NULL); /* configured: not "non-configured" */
}

static void test_lss_unconfigured_and_fastscan(void)
{
    boot(&jd2xxx);
    LSS("04 01 00 00 00 00 00 00", NULL);
    LSS("11 FF 00 00 00 00 00 00", "11 00 00 00 00 00 00 00");
    LSS("04 00 00 00 00 00 00 00", NULL);
    h_drain(d);
    h_rx(d, 0x000, "82 0A");
    EXPECT_NONE(d); /* no node-ID: silent, no boot-up */
    h_rx(d, 0x60A, "40 00 10 00 00 00 00 00");
    EXPECT_NONE(d);
    LSS("4C 00 00 00 00 00 00 00", "50 00 00 00 00 00 00 00");
    /* Fastscan, as a master runs it: 128 bits, one at a time. */
    uint32_t id[4] = {0, 0, 0, 0};
    LSS("51 00 00 00 00 80 00 00", "4F 00 00 00 00 00 00 00");
    uint8_t next = 0;
    for (uint8_t sub = 0; sub < 4u; sub++) {
        for (int bit = 31; bit >= 0; bit--) {
            co_frame_t f = {.id = 0x7E5, .dlc = 8, .data = {0x51}};
            co_put_u32(&f.data[1], id[sub]);
            f.data[5] = (uint8_t)bit;
            f.data[6] = sub;
            f.data[7] = next;
            h_drain(d);
            h_rx_frame(d, &f);
            if (h_next(d) == NULL) {
                id[sub] |= 1u << bit;
            }
        }
        next = (uint8_t)((sub + 1u) & 3u);
        co_frame_t f = {.id = 0x7E5, .dlc = 8, .data = {0x51}};
        co_put_u32(&f.data[1], id[sub]);
        f.data[5] = 0;
        f.data[6] = sub;
        f.data[7] = next;
        h_drain(d);
        h_rx_frame(d, &f);
        CHECK(h_next(d) != NULL);
    }
    CHECK_EQ(id[0], 0x0069666D);
    CHECK_EQ(id[1], 0);
    CHECK_EQ(id[2], 0x00010000);
    CHECK_EQ(id[3], 0x0000D001);
    /* Found and selected: give it node 7, back to waiting: it boots as 7. */
    LSS("11 07 00 00 00 00 00 00", "11 00 00 00 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x7E5, "04 00 00 00 00 00 00 00");
    EXPECT(d, 0x707, "00");
}

static void test_can_error_emcy(void)
{
    boot(&jd2xxx);
    h_drain(d);
    co_node_set_can_state(d->node, CO_CAN_PASSIVE);
    EXPECT(d, 0x08A, "20 81 11 00 00 00 00 00");                  /* CiA 301's 8120h */
    SDO(d, "2B 17 10 00 64 00 00 00", "60 17 10 00 00 00 00 00"); /* heartbeat 100 ms */
    h_drain(d);
    co_node_set_can_state(d->node, CO_CAN_BUSOFF);
    /* A controller in bus-off sends nothing: no "error reset" for the end
     * of error passive, no heartbeat, no EMCY, however long it lasts. */
    EXPECT_NONE(d);
    h_advance(d, 500000);
    EXPECT_NONE(d);
    co_node_set_can_state(d->node, CO_CAN_ACTIVE);
    EXPECT(d, 0x08A, "40 81 11 00 00 00 00 00"); /* recovered from bus-off (CiA 301) */
    EXPECT(d, 0x08A, "00 00 00 00 00 00 00 00");
    h_advance(d, 100000);
    EXPECT(d, 0x70A, "7F"); /* the heartbeat goes on */
    co_led_pattern_t g;
    co_led_pattern_t r;
    co_node_set_can_state(d->node, CO_CAN_BUSOFF);
    co_node_led_patterns(d->node, &g, &r);
    CHECK(r == CO_LED_ON);
}

int main(void)
{
    RUN(test_nmt_frames);
    RUN(test_a_event_timer_example);
    RUN(test_b_tpdo2_mapping_example);
    RUN(test_c_node_number_example);
    RUN(test_d_bitrate_save_with_reset);
    RUN(test_e_preset_example);
    RUN(test_t1_inhibit_only_while_invalid);
    RUN(test_derived_s_vectors);
    RUN(test_s8_guarding_and_life_guard);
    RUN(test_heartbeat_consumer);
    RUN(test_resolution_rescales);
    RUN(test_jd1_full_turn_and_fold);
    RUN(test_moving_average);
    RUN(test_lss_services);
    RUN(test_lss_selective_and_identify);
    RUN(test_lss_unconfigured_and_fastscan);
    RUN(test_can_error_emcy);
    return h_finish();
}
