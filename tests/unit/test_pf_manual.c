/*
 * test_pf_manual.c - every frame example of the P+F INX360D/INY360D manual
 * (V1.., in the order printed) and sequences derived from them here (D1..).
 * Default node-ID 1; the manual's examples use nodes 9, 5 and 1, reached
 * through 0x2000.
 *
 * Abort codes: a value beyond a plain minimum or maximum gets CiA 301's
 * precise "too low" (0x06090032) / "too high" (0x06090031), as for every
 * product of this firmware; other rejected values 0x06090030.
 */
#include "harness.h"
#include "pf.h"

static h_dev_t dev;
static h_dev_t *const d = &dev;

static void boot(const product_t *p)
{
    h_boot(d, p, false);
    EXPECT(d, 0x701, "00");
}

/* Move the node to another ID the manual's way: 0x2000, then reset node. */
static void renumber(uint8_t id)
{
    char req[64];
    char resp[64];
    snprintf(req, sizeof(req), "2F 00 20 00 %02X 00 00 00", id);
    snprintf(resp, sizeof(resp), "60 00 20 00 00 00 00 00");
    SDO(d, req, resp);
    char nmt[16];
    snprintf(nmt, sizeof(nmt), "81 %02X", d->node->node_id);
    h_rx(d, 0x000, nmt);
    EXPECT(d, (uint16_t)(0x700u + id), "00");
}

static void settle(int32_t x, int32_t y)
{
    d->truth[0] = x;
    d->truth[1] = y;
    h_advance(d, 20000); /* no filter: the next sample is the value */
}

static void test_v1_to_v7_boot_and_nmt(void)
{
    boot(&pf_iny360d);
    renumber(9);
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP); /* never operational by itself (6.1) */
    h_power_cycle(d);
    EXPECT(d, 0x709, "00");  /* V1 */
    h_rx(d, 0x000, "01 09"); /* V4 */
    CHECK_EQ(d->node->nmt.state, CO_NMT_OPERATIONAL);
    h_rx(d, 0x000, "80 09"); /* V2 */
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
    h_rx(d, 0x000, "02 09"); /* V3 */
    CHECK_EQ(d->node->nmt.state, CO_NMT_STOPPED);
    h_rx(d, 0x000, "01 00"); /* V7 broadcast */
    CHECK_EQ(d->node->nmt.state, CO_NMT_OPERATIONAL);
    h_drain(d);
    h_rx(d, 0x000, "82 09"); /* V5 */
    EXPECT(d, 0x709, "00");
    h_rx(d, 0x000, "81 09"); /* V6 */
    EXPECT(d, 0x709, "00");
    h_rx(d, 0x000, "01 08"); /* another node */
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
}

static void test_v8_node_id_and_d1_to_d5(void)
{
    boot(&pf_inx360d);
    SDO(d, "2F 00 20 00 0F 00 00 00", "60 00 20 00 00 00 00 00"); /* V8, D1 */
    SDO(d, "40 00 20 00 00 00 00 00", "4F 00 20 00 0F 00 00 00"); /* the stored, pending value */
    h_rx(d, 0x000, "82 01"); /* reset communication keeps the old ID (6.2: "Reset sensor") */
    EXPECT(d, 0x701, "00");
    h_rx(d, 0x000, "81 01"); /* D2 */
    EXPECT(d, 0x70F, "00");  /* D3 */
    SDO(d, "40 00 10 00 00 00 00 00", "43 00 10 00 9A 01 00 00");
    /* D4: 0x80 not adopted ("too high"). */
    SDO(d, "2F 00 20 00 80 00 00 00", "80 00 20 00 31 00 09 06");
    SDO(d, "2F 00 20 00 00 00 00 00", "80 00 20 00 32 00 09 06");
    SDO(d, "40 00 20 00 00 00 00 00", "4F 00 20 00 0F 00 00 00"); /* unchanged */
    h_power_cycle(d);
    EXPECT(d, 0x70F, "00"); /* survived without a save command (6.2) */
    renumber(1);
    SDO(d, "40 00 20 00 00 00 00 00", "4F 00 20 00 01 00 00 00"); /* D5 */
}

