/*
 * test_jd_edge.c - the ifm JD1xxx / JD2xxx beyond the manual's example
 * frames: the JD1 preset through 2600h as an unsigned bit pattern and its
 * offset normalised into (-N/2, N/2], the lateral axis' presets with
 * inversion, the 16-bit slope clamped to its type and the 32-bit one not,
 * the fold of negative angles, the temperature, the moving average across
 * 0/360 deg on the JD1, the LED and LSS "store" through 3000h/3001h.
 * Node 10 (0x70A, SDO 0x60A).
 */
#include "harness.h"
#include "jd.h"

static h_dev_t dev;
static h_dev_t *const d = &dev;

static void boot(const product_t *p)
{
    h_boot(d, p, false);
    EXPECT(d, 0x70A, "00");
}

/* Set the true inputs and let the sensor settle (MAF off: one sample). */
static void tilt(int32_t a, int32_t b)
{
    d->truth[0] = a;
    d->truth[1] = b;
    h_advance(d, 20000);
}

/* JD1 (N = 36000 at 0.01 deg): 2600h takes 0..N-1 as an unsigned bit
 * pattern; the offset is kept in (-N/2, N/2]; the output wraps into 0..N-1. */
static void test_jd1_preset_and_wrap(void)
{
    boot(&jd1xxx);
    tilt(100000, 25000);                                          /* 100 deg */
    SDO(d, "22 11 60 00 02 00 00 00", "60 11 60 00 00 00 00 00"); /* scaling on */
    SDO(d, "2B 00 26 00 B8 88 00 00", "60 00 26 00 00 00 00 00"); /* 35000 */
    SDO(d, "40 13 60 00 00 00 00 00", "4B 13 60 00 08 D5 00 00"); /* 25000 -> -11000 */
    SDO(d, "40 13 61 00 00 00 00 00", "43 13 61 00 08 D5 FF FF");
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 B8 88 00 00"); /* 35000 */
    SDO(d, "40 00 26 00 00 00 00 00", "4B 00 26 00 B8 88 00 00");
    SDO(d, "2B 00 26 00 A0 8C 00 00", "80 00 26 00 30 00 09 06"); /* 36000 = N */
    SDO(d, "23 12 61 00 FF FF FF FF", "80 12 61 00 30 00 09 06"); /* -1 */
    SDO(d, "23 12 61 00 A0 8C 00 00", "80 12 61 00 30 00 09 06"); /* N */
    SDO(d, "23 12 61 00 00 00 00 00", "60 12 61 00 00 00 00 00"); /* 0 */
    SDO(d, "40 13 60 00 00 00 00 00", "4B 13 60 00 F0 D8 00 00"); /* -10000 */
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 00 00 00 00");
    /* 6020h and 6120h read 0 on the JD1 (manual, section 9.41). */
    SDO(d, "40 20 60 00 00 00 00 00", "4B 20 60 00 00 00 00 00");
    SDO(d, "40 20 61 00 00 00 00 00", "43 20 61 00 00 00 00 00");
}

/* JD2 lateral axis: 2601h, 6022h and 6122h set the one preset; the offset
 * of an inverted axis is P + r (the manual's P - r x multiplier). */
static void test_jd2_lateral_preset_inverted(void)
{
    boot(&jd2xxx);
    tilt(0, 20000);                                               /* y = 20 deg */
    SDO(d, "22 21 60 00 03 00 00 00", "60 21 60 00 00 00 00 00"); /* invert, scaling */
    SDO(d, "2B 01 26 00 F4 01 00 00", "60 01 26 00 00 00 00 00"); /* 5.00 deg */
    SDO(d, "40 23 60 00 00 00 00 00", "4B 23 60 00 C4 09 00 00"); /* 500 + 2000 */
    SDO(d, "40 20 60 00 00 00 00 00", "4B 20 60 00 F4 01 00 00"); /* -2000 + 2500 */
    SDO(d, "40 22 60 00 00 00 00 00", "4B 22 60 00 F4 01 00 00");
    SDO(d, "23 22 61 00 E8 03 00 00", "60 22 61 00 00 00 00 00"); /* 10.00 deg */
    SDO(d, "40 23 61 00 00 00 00 00", "43 23 61 00 18 FC FF FF"); /* 1000 - 2000 (not inverted) */
    SDO(d, "40 23 60 00 00 00 00 00", "4B 23 60 00 B8 0B 00 00"); /* 1000 + 2000 */
    SDO(d, "40 01 26 00 00 00 00 00", "4B 01 26 00 E8 03 00 00");
    SDO(d, "2B 01 26 00 29 23 00 00", "80 01 26 00 30 00 09 06"); /* 90.01 deg */
    SDO(d, "2B 01 26 00 D7 DC 00 00", "80 01 26 00 30 00 09 06"); /* -90.01 deg */
    SDO(d, "2B 01 26 00 28 23 00 00",
        "60 01 26 00 00 00 00 00"); /* +-90.00 deg: the range's ends */
    SDO(d, "2B 01 26 00 D8 DC 00 00", "60 01 26 00 00 00 00 00");
    SDO(d, "2B 01 26 00 E8 03 00 00", "60 01 26 00 00 00 00 00"); /* 10.00 deg again */
    SDO(d, "40 12 60 00 00 00 00 00", "4B 12 60 00 00 00 00 00"); /* X untouched */
    /* 6022h is the lateral preset too. */
    SDO(d, "2B 22 60 00 2C 01 00 00", "60 22 60 00 00 00 00 00"); /* 3.00 deg */
    SDO(d, "40 01 26 00 00 00 00 00", "4B 01 26 00 2C 01 00 00");
    SDO(d, "40 12 61 00 00 00 00 00", "43 12 61 00 00 00 00 00"); /* X untouched */
    SDO(d, "40 22 61 00 00 00 00 00", "43 22 61 00 2C 01 00 00");
}

