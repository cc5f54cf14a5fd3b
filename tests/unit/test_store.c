/*
 * test_store.c - the parameter store on the fake EEPROM: round trip, a
 * power cut at every byte of a save, corrupt and blank images, a layout
 * change, the write-cycle limit, and how the DST X730 reports them.
 */
#include "dst.h"
#include "harness.h"

static h_dev_t dev;
static h_dev_t *const d = &dev;

#define SAVE_OK() SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00")

static void test_round_trip(void)
{
    h_boot(d, &dst_x730_xy30, false);
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_BLANK);
    CHECK_EQ(d->node->store.status[CO_CLS_LSS], CO_STORE_BLANK);
    SDO(d, "2B 17 10 00 F4 01 00 00", "60 17 10 00 00 00 00 00");
    SDO(d, "2B 24 60 00 F6 FF 00 00", "60 24 60 00 00 00 00 00");
    SAVE_OK();
    h_power_cycle(d);
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_OK);
    CHECK_EQ(h_read(d, 0x1017, 0), 500);
    CHECK_EQ(h_read(d, 0x6024, 0), 0xFFF6);
    CHECK_EQ(d->node->store.writes, 1);
    /* Second and third saves alternate slots; the newest wins. */
    SDO(d, "2B 17 10 00 58 02 00 00", "60 17 10 00 00 00 00 00");
    SAVE_OK();
    SDO(d, "2B 17 10 00 BC 02 00 00", "60 17 10 00 00 00 00 00");
    SAVE_OK();
    h_power_cycle(d);
    CHECK_EQ(h_read(d, 0x1017, 0), 700);
    CHECK_EQ(d->node->store.writes, 3);
    CHECK_EQ(h_read(d, 0x4001, 0), 0);
}

/*
 * Power cut at every byte of a save: afterwards the device boots with the
 * old complete set or the new complete set, never a mix, never defaults.
 */
static void test_power_cut_at_every_byte(void)
{
    unsigned total = 0;
    unsigned old_seen = 0;
    unsigned new_seen = 0;
    for (long cut = 0;; cut++) {
        h_boot(d, &dst_x730_xy30, false);
        SDO(d, "2B 17 10 00 64 00 00 00", "60 17 10 00 00 00 00 00"); /* old set: 100 */
        SDO(d, "2B 00 18 05 0A 00 00 00", "60 00 18 05 00 00 00 00");
        SAVE_OK();
        SDO(d, "2B 17 10 00 2C 01 00 00", "60 17 10 00 00 00 00 00"); /* new set: 300 */
        SDO(d, "2B 00 18 05 1E 00 00 00", "60 00 18 05 00 00 00 00");
        d->port.cut_after = cut;
        h_drain(d);
        h_rx(d, 0x67F, "23 10 10 01 73 61 76 65");
        const co_frame_t *r = h_next(d);
        bool finished = r != NULL && r->data[0] == 0x60;
        h_power_cycle(d);
        long long hb = h_read(d, 0x1017, 0);
        long long ev = h_read(d, 0x1800, 5);
        bool is_old = hb == 100 && ev == 10;
        bool is_new = hb == 300 && ev == 30;
        CHECK(is_old || is_new);
        CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_OK);
        CHECK_EQ(h_read(d, 0x4001, 0), 0);
        old_seen += is_old;
        new_seen += is_new;
        total++;
        if (finished) {
            CHECK(is_new);
            break; /* the cut came after the last byte: the save finished */
        }
        /* An interrupted save is answered with "hardware error". */
        CHECK(r != NULL && r->data[0] == 0x80 && co_get_u32(&r->data[4]) == CO_E_HW);
        if (cut > 1000) {
            FAIL("save never completed");
            break;
        }
    }
    printf("     power cut at %u points: %u times the old set, %u the new\n", total, old_seen,
           new_seen);
    CHECK(old_seen > 50);
    CHECK(new_seen >= 1);
}

static void corrupt_both_para_slots(void)
{
    /* Flip one data byte in each PARA slot (slots 0 and 1 of the node). */
    d->port.nvm[0 * CO_STORE_SLOT + CO_STORE_HDR + 2] ^= 0x5A;
    d->port.nvm[1 * CO_STORE_SLOT + CO_STORE_HDR + 2] ^= 0x5A;
}