static void test_v9_v10_bitrate_d6_d7(void)
{
    boot(&pf_inx360d);
    pf_dev_t *x = (pf_dev_t *)h_inst(d);
    SDO(d, "2F 01 20 00 08 00 00 00", "60 01 20 00 00 00 00 00"); /* V9, D6 */
    SDO(d, "2F 01 20 00 04 00 00 00", "60 01 20 00 00 00 00 00"); /* V10 */
    SDO(d, "2F 01 20 00 02 00 00 00", "60 01 20 00 00 00 00 00");
    SDO(d, "2F 01 20 00 01 00 00 00", "60 01 20 00 00 00 00 00");
    SDO(d, "2F 01 20 00 03 00 00 00", "80 01 20 00 30 00 09 06"); /* D7 */
    SDO(d, "2F 01 20 00 08 00 00 00", "60 01 20 00 00 00 00 00");
    h_rx(d, 0x000, "81 01");
    EXPECT(d, 0x701, "00"); /* D6: boot-up, now at 1 Mbit/s */
    x = (pf_dev_t *)h_inst(d);
    CHECK_EQ(x->lss.bitrate, PF_BR_1M);
    SDO(d, "40 01 20 00 00 00 00 00", "4F 01 20 00 08 00 00 00");
}

static void test_v11_d9_rtr_pdo(void)
{
    boot(&pf_iny360d);
    renumber(5);
    settle(131700, 231200);
    SDO(d, "2F 00 18 02 FD 00 00 00", "60 00 18 02 00 00 00 00"); /* V12, D8 */
    h_rx(d, 0x000, "01 05");
    h_drain(d);
    h_advance(d, 100000);
    EXPECT_NONE(d); /* FDh: nothing without a request */
    co_frame_t rtr = {.id = 0x185, .rtr = true, .dlc = 4};
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x185, "25 05 08 09"); /* V11 / D9: X 131.7, Y 231.2, DLC 4 */
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 25 05 00 00"); /* D11 */
}

static void test_d10_sync_and_v13(void)
{
    boot(&pf_iny360d);
    settle(10000, 20000);
    SDO(d, "2F 00 18 02 03 00 00 00", "60 00 18 02 00 00 00 00");
    h_rx(d, 0x000, "01 01");
    h_drain(d);
    h_rx(d, 0x080, "");
    h_rx(d, 0x080, "");
    EXPECT_NONE(d);
    h_rx(d, 0x080, "");
    EXPECT(d, 0x181, "64 00 C8 00"); /* one TPDO after every 3rd SYNC */
    SDO(d, "2F 00 18 02 F0 00 00 00", "60 00 18 02 00 00 00 00"); /* V13 */
    SDO(d, "2F 00 18 02 FF 00 00 00", "60 00 18 02 00 00 00 00");
    SDO(d, "2F 00 18 02 F5 00 00 00", "80 00 18 02 30 00 09 06"); /* F1..FB */
}

static void test_v14_inhibit_ff_each_calculation(void)
{
    boot(&pf_inx360d);
    /* FFh: a PDO after each calculation (every 5 ms sample), */
    SDO(d, "2F 00 18 02 FF 00 00 00", "60 00 18 02 00 00 00 00");
    h_rx(d, 0x000, "01 01");
    h_drain(d);
    h_advance(d, 100000);
    unsigned n = 0;
    while (h_next(d) != NULL) {
        n++;
    }
    CHECK(n >= 19 && n <= 21);
    /* V14: inhibit 2710h = 1 s (written while valid, as the manual does). */
    SDO(d, "2B 00 18 03 10 27 00 00", "60 00 18 03 00 00 00 00");
    h_drain(d);
    h_advance(d, 3000000);
    n = 0;
    const co_frame_t *f;
    while ((f = h_next(d)) != NULL) {
        n += f->id == 0x181;
    }
    CHECK(n >= 3 && n <= 4); /* one a second */
}