/* A preset sets the offset once, at the angle of that moment; a
 * saved offset comes back at power-on as it was, whatever the angle is
 * then (the preset is not taken again). */
static void test_jd2_preset_offset_survives_power_cycle(void)
{
    boot(&jd2xxx);
    tilt(10000, 0);
    SDO(d, "22 11 61 00 02 00 00 00", "60 11 61 00 00 00 00 00"); /* scaling on */
    SDO(d, "22 11 60 00 02 00 00 00", "60 11 60 00 00 00 00 00");
    SDO(d, "23 12 61 00 00 00 00 00", "60 12 61 00 00 00 00 00"); /* zero here */
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    d->truth[0] = 20000;
    h_power_cycle(d);
    EXPECT(d, 0x70A, "00");
    h_advance(d, 20000);
    SDO(d, "40 10 61 00 00 00 00 00", "43 10 61 00 E8 03 00 00"); /* 10.00 deg past it */
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 E8 03 00 00");
    SDO(d, "40 13 61 00 00 00 00 00", "43 13 61 00 18 FC FF FF"); /* -1000 */
}

/* Half away from zero, as the device rounds into a coarser unit. */
static int32_t div_round(int32_t v, int32_t k)
{
    return v >= 0 ? (v + k / 2) / k : -((-v + k / 2) / k);
}

/* A new resolution carries every preset, offset and differential
 * offset into the new unit, on both axes, 16- and 32-bit objects: rounded
 * into a coarser unit, multiplied into a finer one. */
static void test_jd2_resolution_rescales_everything(void)
{
    static const uint16_t objs[] = {0x6012, 0x6013, 0x6014, 0x6022, 0x6023, 0x6024,
                                    0x6112, 0x6113, 0x6114, 0x6122, 0x6123, 0x6124};
    enum { N = sizeof(objs) / sizeof(objs[0]) };
    boot(&jd2xxx);
    tilt(12345, -5678);
    SDO(d, "22 11 60 00 02 00 00 00", "60 11 60 00 00 00 00 00"); /* scaling on */
    SDO(d, "22 21 60 00 03 00 00 00", "60 21 60 00 00 00 00 00"); /* and inverted */
    SDO(d, "22 11 61 00 02 00 00 00", "60 11 61 00 00 00 00 00");
    SDO(d, "22 21 61 00 02 00 00 00", "60 21 61 00 00 00 00 00");
    SDO(d, "2B 14 60 00 2D 01 00 00", "60 14 60 00 00 00 00 00"); /* 3.01 deg */
    SDO(d, "2B 24 60 00 69 FF 00 00", "60 24 60 00 00 00 00 00"); /* -1.51 deg */
    SDO(d, "23 14 61 00 FB 00 00 00", "60 14 61 00 00 00 00 00"); /* 2.51 deg */
    SDO(d, "23 24 61 00 CD FF FF FF", "60 24 61 00 00 00 00 00"); /* -0.51 deg */
    SDO(d, "2B 12 60 00 65 00 00 00", "60 12 60 00 00 00 00 00"); /* X 1.01 deg */
    SDO(d, "2B 22 60 00 37 FF 00 00", "60 22 60 00 00 00 00 00"); /* Y -2.01 deg */
    int32_t before[N];
    for (unsigned i = 0; i < N; i++) {
        long long v = h_read(d, objs[i], 0);
        before[i] = objs[i] < 0x6100u ? (int16_t)v : (int32_t)v;
    }
    SDO(d, "22 00 60 00 64 00 00 00", "60 00 60 00 00 00 00 00"); /* 0.1 deg */
    int32_t coarse[N];
    for (unsigned i = 0; i < N; i++) {
        long long v = h_read(d, objs[i], 0);
        coarse[i] = objs[i] < 0x6100u ? (int16_t)v : (int32_t)v;
        if (coarse[i] != div_round(before[i], 10)) {
            fprintf(stderr, "  %04Xh: %ld at 0.01 deg, %ld at 0.1 deg\n", (unsigned)objs[i],
                    (long)before[i], (long)coarse[i]);
            FAIL("not rounded into the coarser unit");
        }
    }
    SDO(d, "22 00 60 00 0A 00 00 00", "60 00 60 00 00 00 00 00"); /* 0.01 deg again */
    for (unsigned i = 0; i < N; i++) {
        long long v = h_read(d, objs[i], 0);
        int32_t fine = objs[i] < 0x6100u ? (int16_t)v : (int32_t)v;
        if (fine != coarse[i] * 10) {
            fprintf(stderr, "  %04Xh: %ld at 0.1 deg, %ld at 0.01 deg\n", (unsigned)objs[i],
                    (long)coarse[i], (long)fine);
            FAIL("not multiplied into the finer unit");
        }
    }
}

/* The cyclic time (2200h = 1800h/1801h sub 5) applies at once to
 * both TPDOs, also while operational. */
static void test_jd2_cyclic_time_while_operational(void)
{
    boot(&jd2xxx);
    SDO(d, "22 00 18 02 FE 00 00 00", "60 00 18 02 00 00 00 00"); /* both on the timer */
    SDO(d, "22 01 18 02 FE 00 00 00", "60 01 18 02 00 00 00 00");
    h_rx(d, 0x000, "01 0A");
    h_advance(d, 100000);
    SDO(d, "2B 00 22 00 32 00 00 00", "60 00 22 00 00 00 00 00"); /* 50 ms */
    h_drain(d);
    h_advance(d, 500000);
    unsigned n1 = 0;
    unsigned n2 = 0;
    for (const co_frame_t *f = h_next(d); f != NULL; f = h_next(d)) {
        n1 += f->id == 0x18A;
        n2 += f->id == 0x28A;
    }
    CHECK(n1 >= 9u && n1 <= 11u);
    CHECK(n2 >= 9u && n2 <= 11u);
}

