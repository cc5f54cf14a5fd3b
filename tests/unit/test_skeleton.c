/*
 * test_skeleton.c - the template family (od/skeleton): what every product
 * of this stack must do, as a new family's first test. Runs on the host,
 * with the family's fixed config and table sizes (unit.fixed.skel_cfg.*),
 * and on the emulated Cortex-M0 (qemu.*), like every family's tests.
 */
#include "harness.h"
#include "skeleton.h"

static h_dev_t dev;
static h_dev_t *const d = &dev;

/* Power-on: boot-up on 0x700 + the default node-ID, pre-operational. */
static void test_boot_and_identity(void)
{
    h_boot(d, &skel_incl, false);
    EXPECT(d, 0x720, "00");
    CHECK_EQ(co_node_nmt_state(d->node), CO_NMT_PREOP);
    CHECK_EQ(d->port.kbps, 250);                       /* the default bit-rate code 3 */
    CHECK_EQ(co_node_poll(d->node, d->now), CO_NEVER); /* nothing due: no poll asked for */
    SDO(d, "40 00 10 00 00 00 00 00", "43 00 10 00 9A 01 00 00"); /* device type: CiA 410 */
    SDO(d, "40 18 10 02 00 00 00 00", "43 18 10 02 01 00 00 00"); /* product code */
    SDO(d, "40 99 10 00 00 00 00 00", "80 99 10 00 00 00 02 06"); /* no such object */
    SDO(d, "2B 00 10 00 01 00 00 00", "80 00 10 00 02 00 01 06"); /* read-only */
    SDO(d, "2F 00 60 00 07 00 00 00", "80 00 60 00 13 00 07 06"); /* 0x6000 is 16 bits: too short */
    SDO(d, "2B 00 60 00 07 00 00 00", "80 00 60 00 30 00 09 06"); /* not a CiA 410 resolution */
}

/* The slope in 0.01 deg on TPDO1 (type 254: at each change) once operational. */
static void test_slope_on_tpdo(void)
{
    h_boot(d, &skel_incl, false);
    d->truth[0] = -12340; /* -12.34 deg */
    h_advance(d, 20000);
    h_drain(d);
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 2E FB 00 00"); /* -1234 */
    h_rx(d, 0x000, "01 20");
    h_advance(d, 20000);
    EXPECT_ID(d, 0x1A0, "2E FB");
    /* Preset 0 with scaling on: the output is 0 from now on. */
    SDO(d, "2F 11 60 00 02 00 00 00", "60 11 60 00 00 00 00 00");
    SDO(d, "2B 12 60 00 00 00 00 00", "60 12 60 00 00 00 00 00");
    h_drain(d);
    h_advance(d, 20000);
    EXPECT_ID(d, 0x1A0, "00 00");
}

/* Type 254 without an event timer: a TPDO when the node becomes
 * operational and at each change of the slope, none for a sample of the
 * same value; back in pre-operational nothing, and the next start sends
 * again. */
static void test_event_on_change(void)
{
    h_boot(d, &skel_incl, false);
    d->truth[0] = 5000;
    h_advance(d, 20000);
    h_drain(d);
    h_rx(d, 0x000, "01 20");
    h_advance(d, 20000);
    EXPECT_ID(d, 0x1A0, "F4 01"); /* 500 = 5.00 deg */
    h_advance(d, 100000);         /* 20 samples of one value */
    EXPECT_NONE(d);
    d->truth[0] = 5010;
    h_advance(d, 20000);
    EXPECT_ID(d, 0x1A0, "F5 01");
    EXPECT_NONE(d);
    h_rx(d, 0x000, "80 20"); /* pre-operational */
    h_advance(d, 20000);
    d->truth[0] = 6000;
    h_advance(d, 20000);
    EXPECT_NONE(d);
    h_rx(d, 0x000, "01 20");
    h_advance(d, 20000);
    EXPECT_ID(d, 0x1A0, "58 02");
    EXPECT_NONE(d);
}

/* A fault raises its EMCY and the error register, and the slope holds
 * its last value; clearing it resets both, and the slope follows again. */