static void test_v17_emcy_and_d27(void)
{
    boot(&pf_iny360d);
    renumber(9);
    h_drain(d);
    d->fault = PF_FAULT_RANGE_X;
    h_advance(d, 10000);
    EXPECT(d, 0x089, "10 50 11 00 00 00 00 00"); /* V17 */
    CHECK_EQ(h_read(d, 0x1001, 0), 0x11);
    co_led_pattern_t run;
    co_led_pattern_t err;
    co_node_led_patterns(d->node, &run, &err);
    CHECK(run == CO_LED_BLINK && err == CO_LED_FLASH1); /* warning: 1x flash */
    d->fault = PF_FAULT_RANGE_X | PF_FAULT_RANGE_Y;
    h_advance(d, 10000);
    EXPECT(d, 0x089, "20 50 11 00 00 00 00 00");
    d->fault = 0;
    h_advance(d, 10000);
    EXPECT(d, 0x089, "00 00 00 00 00 00 00 00"); /* D27: once, when the last clears */
    EXPECT_NONE(d);
    /* Undervoltage: 3100h, register 05h; run off, err on (5.3). */
    d->fault = PF_FAULT_UNDERVOLTAGE;
    h_advance(d, 10000);
    EXPECT(d, 0x089, "00 31 05 00 00 00 00 00");
    co_node_led_patterns(d->node, &run, &err);
    CHECK(run == CO_LED_OFF && err == CO_LED_ON);
    /* No EMCY in stopped; reported once allowed again. */
    d->fault = 0;
    h_rx(d, 0x000, "02 09");
    h_drain(d);
    h_advance(d, 10000);
    EXPECT_NONE(d);
    h_rx(d, 0x000, "80 09");
    h_advance(d, 10000);
    EXPECT(d, 0x089, "00 00 00 00 00 00 00 00");
    /* INX has no Y axis: range-y does nothing there. */
    boot(&pf_inx360d);
    h_drain(d);
    d->fault = PF_FAULT_RANGE_Y;
    h_advance(d, 10000);
    EXPECT_NONE(d);
}

static void test_v18_heartbeat_d21(void)
{
    boot(&pf_inx360d);
    /* A 4-byte write to the 16-bit object (CiA 301; the manual says 32-bit): length too high. */
    SDO(d, "23 17 10 00 E8 03 00 00", "80 17 10 00 12 00 07 06");
    SDO(d, "2B 17 10 00 E8 03 00 00", "60 17 10 00 00 00 00 00"); /* D21 */
    h_drain(d);
    h_advance(d, 1000000);
    EXPECT(d, 0x701, "7F");
    h_rx(d, 0x000, "02 01");
    h_advance(d, 1000000);
    EXPECT(d, 0x701, "04"); /* V18 */
}

static void test_v19_v20_guarding_d22_d24(void)
{
    boot(&pf_inx360d);
    renumber(9);
    co_frame_t rtr = {.id = 0x709, .rtr = true, .dlc = 0};
    h_drain(d);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x709, "7F"); /* D22 */
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x709, "FF");
    h_rx(d, 0x000, "02 09");
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x709, "04"); /* V20: stopped, toggle 0 */
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x709, "84");
    /* D23/D24 on node 1. */
    boot(&pf_inx360d);
    SDO(d, "2B 0C 10 00 64 00 00 00", "60 0C 10 00 00 00 00 00");
    SDO(d, "2F 0D 10 00 03 00 00 00", "60 0D 10 00 00 00 00 00");
    SDO(d, "2F 00 18 02 FD 00 00 00", "60 00 18 02 00 00 00 00"); /* quiet PDO */
    h_rx(d, 0x000, "01 01");
    rtr.id = 0x701;
    h_rx_frame(d, &rtr);
    h_drain(d);
    h_advance(d, 310000);
    EXPECT(d, 0x081,
           "30 81 11 00 00 00 00 00"); /* CiA 301's 8130h, where the manual prints 3081h */
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
    h_rx_frame(d, &rtr);
    EXPECT(d, 0x701, "FF"); /* next guard answer: pre-operational */
}