/* The gyro rates 3400h..3402h in 0.1 deg/s, +-500 deg/s at most, from
 * the angle's change over the 5 ms sample period, the short way round:
 * the JD2's X and Y turn about its X and Y axes, the JD1's Z about Z. */
static void test_gyro_rates(void)
{
    static const struct {
        int32_t x, y;
        int16_t gx, gy;
    } v[] = {
        {0, 0, 0, 0},
        {500, -250, 1000, -500},    /* 100.0 and -50.0 deg/s */
        {3500, -3250, 5000, -5000}, /* 600 deg/s: the range's ends */
        {179000, -179000, 5000, -5000},
        {-179000, 179000, 4000, -4000}, /* across 180 deg: 2 deg the short way */
        {-179000, 179000, 0, 0},
    };
    boot(&jd2xxx);
    CHECK_EQ(h_read(d, 0x3400, 0), 0); /* at rest from power-on */
    CHECK_EQ(h_read(d, 0x3401, 0), 0);
    jd_dev_t *j = h_inst(d);
    for (unsigned i = 0; i < sizeof(v) / sizeof(v[0]); i++) {
        int32_t in[3] = {v[i].x, v[i].y, 25000};
        d->prod->sample(j, in, 0);
        CHECK_EQ((int16_t)h_read(d, 0x3400, 0), v[i].gx);
        CHECK_EQ((int16_t)h_read(d, 0x3401, 0), v[i].gy);
        CHECK_EQ((int16_t)h_read(d, 0x3402, 0), 0);
    }
    boot(&jd1xxx);
    j = h_inst(d);
    for (unsigned i = 0; i < sizeof(v) / sizeof(v[0]); i++) {
        int32_t in[2] = {v[i].y, 25000};
        d->prod->sample(j, in, 0);
        CHECK_EQ((int16_t)h_read(d, 0x3400, 0), 0);
        CHECK_EQ((int16_t)h_read(d, 0x3401, 0), 0);
        CHECK_EQ((int16_t)h_read(d, 0x3402, 0), v[i].gy);
    }
}

/* 3000h = node-ID - 1, 0x7E the last (node 127); read with 3001h
 * at power-on and reset node after a save: a reset communication keeps
 * the running node-ID and bit rate. */