static void test_fault_emcy(void)
{
    h_boot(d, &skel_incl, false);
    h_drain(d);
    d->truth[0] = 10000;
    h_advance(d, 20000);
    CHECK_EQ(h_read(d, 0x6010, 0), 1000);
    d->fault = SKEL_FAULT_SENSOR;
    d->truth[0] = 20000;
    h_advance(d, 20000);
    EXPECT_ID(d, 0xA0, "00 50 01 00 00 00 00 00");
    SDO(d, "40 01 10 00 00 00 00 00", "4F 01 10 00 01 00 00 00");
    CHECK_EQ(h_read(d, 0x6010, 0), 1000); /* no valid reading: the output holds */
    d->fault = 0;
    h_advance(d, 20000);
    EXPECT_ID(d, 0xA0, "00 00 00 00 00 00 00 00");
    CHECK_EQ(h_read(d, 0x6010, 0), 2000);
}

/* 0x1010 "save" keeps a parameter across a power cycle; 0x1011 "load"
 * brings the defaults back at the next one. */
static void test_store(void)
{
    h_boot(d, &skel_incl, false);
    SDO(d, "2B 17 10 00 F4 01 00 00", "60 17 10 00 00 00 00 00"); /* heartbeat 500 ms */
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00"); /* "save" */
    h_power_cycle(d);
    CHECK_EQ(h_read(d, 0x1017, 0), 500);
    SDO(d, "23 11 10 01 6C 6F 61 64", "60 11 10 01 00 00 00 00"); /* "load" */
    CHECK_EQ(h_read(d, 0x1017, 0), 500);                          /* until the next reset */
    h_power_cycle(d);
    CHECK_EQ(h_read(d, 0x1017, 0), 0);
}

/* The dictionary as its table gives it: every object is where the profile
 * puts it (CiA 301 communication objects, CiA 410 slope objects) and reads
 * its default after power-on; sub-indices beyond an object's are absent. */
static void test_dictionary_defaults(void)
{
    static const struct {
        uint16_t index;
        uint8_t sub;
        long long value; /* -1: absent */
    } objs[] = {
        {0x1000, 0, 0x19A},      {0x1001, 0, 0},   {0x1010, 0, 1},          {0x1010, 1, 1},
        {0x1010, 2, -1},         {0x1011, 0, 1},   {0x1011, 1, 1},          {0x1011, 2, -1},
        {0x1017, 0, 0},          {0x1018, 0, 4},   {0x1018, 1, 0},          {0x1018, 2, 1},
        {0x1018, 3, 0x00010000}, {0x1018, 4, 0},   {0x1018, 5, -1},         {0x1800, 0, 5},
        {0x1800, 1, 0x1A0},      {0x1800, 2, 254}, {0x1800, 3, -1},         {0x1800, 4, -1},
        {0x1800, 5, 0},          {0x1A00, 0, 1},   {0x1A00, 1, 0x60100010}, {0x1A00, 2, -1},
        {0x6000, 0, 10},         {0x6010, 0, 0},   {0x6011, 0, 0},          {0x6012, 0, 0},
        {0x6013, 0, 0},          {0x6014, 0, 0},   {0x6015, 0, -1},
    };
    h_boot(d, &skel_incl, false);
    for (unsigned i = 0; i < sizeof(objs) / sizeof(objs[0]); i++) {
        long long v = h_read(d, objs[i].index, objs[i].sub);
        if (v != objs[i].value) {
            fprintf(stderr, "  %04Xh:%u reads %lld, expected %lld\n", (unsigned)objs[i].index,
                    (unsigned)objs[i].sub, v, objs[i].value);
            FAIL("an object differs from the table");
        }
    }
    /* The simulated input starts level: 0 also at the finest resolution. */
    SDO(d, "2F 11 60 00 02 00 00 00", "60 11 60 00 00 00 00 00");
    SDO(d, "2B 00 60 00 01 00 00 00", "60 00 60 00 00 00 00 00");
    h_advance(d, 20000);
    CHECK_EQ(h_read(d, 0x6010, 0), 0);
}

/* The slope's operating parameter takes CiA 410's bits 0 (inversion) and
 * 1 (scaling) only: 0..3, beyond is "value too high". */
static void test_operating_parameter_range(void)
{
    h_boot(d, &skel_incl, false);
    SDO(d, "2F 11 60 00 04 00 00 00", "80 11 60 00 31 00 09 06");
    SDO(d, "2F 11 60 00 03 00 00 00", "60 11 60 00 00 00 00 00");
    SDO(d, "2F 11 60 00 00 00 00 00", "60 11 60 00 00 00 00 00");
}

/* 0x6000 takes CiA 410's resolutions 0.001, 0.01, 0.1 and 1 deg while
 * scaling is on (0x6011 bit 1; else "not in the present device state"); a
 * new one clears the preset's offset, and the slope follows at once and
 * after a saved set comes back at power-on. */