static void test_v21_to_v24_zero_point_d12_to_d18(void)
{
    boot(&pf_inx360d);
    settle(131700, 0);
    SDO(d, "2F 11 60 00 02 00 00 00", "60 11 60 00 00 00 00 00"); /* V21, D12 */
    SDO(d, "2B 12 60 00 00 00 00 00", "60 12 60 00 00 00 00 00"); /* V23, D12 */
    SDO(d, "40 13 60 00 00 00 00 00", "4B 13 60 00 EB 08 00 00"); /* D13: 2283 */
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 00 00 00 00"); /* D14 */
    SDO(d, "2B 14 60 00 38 FF 00 00", "60 14 60 00 00 00 00 00"); /* V24: -20.0 */
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 48 0D 00 00"); /* D15: 340.0 */
    /* D16: reversed, scaling off: 3600 - 1317 = 2283; 0 stays 0 (not the
     * manual's 360 - x = 360.0, outside its 0..359.9). */
    SDO(d, "2F 11 60 00 01 00 00 00", "60 11 60 00 00 00 00 00"); /* V22 */
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 EB 08 00 00");
    settle(0, 0);
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 00 00 00 00");
    /* D17 / D18 ("too high"). */
    SDO(d, "2B 12 60 00 10 0E 00 00", "80 12 60 00 31 00 09 06");
    SDO(d, "2F 11 60 00 04 00 00 00", "80 11 60 00 31 00 09 06");
    SDO(d, "2B 10 60 00 00 00 00 00", "80 10 60 00 02 00 01 06"); /* D19 */
    SDO(d, "40 20 60 00 00 00 00 00", "80 20 60 00 00 00 02 06"); /* D20: INX */
    SDO(d, "2B 00 60 00 0A 00 00 00", "80 00 60 00 30 00 09 06"); /* 0.1 deg fixed */
    /* Full turn: 359.96 rounds to 3600, which is 0, reversed 0 too. */
    settle(359960, 0);
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 00 00 00 00");
}

/* The P+F stores every write on its own (CiA 301 0x1010 bit 1), behind
 * the answer: the write is answered when taken, with no EEPROM write on
 * the answer's path, and stored once the SDO server has been quiet for
 * CO_STORE_QUIET_US; a burst of writes costs one record. A power cut
 * before that keeps the set stored before, whole. */
static void test_autosave_behind_the_answer(void)
{
    boot(&pf_inx360d);
    unsigned before = d->port.nvm_writes;
    uint32_t saves = d->node->store.writes;
    SDO(d, "2B 17 10 00 F4 01 00 00", "60 17 10 00 00 00 00 00"); /* 500 ms */
    CHECK_EQ(d->port.nvm_writes, before);
    h_advance(d, CO_STORE_QUIET_US - 1000u);
    SDO(d, "2F 11 60 00 02 00 00 00", "60 11 60 00 00 00 00 00"); /* scaling on */
    h_advance(d, CO_STORE_QUIET_US - 1000u);
    CHECK_EQ(d->port.nvm_writes, before); /* the second request restarted the wait */
    h_advance(d, 1000u);
    CHECK(d->port.nvm_writes > before);
    CHECK_EQ(d->node->store.writes, saves + 1u); /* one record for both */
    /* Cut before the pause: the stored set, whole. */
    SDO(d, "2B 17 10 00 84 03 00 00", "60 17 10 00 00 00 00 00"); /* 900 ms */
    h_advance(d, CO_STORE_QUIET_US - 1000u);
    h_power_cycle(d);
    EXPECT(d, 0x701, "00");
    CHECK_EQ(h_read(d, 0x1017, 0), 500);
    CHECK_EQ(h_read(d, 0x6011, 0), 2);
    CHECK_EQ(co_node_store_status(d->node, CO_CLS_PARA), CO_STORE_OK);
    /* A master that never pauses long enough (a read every 100 ms): the
     * write is stored CO_STORE_DEFER_MAX_US after it all the same. */
    SDO(d, "2B 17 10 00 84 03 00 00", "60 17 10 00 00 00 00 00");
    before = d->port.nvm_writes;
    uint32_t t0 = d->now;
    while (d->port.nvm_writes == before && d->now - t0 < 2u * CO_STORE_DEFER_MAX_US) {
        h_advance(d, 100000u);
        SDO(d, "40 17 10 00 00 00 00 00", "4B 17 10 00 84 03 00 00");
    }
    CHECK(d->now - t0 >= CO_STORE_DEFER_MAX_US && d->now - t0 <= CO_STORE_DEFER_MAX_US + 100000u);
    h_power_cycle(d);
    EXPECT(d, 0x701, "00");
    CHECK_EQ(h_read(d, 0x1017, 0), 900);
}

/* A reset stores a write still waiting for its pause first (its restore
 * reads the EEPROM), and a "load" (1011h) drops it: the defaults it asks
 * for are the newest record, not the values in use. */