static void test_corrupt_image_reported(void)
{
    h_boot(d, &dst_x730_xy30, false);
    SDO(d, "2B 17 10 00 64 00 00 00", "60 17 10 00 00 00 00 00");
    SAVE_OK();
    SAVE_OK();
    corrupt_both_para_slots();
    h_power_cycle(d);
    EXPECT(d, 0x77F, "00");
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_CORRUPT);
    h_advance(d, 1000);
    EXPECT(d, 0xFF, "00 10 00 00 40 00 00 00"); /* 0x4001 bit 6 + EMCY */
    CHECK_EQ(h_read(d, 0x1017, 0), 0);          /* defaults in use */
    CHECK_EQ(h_read(d, 0x4001, 0), DST_ERR_CHECKSUM);
    /* A good save clears it (EMCY error reset), and so does the next boot. */
    SAVE_OK();
    h_advance(d, 1000);
    EXPECT(d, 0xFF, "00 00 00 00 00 00 00 00");
    h_power_cycle(d);
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_OK);
    /* One bad copy of two: the other is used, nothing to report. */
    SDO(d, "2B 17 10 00 C8 00 00 00", "60 17 10 00 00 00 00 00");
    SAVE_OK();
    d->port.nvm[0 * CO_STORE_SLOT + 5] ^= 0x01; /* slot 0's layout hash */
    h_power_cycle(d);
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_OK);
    CHECK_EQ(h_read(d, 0x4001, 0), 0);
}

static void test_lss_checksum_bit(void)
{
    h_boot(d, &dst_x730_xy30, false);
    SDO(d, "2F F0 20 00 05 00 00 00", "60 F0 20 00 00 00 00 00");
    SDO(d, "2F F1 20 00 05 00 00 00", "60 F1 20 00 00 00 00 00");
    /* LSS slots are 2 and 3; only slot 0 of the class was written. */
    d->port.nvm[2 * CO_STORE_SLOT + CO_STORE_HDR] ^= 0xFF;
    h_power_cycle(d);
    EXPECT(d, 0x77F, "00"); /* back on the default ID 0x7F (decision: a bad LSS checksum) */
    CHECK_EQ(d->node->store.status[CO_CLS_LSS], CO_STORE_CORRUPT);
    h_advance(d, 1000);
    EXPECT(d, 0xFF, "00 10 00 00 40 00 00 00");
}

static void test_layout_change_is_not_misread(void)
{
    h_boot(d, &dst_x730_xy30, false);
    SDO(d, "2B 17 10 00 64 00 00 00", "60 17 10 00 00 00 00 00");
    SAVE_OK();
    /* A firmware with another layout: same bytes, different layout hash. */
    uint32_t h = co_get_u32(&d->port.nvm[4]);
    co_put_u32(&d->port.nvm[4], h ^ 1u);
    h_power_cycle(d);
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_CORRUPT);
    CHECK_EQ(h_read(d, 0x1017, 0), 0);
    CHECK(co_store_layout_hash(d->node, CO_CLS_PARA) != co_store_layout_hash(d->node, CO_CLS_LSS));
}

static void test_nvm_read_failure(void)
{
    h_boot(d, &dst_x730_xy30, false);
    SAVE_OK();
    d->port.nvm_read_fails = true;
    h_power_cycle(d);
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_HW);
    d->port.nvm_read_fails = false;
    h_advance(d, 1000);
    CHECK_EQ(h_read(d, 0x4001, 0), DST_ERR_CHECKSUM);
}

/*
 * The slot the next save writes is offered to the board to erase ahead
 * (co_port_nvm_prepare; the fake port erases it), never one a restore
 * needs: at power-on, before the boot-up, the older of two records; after
 * a save, once no SDO request came for CO_STORE_QUIET_US, the record it
 * replaced. A set with no valid record (blank, corrupt) is left alone, so
 * a corrupt set stays reported after a power cycle; and so is a class
 * whose slots could not be read.
 */