static void test_resolution(void)
{
    h_boot(d, &skel_incl, false);
    d->truth[0] = 12345;
    h_advance(d, 20000);
    SDO(d, "2B 00 60 00 64 00 00 00", "80 00 60 00 22 00 00 08"); /* scaling off */
    SDO(d, "2F 11 60 00 02 00 00 00", "60 11 60 00 00 00 00 00");
    SDO(d, "2B 12 60 00 00 00 00 00", "60 12 60 00 00 00 00 00"); /* preset 0 */
    CHECK_EQ((int16_t)h_read(d, 0x6013, 0), -1235);               /* 0 - 12.345 deg in 0.01 */
    static const char *const refused[] = {"2B 00 60 00 00 00 00 00", "2B 00 60 00 02 00 00 00",
                                          "2B 00 60 00 09 00 00 00", "2B 00 60 00 0B 00 00 00",
                                          "2B 00 60 00 65 00 00 00", "2B 00 60 00 E9 03 00 00"};
    for (unsigned i = 0; i < sizeof(refused) / sizeof(refused[0]); i++) {
        h_rx(d, 0x620, refused[i]);
        const co_frame_t *f = h_next(d);
        CHECK(f != NULL && f->id == 0x5A0 && co_get_u32(&f->data[4]) == 0x06090030u);
    }
    SDO(d, "2B 00 60 00 01 00 00 00", "60 00 60 00 00 00 00 00"); /* 0.001 deg */
    CHECK_EQ(h_read(d, 0x6013, 0), 0);
    CHECK_EQ(h_read(d, 0x6010, 0), 12345);
    SDO(d, "2B 00 60 00 E8 03 00 00", "60 00 60 00 00 00 00 00"); /* 1 deg */
    CHECK_EQ(h_read(d, 0x6010, 0), 12);
    SDO(d, "2B 00 60 00 0A 00 00 00", "60 00 60 00 00 00 00 00"); /* 0.01 deg */
    CHECK_EQ(h_read(d, 0x6010, 0), 1235);
    SDO(d, "2B 00 60 00 64 00 00 00", "60 00 60 00 00 00 00 00"); /* 0.1 deg */
    CHECK_EQ(h_read(d, 0x6010, 0), 123);
    SDO(d, "2B 12 60 00 0A 00 00 00", "60 12 60 00 00 00 00 00"); /* preset 1.0 deg */
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    h_power_cycle(d);
    h_advance(d, 20000);
    CHECK_EQ(h_read(d, 0x6000, 0), 100);
    CHECK_EQ(h_read(d, 0x6010, 0), 10);
    CHECK_EQ((int16_t)h_read(d, 0x6013, 0), -113);
    /* Scaling is asked of a new resolution only: saved with scaling off,
     * the resolution comes back all the same. */
    SDO(d, "2F 11 60 00 00 00 00 00", "60 11 60 00 00 00 00 00");
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    h_power_cycle(d);
    h_advance(d, 20000);
    CHECK_EQ(h_read(d, 0x6000, 0), 100);
    CHECK_EQ(h_read(d, 0x6010, 0), 123);
}

/* A stored set that fails its check at power-on: the table's defaults,
 * and CiA 301's EMCY 6300h "data set" with the generic error bit, until a
 * good save. */
static void test_corrupt_store_emcy(void)
{
    h_boot(d, &skel_incl, false);
    SDO(d, "2B 17 10 00 F4 01 00 00", "60 17 10 00 00 00 00 00");
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    for (unsigned i = 0; i < 2u * CO_STORE_SLOT; i++) {
        if (d->port.nvm[i] != 0xFFu) {
            d->port.nvm[i + CO_STORE_HDR] ^= 0x01u; /* a data byte of the record */
            break;
        }
    }
    h_power_cycle(d);
    EXPECT(d, 0x720, "00");
    h_advance(d, 1000);
    EXPECT(d, 0xA0, "00 63 01 00 00 00 00 00");
    CHECK_EQ(h_read(d, 0x1017, 0), 0);
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    h_advance(d, 1000);
    EXPECT_ID(d, 0xA0, "00 00 00 00 00 00 00 00");
}

int main(void)
{
    RUN(test_boot_and_identity);
    RUN(test_slope_on_tpdo);
    RUN(test_event_on_change);
    RUN(test_fault_emcy);
    RUN(test_store);
    RUN(test_dictionary_defaults);
    RUN(test_operating_parameter_range);
    RUN(test_resolution);
    RUN(test_corrupt_store_emcy);
    return h_finish();
}