static void test_autosave_before_reset_not_after_load(void)
{
    boot(&pf_inx360d);
    SDO(d, "2B 14 60 00 0A 00 00 00", "60 14 60 00 00 00 00 00"); /* 6014h = 10 */
    h_rx(d, 0x000, "81 01");                                      /* reset node at once */
    EXPECT(d, 0x701, "00");
    CHECK_EQ(h_read(d, 0x6014, 0), 10);
    h_power_cycle(d);
    EXPECT(d, 0x701, "00");
    CHECK_EQ(h_read(d, 0x6014, 0), 10);
    SDO(d, "2B 14 60 00 14 00 00 00", "60 14 60 00 00 00 00 00"); /* 20, waiting */
    SDO(d, "23 11 10 01 6C 6F 61 64", "60 11 10 01 00 00 00 00"); /* load */
    h_advance(d, 2u * CO_STORE_QUIET_US);
    h_power_cycle(d);
    EXPECT(d, 0x701, "00");
    CHECK_EQ(h_read(d, 0x6014, 0), 0);
}

/* A write the node refuses (an abort) changes nothing, so nothing is
 * stored for it after the pause either. */
static void test_refused_write_stores_nothing(void)
{
    boot(&pf_inx360d);
    h_advance(d, 2u * CO_STORE_QUIET_US);
    unsigned before = d->port.nvm_writes;
    SDO(d, "2F 00 20 00 80 00 00 00", "80 00 20 00 31 00 09 06"); /* node-ID 128 */
    h_advance(d, 2u * CO_STORE_QUIET_US);
    CHECK_EQ(d->port.nvm_writes, before);
}

/* When the store behind a write fails (the EEPROM refuses it), the write
 * was answered already: the value stays in use and the stored set is
 * reported bad (EMCY 6300h, as for a set that cannot be read) until a
 * store works again. */
static void test_failed_autosave_reported(void)
{
    boot(&pf_inx360d);
    SDO(d, "2B 17 10 00 F4 01 00 00", "60 17 10 00 00 00 00 00"); /* 500 ms */
    h_advance(d, CO_STORE_QUIET_US);
    d->port.cut_after = 0; /* every EEPROM write fails from now */
    SDO(d, "2B 17 10 00 84 03 00 00", "60 17 10 00 00 00 00 00"); /* 900 ms: taken */
    h_drain(d);
    h_advance(d, CO_STORE_QUIET_US);
    EXPECT_ID(d, 0x081, "00 63 01 00 00 00 00 00");
    CHECK_EQ(co_node_store_status(d->node, CO_CLS_PARA), CO_STORE_HW);
    SDO(d, "40 17 10 00 00 00 00 00", "4B 17 10 00 84 03 00 00"); /* in use */
    d->port.cut_after = -1;
    SDO(d, "2B 17 10 00 84 03 00 00", "60 17 10 00 00 00 00 00");
    h_drain(d);
    h_advance(d, CO_STORE_QUIET_US);
    EXPECT_ID(d, 0x081, "00 00 00 00 00 00 00 00"); /* the set is sound again */
    CHECK_EQ(co_node_store_status(d->node, CO_CLS_PARA), CO_STORE_OK);
    h_power_cycle(d);
    EXPECT(d, 0x701, "00");
    CHECK_EQ(h_read(d, 0x1017, 0), 900);
}

/* The zero point sets the offset once, at the position of that
 * moment (7.3.2); stored at once, the offset comes back at power-on as it
 * was, the sensor elsewhere by then (the preset is not taken again). */
static void test_zero_point_kept_across_power_cycle(void)
{
    boot(&pf_inx360d);
    settle(131700, 0);
    SDO(d, "2F 11 60 00 02 00 00 00", "60 11 60 00 00 00 00 00"); /* scaling on */
    SDO(d, "2B 12 60 00 00 00 00 00", "60 12 60 00 00 00 00 00"); /* zero here */
    h_advance(d, CO_STORE_QUIET_US); /* stored once the master pauses */
    d->truth[0] = 140000;
    h_power_cycle(d);
    EXPECT(d, 0x701, "00");
    settle(140000, 0);
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 53 00 00 00"); /* 8.3 deg past it */
    SDO(d, "40 13 60 00 00 00 00 00", "4B 13 60 00 EB 08 00 00"); /* 2283, as set */
}