static void test_erase_ahead_rules(void)
{
    h_boot(d, &dst_x730_xy30, false);
    CHECK_EQ(d->port.prepares, 0);                                /* blank: nothing to offer */
    SDO(d, "2B 17 10 00 F4 01 00 00", "60 17 10 00 00 00 00 00"); /* 500 */
    SAVE_OK();                                                    /* slot 0 */
    SDO(d, "2B 17 10 00 58 02 00 00", "60 17 10 00 00 00 00 00"); /* 600 */
    SAVE_OK();                                                    /* slot 1 */
    CHECK_EQ(d->port.prepares, 0);
    uint32_t para0 = d->node->nvm_base; /* PARA's slots are the first two */
    h_advance(d, CO_STORE_QUIET_US - 1000u);
    SDO(d, "40 17 10 00 00 00 00 00", "4B 17 10 00 58 02 00 00"); /* restarts the wait */
    uint32_t asked = d->now;
    h_advance(d, CO_STORE_QUIET_US + 1000u);
    CHECK_EQ(d->port.prepares, 1);
    CHECK_EQ(d->port.prepared_addr, para0);
    CHECK_EQ(d->port.prepared_at - asked, CO_STORE_QUIET_US);
    CHECK_EQ(d->port.nvm[para0], 0xFF);
    h_advance(d, 10u * CO_STORE_QUIET_US);
    CHECK_EQ(d->port.prepares, 1); /* once a save */
    h_power_cycle(d);
    CHECK_EQ(h_read(d, 0x1017, 0), 600);
    CHECK_EQ(d->port.prepares, 2); /* slot 0 again, blank already */
    CHECK_EQ(d->port.prepared_addr, para0);
    SDO(d, "2B 17 10 00 BC 02 00 00", "60 17 10 00 00 00 00 00"); /* 700 */
    SAVE_OK();                                                    /* slot 0 */
    h_power_cycle(d);                                             /* no pause: both full */
    CHECK_EQ(d->port.prepares, 3);
    CHECK_EQ(d->port.prepared_addr, para0 + CO_STORE_SLOT); /* the older, 600 */
    CHECK_EQ(h_read(d, 0x1017, 0), 700);
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_OK);
    /* A corrupt set: no slot offered, still corrupt after a power cycle. */
    d->port.nvm[para0 + CO_STORE_HDR] ^= 0x01u;
    unsigned n = d->port.prepares;
    h_power_cycle(d);
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_CORRUPT);
    h_advance(d, 2u * CO_STORE_QUIET_US);
    h_power_cycle(d);
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_CORRUPT);
    CHECK(d->port.prepares == n || d->port.prepared_addr >= para0 + 2u * CO_STORE_SLOT);
    /* Slots that cannot be read: nothing offered, nothing erased. */
    SAVE_OK();
    n = d->port.prepares;
    d->port.nvm_read_fails = true;
    h_power_cycle(d);
    CHECK_EQ(d->port.prepares, n);
    d->port.nvm_read_fails = false;
    h_power_cycle(d);
    CHECK_EQ(d->node->store.status[CO_CLS_PARA], CO_STORE_OK);
}

static void test_write_limit(void)
{
    h_boot(d, &dst_x730_xy30, false);
    d->node->store.writes = DST_WRITE_LIMIT - 2u; /* as if 99,998 saves had been made */
    SAVE_OK();
    CHECK_EQ(h_read(d, 0x4001, 0), 0);
    SAVE_OK(); /* the 100,000th */
    h_advance(d, 1000);
    EXPECT(d, 0xFF, "00 10 00 00 20 00 00 00"); /* bit 5: flash limit reached */
    SDO(d, "23 10 10 01 73 61 76 65",
        "80 10 10 01 20 00 00 08"); /* refused at the limit (a decision) */
    SDO(d, "2F F0 20 00 05 00 00 00", "60 F0 20 00 00 00 00 00");
    SDO(d, "2F F1 20 00 05 00 00 00", "80 F1 20 00 20 00 00 08");
    h_power_cycle(d);
    CHECK_EQ(d->node->store.writes, DST_WRITE_LIMIT); /* counted in the EEPROM */
    CHECK_EQ(h_read(d, 0x4001, 0), DST_ERR_FLASH);
}

int main(void)
{
    RUN(test_round_trip);
    RUN(test_power_cut_at_every_byte);
    RUN(test_corrupt_image_reported);
    RUN(test_lss_checksum_bit);
    RUN(test_layout_change_is_not_misread);
    RUN(test_nvm_read_failure);
    RUN(test_write_limit);
    RUN(test_erase_ahead_rules);
    return h_finish();
}
