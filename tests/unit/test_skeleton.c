/*
 * test_skeleton.c - the template family (od/skeleton): what every product
 * of this stack must do, as a new family's first test. Runs on the host,
 * with the family's fixed config and table sizes (unit.fixed.skel_cfg.*),
 * and on the emulated Cortex-M0 (qemu.*), like every family's tests.
 */
#include "skeleton.h"
#include "harness.h"

static h_dev_t dev;
static h_dev_t *const d = &dev;

/* Power-on: boot-up on 0x700 + the default node-ID, pre-operational. */
static void test_boot_and_identity(void)
{
    h_boot(d, &skel_incl, false);
    EXPECT(d, 0x720, "00");
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
    SDO(d, "40 00 10 00 00 00 00 00", "43 00 10 00 9A 01 00 00"); /* device type: CiA 410 */
    SDO(d, "40 18 10 02 00 00 00 00", "43 18 10 02 01 00 00 00"); /* product code */
    SDO(d, "40 99 10 00 00 00 00 00", "80 99 10 00 00 00 02 06"); /* no such object */
    SDO(d, "2B 00 10 00 01 00 00 00", "80 00 10 00 02 00 01 06"); /* read-only */
    SDO(d, "2F 00 60 00 07 00 00 00", "80 00 60 00 13 00 07 06"); /* 0x6000 is 16 bits: too short */
    SDO(d, "2B 00 60 00 07 00 00 00", "80 00 60 00 30 00 09 06"); /* not a CiA 410 resolution */
}

/* The slope in 0.01 deg on TPDO1 (type 254: every sample) once operational. */
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

/* A fault raises its EMCY and the error register; clearing it resets both. */
static void test_fault_emcy(void)
{
    h_boot(d, &skel_incl, false);
    h_drain(d);
    d->fault = SKEL_FAULT_SENSOR;
    h_advance(d, 20000);
    EXPECT_ID(d, 0xA0, "00 50 01 00 00 00 00 00");
    SDO(d, "40 01 10 00 00 00 00 00", "4F 01 10 00 01 00 00 00");
    d->fault = 0;
    h_advance(d, 20000);
    EXPECT_ID(d, 0xA0, "00 00 00 00 00 00 00 00");
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
    CHECK_EQ(h_read(d, 0x1017, 0), 500); /* until the next reset */
    h_power_cycle(d);
    CHECK_EQ(h_read(d, 0x1017, 0), 0);
}

int main(void)
{
    RUN(test_boot_and_identity);
    RUN(test_slope_on_tpdo);
    RUN(test_fault_emcy);
    RUN(test_store);
    return h_finish();
}