/* The zero point on the INY's Y axis: 6022h is the lateral zero point (6020h reads
 * it at once, scaling on), the X axis untouched. */
static void test_lateral_zero_point(void)
{
    boot(&pf_iny360d);
    settle(10000, 20000);
    SDO(d, "2F 21 60 00 02 00 00 00", "60 21 60 00 00 00 00 00");
    SDO(d, "2F 11 60 00 02 00 00 00", "60 11 60 00 00 00 00 00");
    SDO(d, "2B 22 60 00 32 00 00 00", "60 22 60 00 00 00 00 00"); /* 5.0 deg */
    SDO(d, "40 20 60 00 00 00 00 00", "4B 20 60 00 32 00 00 00");
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 64 00 00 00"); /* X still 10.0 */
    SDO(d, "40 12 60 00 00 00 00 00", "4B 12 60 00 00 00 00 00");
}

/* The INY's axes each have their own objects (CiA 410): X scaling and
 * zero point (6011h, 6012h) leave Y alone, Y's inversion (6021h) leaves X
 * alone; both report device type 0000019Ah (CiA 410) like the INX. */
static void test_iny_axes_are_their_own(void)
{
    boot(&pf_iny360d);
    SDO(d, "40 00 10 00 00 00 00 00", "43 00 10 00 9A 01 00 00");
    settle(10000, 20000);
    SDO(d, "2F 11 60 00 02 00 00 00", "60 11 60 00 00 00 00 00");
    SDO(d, "2B 12 60 00 00 00 00 00", "60 12 60 00 00 00 00 00");
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 00 00 00 00");
    SDO(d, "40 20 60 00 00 00 00 00", "4B 20 60 00 C8 00 00 00"); /* Y 20.0 */
    SDO(d, "2F 21 60 00 01 00 00 00", "60 21 60 00 00 00 00 00");
    SDO(d, "40 20 60 00 00 00 00 00", "4B 20 60 00 48 0D 00 00"); /* 340.0 */
    SDO(d, "40 10 60 00 00 00 00 00", "4B 10 60 00 00 00 00 00");
    boot(&pf_inx360d);
    SDO(d, "40 00 10 00 00 00 00 00", "43 00 10 00 9A 01 00 00");
}

/* The error check asks for no poll at once: in stopped an error waits for
 * the NMT command, and once reported nothing is due (no heartbeat, no
 * timer: CO_NEVER). */
static void test_error_poll_leaves_nothing_due(void)
{
    boot(&pf_inx360d);
    h_advance(d, 10000);
    CHECK_EQ(co_node_poll(d->node, d->now), CO_NEVER);
    h_rx(d, 0x000, "02 01");
    d->fault = PF_FAULT_RANGE_X;
    h_advance(d, 10000);
    CHECK_EQ(co_node_poll(d->node, d->now), CO_NEVER);
    h_drain(d);
    h_rx(d, 0x000, "80 01");
    EXPECT(d, 0x081, "10 50 11 00 00 00 00 00");
    CHECK_EQ(co_node_poll(d->node, d->now), CO_NEVER);
}

static void test_d25_stopped_and_d26_store(void)
{
    boot(&pf_inx360d);
    h_rx(d, 0x000, "02 01");
    h_drain(d);
    h_rx(d, 0x601, "40 00 20 00 00 00 00 00");
    EXPECT_NONE(d); /* D25 */
    h_rx(d, 0x000, "80 01");
    /* Autonomous store: written values survive a power cycle unsaved. */
    SDO(d, "2B 14 60 00 38 FF 00 00", "60 14 60 00 00 00 00 00");
    SDO(d, "2F 00 20 00 07 00 00 00", "60 00 20 00 00 00 00 00");
    SDO(d, "40 10 10 01 00 00 00 00", "43 10 10 01 03 00 00 00");
    h_advance(d, CO_STORE_QUIET_US); /* stored once the master pauses */
    h_power_cycle(d);
    EXPECT(d, 0x707, "00");
    SDO(d, "40 14 60 00 00 00 00 00", "4B 14 60 00 38 FF 00 00");
    /* D26: save and load; load keeps node-ID and bit rate (a decision). */
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    SDO(d, "23 11 10 01 6C 6F 61 64", "60 11 10 01 00 00 00 00");
    SDO(d, "40 14 60 00 00 00 00 00", "4B 14 60 00 38 FF 00 00"); /* RAM until reset */
    h_rx(d, 0x000, "81 07");
    EXPECT(d, 0x707, "00");
    SDO(d, "40 14 60 00 00 00 00 00", "4B 14 60 00 00 00 00 00");
    SDO(d, "40 00 18 02 00 00 00 00", "4F 00 18 02 01 00 00 00"); /* type 1 (CiA 410's default) */
}