static void test_node_number_at_reset_node_only(void)
{
    boot(&jd2xxx);
    SDO(d, "22 00 30 00 7E 00 00 00", "60 00 30 00 00 00 00 00");
    SDO(d, "22 01 30 00 05 00 00 00", "60 01 30 00 00 00 00 00"); /* 500 kbit/s */
    SDO(d, "22 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x000, "82 0A");
    EXPECT(d, 0x70A, "00");
    CHECK_EQ(d->port.kbps, 125);
    h_rx(d, 0x000, "81 0A");
    EXPECT(d, 0x77F, "00");
    CHECK_EQ(d->port.kbps, 500);
}

/* An LSS request counts as an SDO request for the pause an erase ahead
 * waits for (co_store_poll): an LSS master's answers wait for no erase. */
static void test_lss_request_delays_the_erase_ahead(void)
{
    boot(&jd2xxx);
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00"); /* slot 0 the older */
    unsigned n = d->port.prepares;
    h_advance(d, CO_STORE_QUIET_US - 1000u);
    h_rx(d, 0x7E5, "5E 00 00 00 00 00 00 00"); /* inquire node-ID: not answered in waiting */
    EXPECT_NONE(d);
    uint32_t asked = d->now;
    h_advance(d, CO_STORE_QUIET_US - 1000u);
    CHECK_EQ(d->port.prepares, n);
    h_advance(d, 2000u);
    CHECK(d->port.prepares > n);
    CHECK_EQ(d->port.prepared_at - asked, CO_STORE_QUIET_US);
}

/* A request that names no object is aborted with 0000h sub 00h when no
 * transfer is in progress (CiA 301), not with its data bytes read as an
 * index (these once came back as "2211h sub 33"). */
static void test_stray_sdo_aborts_name_no_object(void)
{
    boot(&jd2xxx);
    SDO(d, "E0 11 22 33 44 55 66 77", "80 00 00 00 01 00 04 05"); /* reserved */
    SDO(d, "00 11 22 33 44 55 66 77", "80 00 00 00 01 00 04 05"); /* download segment */
    SDO(d, "61 11 22 33 44 55 66 77", "80 00 00 00 01 00 04 05"); /* upload segment */
    SDO(d, "A1 11 22 33 44 55 66 77", "80 00 00 00 01 00 04 05"); /* block upload end */
}

/* 3005h = 1 starts the node on its own right after every
 * boot-up (power-on after a save, and a reset communication); 0 leaves it
 * pre-operational. */
static void test_autostart(void)
{
    boot(&jd2xxx);
    SDO(d, "22 05 30 00 01 00 00 00", "60 05 30 00 00 00 00 00");
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP); /* at the next boot */
    SDO(d, "22 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    h_power_cycle(d);
    EXPECT(d, 0x70A, "00");
    CHECK_EQ(d->node->nmt.state, CO_NMT_OPERATIONAL);
    SDO(d, "22 05 30 00 00 00 00 00", "60 05 30 00 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x000, "82 0A");
    EXPECT(d, 0x70A, "00");
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
}

/* CiA 305 bit-timing indices (0 = 1000 ... 4 = 125, 6 = 50, 7 = 20
 * kbit/s) stored by LSS as the 3001h codes (0 = 20 ... 7 = 1000 kbit/s). */
static void test_lss_bit_timing_codes(void)
{
    static const uint8_t code[8] = {7, 6, 5, 4, 3, 0xFF, 1, 0};
    boot(&jd2xxx);
    h_rx(d, 0x7E5, "04 01 00 00 00 00 00 00");
    for (uint8_t i = 0; i < 8u; i++) {
        if (code[i] == 0xFFu) {
            continue;
        }
        co_frame_t f = {.id = 0x7E5, .dlc = 8, .data = {0x13, 0x00, i}};
        h_drain(d);
        h_rx_frame(d, &f);
        EXPECT(d, 0x7E4, "13 00 00 00 00 00 00 00");
        h_rx(d, 0x7E5, "17 00 00 00 00 00 00 00");
        EXPECT(d, 0x7E4, "17 00 00 00 00 00 00 00");
        CHECK_EQ(h_read(d, 0x3001, 0), code[i]);
    }
}

/* LSS "store" writes the node-ID (1 and 127, the ends, as 3000h 00h
 * and 7Eh) and the manufacturer parameters (2000h-5FFFh) only: an
 * application parameter changed meanwhile (6000h) is not saved with them. */
static void test_lss_store_node_id_ends(void)
{
    boot(&jd2xxx);
    SDO(d, "22 00 60 00 64 00 00 00", "60 00 60 00 00 00 00 00"); /* 0.1 deg, not saved */
    h_rx(d, 0x7E5, "04 01 00 00 00 00 00 00");
    h_rx(d, 0x7E5, "11 01 00 00 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x7E5, "17 00 00 00 00 00 00 00");
    EXPECT(d, 0x7E4, "17 00 00 00 00 00 00 00");
    CHECK_EQ(h_read(d, 0x3000, 0), 0x00);
    h_rx(d, 0x7E5, "11 7F 00 00 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x7E5, "17 00 00 00 00 00 00 00");
    EXPECT(d, 0x7E4, "17 00 00 00 00 00 00 00");
    CHECK_EQ(h_read(d, 0x3000, 0), 0x7E);
    h_power_cycle(d);
    EXPECT(d, 0x77F, "00");
    h_drain(d);
    h_rx(d, 0x67F, "40 00 60 00 00 00 00 00");
    EXPECT(d, 0x5FF, "4B 00 60 00 0A 00 00 00"); /* 0.01 deg: not stored by LSS */
}

/* 3100h = N averages the last N samples (fewer while the window
 * fills); a new N starts a new window. */
static void test_moving_average_window(void)
{
    static const struct {
        uint16_t n;
        int32_t x;
        int16_t out; /* 6010h, 0.01 deg */
    } v[] = {
        {4, 4000, 400},   {4, 8000, 600},   {4, 12000, 800},  {4, 16000, 1000},
        {4, 20000, 1400}, {4, 24000, 1800}, {2, 28004, 2800}, {2, 32000, 3000},
        {2, 36000, 3400}, {0, -5000, -500}, {1, 7004, 700},   {1, 9000, 900},
    };
    boot(&jd2xxx);
    jd_dev_t *j = h_inst(d);
    for (unsigned i = 0; i < sizeof(v) / sizeof(v[0]); i++) {
        if (i == 0u || v[i].n != v[i - 1u].n) {
            co_frame_t f = {.id = 0x60A, .dlc = 8, .data = {0x2B, 0x00, 0x31, 0x00}};
            co_put_u16(&f.data[4], v[i].n);
            h_drain(d);
            h_rx_frame(d, &f);
            EXPECT(d, 0x58A, "60 00 31 00 00 00 00 00");
        }
        int32_t in[3] = {v[i].x, 0, 25000};
        d->prod->sample(j, in, 0);
        CHECK_EQ((int16_t)h_read(d, 0x6010, 0), v[i].out);
    }
}

/* The moving average on the JD1: two samples average the short way round,
 * from the second sample of a new window on (359 and 1 deg: 0; 1 and 359:
 * 0; 10 and 160: 85); exactly half a turn apart either midpoint is as
 * near, and the device takes the one between the two readings as 0..360
 * values (10 and 190 deg: 100, also 190 and 10). */
static void test_jd1_average_of_two(void)
{
    static const struct {
        int32_t a, b, out; /* 6010h, 0.01 deg */
    } v[] = {{359000, 1000, 0},     {1000, 359000, 0},      {10000, 160000, 8500},
             {160000, 10000, 8500}, {10000, 190000, 10000}, {190000, 10000, 10000}};
    boot(&jd1xxx);
    jd_dev_t *j = h_inst(d);
    for (unsigned i = 0; i < sizeof(v) / sizeof(v[0]); i++) {
        /* A new window each time: a sample with the average off (3100h =
         * 0), then 3100h = 2 and the pair. */
        int32_t a[2] = {v[i].a, 25000};
        int32_t b[2] = {v[i].b, 25000};
        SDO(d, "2B 00 31 00 00 00 00 00", "60 00 31 00 00 00 00 00");
        d->prod->sample(j, a, 0);
        SDO(d, "2B 00 31 00 02 00 00 00", "60 00 31 00 00 00 00 00");
        d->prod->sample(j, a, 0);
        d->prod->sample(j, b, 0);
        long long got = h_read(d, 0x6010, 0);
        if (got != v[i].out) {
            fprintf(stderr, "  %ld and %ld mdeg: %lld, expected %ld\n", (long)v[i].a, (long)v[i].b,
                    got, (long)v[i].out);
            FAIL("the average of two samples is not the short way round");
        }
    }
}

/* The moving average with the JD1 turning one way for many turns under the longest
 * average (250 samples): the output keeps following in 0..360 deg, the
 * mean of the last 250 angles (the averaged values stay within a turn, so
 * nothing grows with the turns). 1 deg a sample, 10 000 samples. */
static void test_jd1_longest_average_many_turns(void)
{
    boot(&jd1xxx);
    jd_dev_t *j = h_inst(d);
    SDO(d, "2B 00 31 00 FA 00 00 00", "60 00 31 00 00 00 00 00");
    unsigned bad = 0;
    for (int32_t k = 1; k <= 10000; k++) {
        int32_t in[2] = {(k % 360) * 1000, 25000};
        d->prod->sample(j, in, 0);
        if (k % 500 == 0) {
            /* The last 250 angles, k - 249 .. k deg: their mean in 0.01 deg. */
            int32_t mean = (int32_t)(((int64_t)k * 1000 - 124500) % 360000);
            if (h_read(d, 0x6010, 0) != mean / 10) {
                bad++;
            }
        }
    }
    CHECK_EQ(bad, 0);
}

/* Beyond +-90 deg the JD2 folds back exactly: 100.006 deg is 79.994
 * (79.99 at 0.01 deg), 100.005 is 79.995 (80.00), and the same negative. */
static void test_jd2_fold_is_exact(void)
{
    boot(&jd2xxx);
    tilt(100006, -100006);
    CHECK_EQ((int16_t)h_read(d, 0x6010, 0), 7999);
    CHECK_EQ((int16_t)h_read(d, 0x6020, 0), -7999);
    tilt(100005, -100005); /* 79.995: 80.00 */
    CHECK_EQ((int16_t)h_read(d, 0x6010, 0), 8000);
    CHECK_EQ((int16_t)h_read(d, 0x6020, 0), -8000);
    /* From just beyond: 90.001 folds to 89.999, seen in the average of two
     * samples with 0.009 deg: 45.004, 45.00 at 0.01 deg. */
    SDO(d, "2B 00 31 00 02 00 00 00", "60 00 31 00 00 00 00 00");
    jd_dev_t *j = h_inst(d);
    int32_t a[3] = {90001, -90001, 25000};
    int32_t b[3] = {9, -9, 25000};
    d->prod->sample(j, a, 0);
    d->prod->sample(j, b, 0);
    CHECK_EQ((int16_t)h_read(d, 0x6010, 0), 4500);
    CHECK_EQ((int16_t)h_read(d, 0x6020, 0), -4500);
}

/* Transmission type 254 without an event timer sends a TPDO when its
 * data changed, both TPDOs, and nothing while the data stay the same. */
static void test_change_of_state_both_tpdos(void)
{
    boot(&jd2xxx);
    SDO(d, "2B 00 22 00 00 00 00 00", "60 00 22 00 00 00 00 00"); /* no timer */
    SDO(d, "22 00 18 02 FE 00 00 00", "60 00 18 02 00 00 00 00");
    SDO(d, "22 01 18 02 FE 00 00 00", "60 01 18 02 00 00 00 00");
    h_rx(d, 0x000, "01 0A");
    h_advance(d, 100000);
    h_drain(d);
    h_advance(d, 100000);
    EXPECT_NONE(d);
    tilt(5000, -3000);
    unsigned n1 = 0;
    unsigned n2 = 0;
    for (const co_frame_t *f = h_next(d); f != NULL; f = h_next(d)) {
        n1 += f->id == 0x18A;
        n2 += f->id == 0x28A;
    }
    CHECK(n1 >= 1u);
    CHECK(n2 >= 1u);
}

/* The TPDOs' factory settings (manual, sections 8.9.1 and 8.9.2): COB-IDs 180h and
 * 280h + node-ID, TPDO1 inhibit 0,
 * TPDO2 inhibit 1 as printed; JD2 maps both slopes into each TPDO, the JD1
 * its one slope (the second entry names 6020h, unused). */
static void test_tpdo_defaults(void)
{
    static const struct {
        uint16_t index;
        uint8_t sub;
        long long jd2, jd1;
    } v[] = {
        {0x1800, 1, 0x18A, 0x18A},
        {0x1801, 1, 0x28A, 0x28A},
        {0x1800, 3, 0, 0},
        {0x1801, 3, 1, 1},
        {0x1A00, 0, 2, 1},
        {0x1A01, 0, 2, 1},
        {0x1A00, 1, 0x60100010, 0x60100010},
        {0x1A01, 1, 0x60100010, 0x60100010},
        {0x1A00, 2, 0x60200010, 0x60200010},
        {0x1A01, 2, 0x60200010, 0x60200010},
    };
    const product_t *const p[2] = {&jd2xxx, &jd1xxx};
    for (unsigned k = 0; k < 2u; k++) {
        boot(p[k]);
        for (unsigned i = 0; i < sizeof(v) / sizeof(v[0]); i++) {
            long long want = k == 0u ? v[i].jd2 : v[i].jd1;
            long long got = h_read(d, v[i].index, v[i].sub);
            if (got != want) {
                fprintf(stderr, "  %s %04Xh:%u = %lld, expected %lld\n", p[k]->id,
                        (unsigned)v[i].index, (unsigned)v[i].sub, got, want);
                FAIL("a TPDO default differs");
            }
        }
    }
}

/* The 16-bit slope is clamped to INTEGER16 only; the 32-bit one
 * carries the same sum unclamped. A differential offset beyond +-90 deg is
 * refused (6014h/6114h, 0x06090030), so only a stored offset reaches
 * the clamp: written into the product's RAM here. */
static void test_jd2_slope_limits(void)
{
    boot(&jd2xxx);
    jd_dev_t *j = h_inst(d);
    tilt(90000, -90000);
    SDO(d, "22 11 60 00 02 00 00 00", "60 11 60 00 00 00 00 00");
    SDO(d, "2B 14 60 00 30 75 00 00", "80 14 60 00 30 00 09 06"); /* +300.00 deg */
    SDO(d, "2B 14 60 00 28 23 00 00", "60 14 60 00 00 00 00 00"); /* +90.00 deg */
    j->para.off16[0] = 30000;
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 FF 7F 00 00"); /* 48000 -> 32767 */
    SDO(d, "22 21 60 00 02 00 00 00", "60 21 60 00 00 00 00 00");
    SDO(d, "2B 24 60 00 D0 8A 00 00", "80 24 60 00 30 00 09 06"); /* -300.00 deg */
    SDO(d, "2B 24 60 00 D8 DC 00 00", "60 24 60 00 00 00 00 00"); /* -90.00 deg */
    j->para.off16[1] = -30000;
    SDO(d, "40 20 60 00 00 00 00 00", "4B 20 60 00 00 80 00 00"); /* -48000 -> -32768 */
    SDO(d, "22 11 61 00 02 00 00 00", "60 11 61 00 00 00 00 00");
    SDO(d, "23 14 61 00 28 23 00 00", "60 14 61 00 00 00 00 00");
    j->para.off32[0] = 21000;
    SDO(d, "40 10 61 00 00 00 00 00", "43 10 61 00 58 98 00 00"); /* 39000 */
}

/* Beyond -90 deg the output folds back too; angles wrap first. */
static void test_jd2_negative_fold(void)
{
    boot(&jd2xxx);
    tilt(-120000, -200000);
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 90 E8 00 00"); /* -60.00 */
    SDO(d, "40 20 60 00 00 00 00 00", "4B 20 60 00 D0 07 00 00"); /* -200 = 160: 20.00 */
}

/* 3411h, 0.1 degC, negative as two's complement. */
static void test_temperature(void)
{
    boot(&jd2xxx);
    d->truth[2] = 23400;
    h_advance(d, 5000);
    SDO(d, "40 11 34 00 00 00 00 00", "4B 11 34 00 EA 00 00 00"); /* 23.4 */
    d->truth[2] = -5000;
    h_advance(d, 5000);
    SDO(d, "40 11 34 00 00 00 00 00", "4B 11 34 00 CE FF 00 00"); /* -5.0 */
}

/* The JD1's moving average crosses 0/360 deg the short way,
 * in both directions: every output on the way is within the window of the
 * inputs averaged (359..1 deg), never a value across the circle. */
static void test_jd1_moving_average_across_zero(void)
{
    boot(&jd1xxx);
    SDO(d, "22 00 31 00 04 00 00 00", "60 00 31 00 00 00 00 00"); /* 4 samples */
    d->truth[0] = 359000;
    h_advance(d, 40000);
    CHECK_EQ(h_read(d, 0x6010, 0), 35900);
    unsigned bad = 0;
    for (int round = 0; round < 3; round++) {
        d->truth[0] = (round % 2 == 0) ? 1000 : 359000;
        for (int s = 0; s < 8; s++) {
            h_advance(d, 5000);
            long long v = h_read(d, 0x6010, 0);
            bool near_zero = v >= 35900 || v <= 100;
            if (!near_zero) {
                bad++;
                fprintf(stderr, "round %d sample %d: 6010h = %lld\n", round, s, v);
            }
        }
        CHECK_EQ(h_read(d, 0x6010, 0), (round % 2 == 0) ? 100 : 35900);
    }
    CHECK_EQ(bad, 0);
}

/* Green on in pre-operational, flashing in operational (the manual's LED
 * table, section 7); red wins
 * (single flash: warning level, double: guard event, flashes: corrupt
 * stored parameters) and then green is off. */
static void test_leds(void)
{
    boot(&jd2xxx);
    co_led_pattern_t g;
    co_led_pattern_t r;
    co_node_led_patterns(d->node, &g, &r);
    CHECK(g == CO_LED_ON && r == CO_LED_OFF);
    h_rx(d, 0x000, "01 0A");
    co_node_led_patterns(d->node, &g, &r);
    CHECK(g == CO_LED_BLINK && r == CO_LED_OFF);
    co_node_set_can_state(d->node, CO_CAN_WARNING);
    co_node_led_patterns(d->node, &g, &r);
    CHECK(g == CO_LED_OFF && r == CO_LED_FLASH1);
    co_node_set_can_state(d->node, CO_CAN_ACTIVE);
    /* A stored parameter set with a bad CRC: defaults, red flashing. */
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    for (unsigned i = 0; i < 2u * CO_STORE_SLOT; i++) {
        if (d->port.nvm[i] != 0xFFu) {
            d->port.nvm[i + 40u] ^= 0x01u; /* a data byte of the first record */
            break;
        }
    }
    h_power_cycle(d);
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_CORRUPT);
    co_node_led_patterns(d->node, &g, &r);
    CHECK(g == CO_LED_OFF && r == CO_LED_BLINK);
}

/* LSS "activate bit timing" (CiA 305): the configured rate reaches the
 * board after the switch delay, not before; no configured rate, nothing;
 * a reset node then applies the stored code again. */
static void test_lss_activate_bit_timing(void)
{
    boot(&jd2xxx);
    CHECK_EQ(d->port.kbps, 125);
    unsigned calls = d->port.bitrate_calls;
    h_rx(d, 0x7E5, "04 01 00 00 00 00 00 00");
    h_rx(d, 0x7E5, "15 0A 00 00 00 00 00 00"); /* nothing configured yet */
    h_advance(d, 20000);
    CHECK_EQ(d->port.bitrate_calls, calls);
    h_rx(d, 0x7E5, "13 00 02 00 00 00 00 00"); /* index 2: 500 kbit/s */
    EXPECT(d, 0x7E4, "13 00 00 00 00 00 00 00");
    h_rx(d, 0x7E5, "15 E8 03 00 00 00 00 00"); /* after 1000 ms */
    h_advance(d, 999000);
    CHECK_EQ(d->port.kbps, 125);
    CHECK_EQ(d->port.bitrate_calls, calls);
    h_advance(d, 2000);
    CHECK_EQ(d->port.kbps, 500);
    CHECK_EQ(d->port.bitrate_calls, calls + 1u);
    h_rx(d, 0x7E5, "04 00 00 00 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x000, "82 0A"); /* reset communication: the activated rate holds */
    EXPECT(d, 0x70A, "00");
    CHECK_EQ(d->port.kbps, 500);
    CHECK_EQ(d->port.bitrate_calls, calls + 1u);
    h_rx(d, 0x000, "81 0A"); /* not stored: reset node goes back to 125 k */
    EXPECT(d, 0x70A, "00");
    CHECK_EQ(d->port.kbps, 125);
    CHECK_EQ(d->port.bitrate_calls, calls + 2u);
}

/* LSS "store" writes 3000h/3001h: an unconfigured node-ID (0xFF)
 * and no bit timing leave them as they are; an EEPROM that refuses the
 * write answers error 2. */
static void test_lss_store_edges(void)
{
    boot(&jd2xxx);
    h_rx(d, 0x7E5, "04 01 00 00 00 00 00 00");
    h_rx(d, 0x7E5, "11 FF 00 00 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x7E5, "17 00 00 00 00 00 00 00");
    EXPECT(d, 0x7E4, "17 00 00 00 00 00 00 00");
    SDO(d, "40 00 30 00 00 00 00 00", "4F 00 30 00 09 00 00 00"); /* still node 10 */
    SDO(d, "40 01 30 00 00 00 00 00", "4F 01 30 00 03 00 00 00"); /* still 125 k */
    h_rx(d, 0x7E5, "11 0B 00 00 00 00 00 00");
    d->port.cut_after = 0;
    h_drain(d);
    h_rx(d, 0x7E5, "17 00 00 00 00 00 00 00");
    EXPECT(d, 0x7E4, "17 02 00 00 00 00 00 00");
    d->port.cut_after = -1;
    h_power_cycle(d);
    EXPECT(d, 0x70A, "00");
    /* 2300h "save with reset" that cannot save: abort, no reset. */
    d->port.cut_after = 0;
    h_drain(d);
    h_rx(d, 0x60A, "23 00 23 00 55 AA AA 55");
    const co_frame_t *f = h_next(d);
    CHECK(f != NULL && f->id == 0x58A && f->data[0] == 0x80u);
    h_advance(d, 10000);
    EXPECT_NONE(d); /* no boot-up */
}

/* LSS stores across power cycles: after several stores and a restart the
 * next store is still the newest record, and the write-cycle count (what a
 * product's write limit is judged by) read back at start covers the LSS
 * class too (tools/mutate's survivor: the per-class loop of co_store_init
 * stopping before the LSS class). */
static void test_lss_stores_across_power_cycles(void)
{
    boot(&jd2xxx);
    h_rx(d, 0x7E5, "04 01 00 00 00 00 00 00");
    static const char *const ids[] = {"11 0B 00 00 00 00 00 00", "11 0C 00 00 00 00 00 00",
                                      "11 0D 00 00 00 00 00 00"};
    for (unsigned k = 0; k < 3u; k++) {
        h_rx(d, 0x7E5, ids[k]);
        h_drain(d);
        h_rx(d, 0x7E5, "17 00 00 00 00 00 00 00");
        EXPECT(d, 0x7E4, "17 00 00 00 00 00 00 00");
    }
    h_power_cycle(d);
    EXPECT(d, 0x70D, "00");
    CHECK_EQ(d->node->store.writes, 3); /* every save counted, LSS ones too */
    h_rx(d, 0x7E5, "04 01 00 00 00 00 00 00");
    h_rx(d, 0x7E5, "11 0E 00 00 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x7E5, "17 00 00 00 00 00 00 00");
    EXPECT(d, 0x7E4, "17 00 00 00 00 00 00 00");
    h_power_cycle(d);
    EXPECT(d, 0x70E, "00");
    h_power_cycle(d);
    EXPECT(d, 0x70E, "00");
    CHECK_EQ(d->node->store.writes, 4);
}

/* sin(deg) for 0..90 degrees without libm (the qemu builds link none):
 * its Taylor series to x^21, far below 1e-9 on a quarter turn. */
static double sin_deg(int deg)
{
    double x = (double)deg * 3.14159265358979323846 / 180.0;
    double term = x;
    double sum = x;
    for (int k = 1; k <= 10; k++) {
        term = -term * x * x / (double)((2 * k) * (2 * k + 1));
        sum += term;
    }
    return sum;
}

/* The accelerations (mg) at whole degrees are 1000 x sin and cos, rounded,
 * both signs, on both axes of the JD2 and the JD1's two (tools/mutate's
 * survivors: any entry of the sine table one off passed every test). */
static void test_accel_sine_table(void)
{
    boot(&jd2xxx);
    jd_dev_t *j = h_inst(d);
    for (int deg = 0; deg <= 90; deg++) {
        double s = sin_deg(deg) * 1000.0 + 0.5;
        int32_t want = (int32_t)s;
        int32_t v[3] = {deg * 1000, -deg * 1000, 25000};
        d->prod->sample(j, v, 0);
        CHECK_EQ(j->accel[0], want);
        CHECK_EQ(j->accel[1], -want);
        int32_t c = (int32_t)(sin_deg(90 - deg) * 1000.0 + 0.5);
        CHECK_EQ(j->accel[2], c * c / 1000);
    }
    boot(&jd1xxx);
    j = h_inst(d);
    for (int deg = 0; deg <= 90; deg++) {
        int32_t want = (int32_t)(sin_deg(deg) * 1000.0 + 0.5);
        int32_t v[2] = {-deg * 1000, 25000};
        d->prod->sample(j, v, 0);
        CHECK_EQ(j->accel[0], -want);
        CHECK_EQ(j->accel[1], -(int32_t)(sin_deg(90 - deg) * 1000.0 + 0.5));
    }
}

/* Between whole degrees the accelerations are linear between the
 * neighbouring whole degrees' values (truncated to whole mg), both signs,
 * and symmetric about 90 deg: sin(180 - a) = sin a. */
static void test_accel_between_degrees(void)
{
    boot(&jd2xxx);
    jd_dev_t *j = h_inst(d);
    static const int32_t fracs[] = {1, 250, 500, 950, 999};
    int32_t lo = 0;
    for (int deg = 0; deg < 90; deg++) {
        int32_t v[3] = {(deg + 1) * 1000, 0, 25000};
        d->prod->sample(j, v, 0);
        int32_t hi = j->accel[0];
        for (unsigned k = 0; k < sizeof(fracs) / sizeof(fracs[0]); k++) {
            int32_t a = deg * 1000 + fracs[k];
            int32_t want = lo + (hi - lo) * fracs[k] / 1000;
            int32_t in[4][3] = {
                {a, 0, 25000}, {-a, 0, 25000}, {180000 - a, 0, 25000}, {a - 180000, 0, 25000}};
            int32_t sign[4] = {1, -1, 1, -1};
            for (unsigned m = 0; m < 4u; m++) {
                d->prod->sample(j, in[m], 0);
                if (j->accel[0] != sign[m] * want) {
                    fprintf(stderr, "  x = %ld mdeg: %d mg, expected %ld\n", (long)in[m][0],
                            j->accel[0], (long)(sign[m] * want));
                    FAIL("acceleration not linear between whole degrees");
                }
            }
        }
        lo = hi;
    }
}

/* The accelerations across the tilt are the cosines: the JD1's Y
 * (3404h) is -cos z and the JD2's Z (3405h) cos x cos y, each the sine
 * of 90 deg - a, also between whole degrees; the JD1 lies flat: Z 0. */
static void test_accel_cosines(void)
{
    static const int32_t fracs[] = {0, 1, 112, 500, 889, 999};
    boot(&jd1xxx);
    jd_dev_t *j = h_inst(d);
    unsigned bad = 0;
    for (int deg = 0; deg < 90; deg++) {
        for (unsigned k = 0; k < sizeof(fracs) / sizeof(fracs[0]); k++) {
            int32_t a = deg * 1000 + fracs[k];
            int32_t s[2] = {90000 - a, 25000};
            d->prod->sample(j, s, 0);
            int16_t sine = j->accel[0];
            int32_t c[2] = {a, 25000};
            d->prod->sample(j, c, 0);
            bad += j->accel[1] != -sine || j->accel[2] != 0;
        }
    }
    CHECK_EQ(bad, 0);
    CHECK_EQ(h_read(d, 0x3405, 0), 0);
    boot(&jd2xxx);
    j = h_inst(d);
    bad = 0;
    for (int deg = 0; deg < 90; deg++) {
        for (unsigned k = 0; k < sizeof(fracs) / sizeof(fracs[0]); k++) {
            int32_t a = deg * 1000 + fracs[k];
            int32_t s[3] = {90000 - a, 0, 25000};
            d->prod->sample(j, s, 0);
            int16_t sine = j->accel[0];
            int32_t cx[3] = {a, 0, 25000};
            d->prod->sample(j, cx, 0);
            bad += j->accel[2] != sine;
            int32_t cy[3] = {0, a, 25000};
            d->prod->sample(j, cy, 0);
            bad += j->accel[2] != sine;
        }
    }
    CHECK_EQ(bad, 0);
}

int main(void)
{
    RUN(test_lss_activate_bit_timing);
    RUN(test_jd1_preset_and_wrap);
    RUN(test_jd2_lateral_preset_inverted);
    RUN(test_jd2_preset_offset_survives_power_cycle);
    RUN(test_jd2_resolution_rescales_everything);
    RUN(test_jd2_cyclic_time_while_operational);
    RUN(test_gyro_rates);
    RUN(test_node_number_at_reset_node_only);
    RUN(test_autostart);
    RUN(test_lss_bit_timing_codes);
    RUN(test_lss_store_node_id_ends);
    RUN(test_moving_average_window);
    RUN(test_jd2_fold_is_exact);
    RUN(test_jd1_average_of_two);
    RUN(test_jd1_longest_average_many_turns);
    RUN(test_change_of_state_both_tpdos);
    RUN(test_tpdo_defaults);
    RUN(test_jd2_slope_limits);
    RUN(test_jd2_negative_fold);
    RUN(test_temperature);
    RUN(test_jd1_moving_average_across_zero);
    RUN(test_leds);
    RUN(test_accel_sine_table);
    RUN(test_accel_between_degrees);
    RUN(test_accel_cosines);
    RUN(test_lss_stores_across_power_cycles);
    RUN(test_lss_store_edges);
    RUN(test_lss_request_delays_the_erase_ahead);
    RUN(test_stray_sdo_aborts_name_no_object);
    return h_finish();
}