static void test_eeprom_checksum_6300(void)
{
    boot(&pf_inx360d);
    SDO(d, "2B 14 60 00 0A 00 00 00", "60 14 60 00 00 00 00 00"); /* autostored */
    h_advance(d, CO_STORE_QUIET_US);
    for (unsigned s = 0; s < 2; s++) {
        d->port.nvm[s * CO_STORE_SLOT + CO_STORE_HDR + 1] ^= 0xFF;
    }
    h_power_cycle(d);
    EXPECT(d, 0x701, "00");
    h_advance(d, 1000);
    EXPECT(d, 0x081, "00 63 01 00 00 00 00 00"); /* 6300h: the stored set is bad */
    co_led_pattern_t run;
    co_led_pattern_t err;
    co_node_led_patterns(d->node, &run, &err);
    CHECK(err == CO_LED_FLASH2);
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    h_advance(d, 1000);
    EXPECT(d, 0x081, "00 00 00 00 00 00 00 00"); /* good store: error over */
}

static void test_dynamic_mapping_and_cobid(void)
{
    boot(&pf_iny360d);
    settle(10000, 20000);
    /* Mapping only while invalid; COB-ID only while invalid (CiA 301). */
    SDO(d, "2F 00 1A 00 01 00 00 00", "80 00 1A 00 00 00 01 06");
    SDO(d, "23 00 18 01 81 02 00 00", "80 00 18 01 30 00 09 06");
    SDO(d, "23 00 18 01 81 01 00 80", "60 00 18 01 00 00 00 00");
    SDO(d, "2F 00 1A 00 00 00 00 00", "60 00 1A 00 00 00 00 00");
    SDO(d, "23 00 1A 01 10 00 20 60", "60 00 1A 01 00 00 00 00"); /* Y first */
    SDO(d, "23 00 1A 02 10 00 11 60", "80 00 1A 02 41 00 04 06"); /* 6011 not mappable */
    SDO(d, "2F 00 1A 00 01 00 00 00", "60 00 1A 00 00 00 00 00");
    SDO(d, "23 00 18 01 81 02 00 00", "60 00 18 01 00 00 00 00"); /* valid, new ID */
    h_rx(d, 0x000, "01 01");
    h_drain(d);
    h_rx(d, 0x080, "");
    EXPECT(d, 0x281, "C8 00"); /* Y only, DLC 2 */
}

int main(void)
{
    RUN(test_v1_to_v7_boot_and_nmt);
    RUN(test_v8_node_id_and_d1_to_d5);
    RUN(test_v9_v10_bitrate_d6_d7);
    RUN(test_v11_d9_rtr_pdo);
    RUN(test_d10_sync_and_v13);
    RUN(test_v14_inhibit_ff_each_calculation);
    RUN(test_v17_emcy_and_d27);
    RUN(test_v18_heartbeat_d21);
    RUN(test_v19_v20_guarding_d22_d24);
    RUN(test_v21_to_v24_zero_point_d12_to_d18);
    RUN(test_autosave_behind_the_answer);
    RUN(test_failed_autosave_reported);
    RUN(test_refused_write_stores_nothing);
    RUN(test_autosave_before_reset_not_after_load);
    RUN(test_zero_point_kept_across_power_cycle);
    RUN(test_lateral_zero_point);
    RUN(test_iny_axes_are_their_own);
    RUN(test_error_poll_leaves_nothing_due);
    RUN(test_d25_stopped_and_d26_store);
    RUN(test_eeprom_checksum_6300);
    RUN(test_dynamic_mapping_and_cobid);
    return h_finish();
}
