/*
 * test_products_edge.c - the product registry and the DST and P+F
 * behaviour the manuals' example frames leave out: product_find() and the
 * bit-rate code tables; on the DST X730 the
 * values it accepts and refuses (heartbeat 0, transmission types,
 * resolutions, EMCY COB-ID), the node-ID pair written only when it
 * changes, big-endian PDOs after a reset (0x5001 = 0), an error
 * raised while stopped reported once allowed again, the error behaviour
 * 0x4000 = 0 in pre-operational, an EEPROM that cannot be read (0x4001
 * bit 6); on the P+F the fixed resolution (0.1 deg),
 * the error LED and 6300h for stored sets that cannot be used. For every
 * product: its LSS bit rates are its own table's; each TPDO's mapping names objects of the mapped
 * length and covers exactly the bytes the frame has (CiA 301: a consumer checks the length against
 * the mapping, EMCY 8220h).
 */
#include "dst.h"
#include "gsh.h"
#include "harness.h"
#include "jd.h"
#include "pf.h"

static h_dev_t dev;
static h_dev_t *const d = &dev;

static void test_registry(void)
{
    for (size_t i = 0; product_list[i] != NULL; i++) {
        CHECK(product_find(product_list[i]->id) == product_list[i]);
    }
    /* Each product's own id is the ID its family's declaration gives its
     * row (od/<family>/family.cmake, cmake/families.cmake checks that no
     * ID is declared twice), in the registry's order. */
    static const char *const ids[] = {PRODUCT_REGISTRY_IDS PRODUCT_REGISTRY_EXAMPLE_IDS};
    size_t n = 0;
    for (; product_list[n] != NULL; n++) {
        CHECK(n < sizeof(ids) / sizeof(ids[0]) && strcmp(product_list[n]->id, ids[n]) == 0);
        for (size_t j = 0; j < n; j++) {
            CHECK(strcmp(product_list[j]->id, product_list[n]->id) != 0);
        }
    }
    CHECK_EQ(n, sizeof(ids) / sizeof(ids[0]));
    CHECK(product_find("dst-x730") == NULL); /* a prefix is no ID */
    CHECK(product_find("") == NULL);
    CHECK(product_find("DST-X730-XY30") == NULL);
    /* Bit-rate codes (kbit/s): CiA (DST, GSH-A), ifm (JD 3001h), P+F. */
    CHECK_EQ(product_kbps(&dst_x730_xy30, 0), 1000);
    CHECK_EQ(product_kbps(&dst_x730_xy30, 3), 250);
    CHECK_EQ(product_kbps(&dst_x730_xy30, 7), 20);
    CHECK_EQ(product_kbps(&dst_x730_xy30, 8), 0);  /* no such code */
    CHECK_EQ(product_kbps(&dst_x730_xy30, 16), 0); /* outside the table */
    CHECK_EQ(product_kbps(&dst_x730_xy30, 255), 0);
    CHECK_EQ(product_kbps(product_find("jd2xxx"), 0), 20);
    CHECK_EQ(product_kbps(product_find("jd2xxx"), 7), 1000);
    CHECK_EQ(product_kbps(&pf_inx360d, 2), 250);
    CHECK_EQ(product_kbps(&pf_inx360d, 3), 0);
    product_t none = {.id = "no-table"};
    CHECK_EQ(product_kbps(&none, 3), 0);
}

/* An LSS slave offers a CiA 305 bit-timing index exactly when its own
 * bit-rate table (what its code object and co_node_set_bitrate take) has
 * that rate: co_node_cfg_t.lss_bitrates is written next to the table and
 * must say the same. A product without LSS offers none. */
static void test_lss_rates_are_the_tables(void)
{
    static const uint16_t cia305[16] = {1000, 800, 500, 250, 125, 0 /* reserved */, 50, 20, 10};
    unsigned lss_products = 0;
    for (size_t i = 0; product_list[i] != NULL; i++) {
        const product_t *p = product_list[i];
        if (!product_lss(p)) {
            CHECK_EQ(p->cfg != NULL ? p->cfg->lss_bitrates : 0u, 0u);
            continue;
        }
        lss_products++;
        for (unsigned k = 0; k < 16u; k++) {
            bool has = false;
            for (uint8_t code = 0; code < 16u; code++) {
                has = has || (cia305[k] != 0u && product_kbps(p, code) == cia305[k]);
            }
            CHECK_EQ((p->cfg->lss_bitrates >> k) & 1u, has ? 1u : 0u);
        }
    }
    CHECK(lss_products >= 2u); /* JD1xxx, JD2xxx */
}

#define ANSWERS_MAX 128u
/* Scratch memory of the tests below, one test at a time (the emulated
 * Cortex-M0 has 16 KB of RAM): the answers of two power-ons, or the ports
 * of a product's nodes. */
static union {
    uint8_t answers[2][2][ANSWERS_MAX][8];
    fake_port_t ports[PRODUCT_MAX_NODES];
    struct {
        uint8_t out[2][ANSWERS_MAX][8];
        uint8_t nvm[2][FAKE_NVM_SIZE];
    } saved;
} scratch;
static unsigned power_on_answers(const product_t *p, uint8_t fill, uint8_t out[2][ANSWERS_MAX][8]);

static void boot_dst(void)
{
    h_boot(d, &dst_x730_xy30, false);
    EXPECT(d, 0x77F, "00");
}

static void test_dst_values(void)
{
    boot_dst();
    SDO(d, "2B 17 10 00 14 00 00 00", "60 17 10 00 00 00 00 00"); /* 20 ms */
    SDO(d, "2B 17 10 00 00 00 00 00", "60 17 10 00 00 00 00 00"); /* 0: off */
    SDO(d, "2B 17 10 00 13 00 00 00", "80 17 10 00 30 00 09 06"); /* 1-19 refused */
    SDO(d, "2B 17 10 00 01 00 00 00", "80 17 10 00 30 00 09 06"); /* from 1 on (object 1017h) */
    /* Event timer: 0 off, 4..65535 ms; 1..3 refused from 1 on (section 12, examples 12, 13). */
    SDO(d, "2B 00 18 05 01 00 00 00", "80 00 18 05 30 00 09 06");
    /* Transmission types 1..240 and 254 only (section 12, 0x1800 sub 2). */
    SDO(d, "2F 00 18 02 FF 00 00 00", "80 00 18 02 30 00 09 06");
    SDO(d, "2F 00 18 02 FC 00 00 00", "80 00 18 02 30 00 09 06");
    SDO(d, "2F 00 18 02 F1 00 00 00", "80 00 18 02 30 00 09 06");
    SDO(d, "2F 00 18 02 F0 00 00 00", "60 00 18 02 00 00 00 00");
    /* 0x6000: 0.01, 0.05, 0.1, 0.5, 1 deg. */
    static const char *const ok[] = {"2B 00 60 00 32 00 00 00", "2B 00 60 00 F4 01 00 00",
                                     "2B 00 60 00 E8 03 00 00", "2B 00 60 00 0A 00 00 00"};
    for (unsigned i = 0; i < 4u; i++) {
        SDO(d, ok[i], "60 00 60 00 00 00 00 00");
    }
    SDO(d, "2B 00 60 00 14 00 00 00", "80 00 60 00 30 00 09 06"); /* 0.02 */
    /* EMCY COB-ID: CAN-ID 0 is no EMCY while valid (CiA 301 7.3.5); an
     * invalid one may name any CAN-ID. */
    SDO(d, "23 14 10 00 00 00 00 00", "80 14 10 00 30 00 09 06");
    SDO(d, "23 14 10 00 00 00 00 80", "60 14 10 00 00 00 00 00");
}

/* The pair is written to EEPROM when both copies agree on a new
 * value; agreeing on the active one costs no write cycle. */
static void test_dst_node_id_pair_unchanged(void)
{
    boot_dst();
    unsigned w = d->port.nvm_writes;
    SDO(d, "2F F0 20 00 7F 00 00 00", "60 F0 20 00 00 00 00 00");
    SDO(d, "2F F1 20 00 7F 00 00 00", "60 F1 20 00 00 00 00 00");
    CHECK_EQ(d->port.nvm_writes, w);
    SDO(d, "2F F0 20 00 20 00 00 00", "60 F0 20 00 00 00 00 00");
    CHECK_EQ(d->port.nvm_writes, w);
    SDO(d, "2F F1 20 00 20 00 00 00", "60 F1 20 00 00 00 00 00");
    CHECK(d->port.nvm_writes > w);
    h_power_cycle(d);
    EXPECT(d, 0x720, "00");
}

/* Each copy of the pair reads what was written to it (each write answered on its own): one copy
 * alone commits nothing, and the other keeps the active value. */
static void test_dst_pair_copies_are_their_own(void)
{
    boot_dst();
    SDO(d, "2F F0 20 00 20 00 00 00", "60 F0 20 00 00 00 00 00");
    CHECK_EQ(h_read(d, 0x20F0, 0), 0x20);
    CHECK_EQ(h_read(d, 0x20F1, 0), 0x7F);
    SDO(d, "2F F3 20 00 05 00 00 00", "60 F3 20 00 00 00 00 00");
    CHECK_EQ(h_read(d, 0x20F2, 0), 3);
    CHECK_EQ(h_read(d, 0x20F3, 0), 5);
    h_power_cycle(d);
    EXPECT(d, 0x77F, "00");
    CHECK_EQ(d->port.kbps, 250);
}

/* 0x4001 bit 0 "sensor error" (self-test failure, MEMS IC communication
 * error): no valid reading, so the slope holds its last value until the
 * sensor works again; and with no error, 0x4001 reads 0 from the first
 * request after power-on, before the node has looked for errors. */
static void test_dst_sensor_error_holds_the_slope(void)
{
    (void)power_on_answers(&dst_x730_xy30, 0xA5, scratch.answers[0]);
    const co_od_t *od = co_cfg(d->node)->od;
    for (unsigned k = 0; k < od->count && k < ANSWERS_MAX; k++) {
        if (od->entries[k].index == 0x4001u) {
            CHECK_EQ(scratch.answers[0][0][k][0], 0x4F);
            CHECK_EQ(scratch.answers[0][0][k][4], 0);
        }
    }
    boot_dst();
    d->truth[0] = 10000;
    h_advance(d, 3000000);
    CHECK_EQ(h_read(d, 0x6010, 0), 200); /* 10 deg in 0.05 deg */
    d->fault = 1u;
    d->truth[0] = 20000;
    h_advance(d, 3000000);
    CHECK_EQ(h_read(d, 0x4001, 0), DST_ERR_SENSOR);
    CHECK_EQ(h_read(d, 0x6010, 0), 200);
    d->fault = 0u;
    h_advance(d, 3000000);
    CHECK_EQ(h_read(d, 0x6010, 0), 400);
}

/* The bit-rate codes are 0..7 (object 20F2h): the last, 7 (20 kbit/s), is
 * a good stored code; a stored 8 (written by no SDO: 0x20F2 takes 0..7)
 * is not: the default 250 kbit/s, and the set reported corrupt (0x4001
 * bit 6). */
static void test_dst_stored_bitrate_codes(void)
{
    boot_dst();
    SDO(d, "2F F2 20 00 07 00 00 00", "60 F2 20 00 00 00 00 00");
    SDO(d, "2F F3 20 00 07 00 00 00", "60 F3 20 00 00 00 00 00");
    h_power_cycle(d);
    EXPECT(d, 0x77F, "00");
    CHECK_EQ(d->port.kbps, 20);
    h_advance(d, 1000);
    CHECK_EQ(h_read(d, 0x4001, 0), 0);
    dst_dev_t *x = h_inst(d);
    x->lss.bitrate = 8;
    CHECK_EQ(co_store_save(d->node, CO_CLS_LSS), CO_OK);
    h_power_cycle(d);
    EXPECT(d, 0x77F, "00");
    CHECK_EQ(d->port.kbps, 250);
    h_advance(d, 1000);
    CHECK_EQ(h_read(d, 0x4001, 0), DST_ERR_CHECKSUM);
}

/* A saved resolution comes back at power-on also when scaling was turned
 * off after it was set (scaling is asked of a new resolution only). */
static void test_dst_resolution_kept_without_scaling(void)
{
    boot_dst();
    SDO(d, "2B 00 60 00 0A 00 00 00", "60 00 60 00 00 00 00 00"); /* 0.01 deg */
    SDO(d, "2F 11 60 00 00 00 00 00", "60 11 60 00 00 00 00 00"); /* scaling off */
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    h_power_cycle(d);
    EXPECT(d, 0x77F, "00");
    CHECK_EQ(h_read(d, 0x6000, 0), 10);
    CHECK_EQ(h_read(d, 0x6011, 0), 0);
    SDO(d, "2B 00 60 00 32 00 00 00", "80 00 60 00 22 00 00 08"); /* a new one needs it */
}

/* 0x5001 = 0 (big endian), saved: the PDOs after the next power-on too. */
static void test_dst_big_endian_after_reset(void)
{
    boot_dst();
    d->truth[0] = 12500;
    d->truth[1] = -3000;
    h_advance(d, 3000000); /* the filter settles */
    SDO(d, "2F 01 50 00 00 00 00 00", "60 01 50 00 00 00 00 00");
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    h_power_cycle(d);
    h_advance(d, 3000000);
    h_rx(d, 0x000, "01 7F");
    h_advance(d, 1000);
    EXPECT_ID(d, 0x1FF, "00 FA FF C4 00 00 00 00"); /* 250, -60 in 0.05 deg (default) */
}

/* No EMCY in stopped: an error raised there is reported when EMCY is
 * allowed again. With 0x4000 = 0 a new error in pre-operational keeps the
 * state (only operational drops to pre-operational). */
static void test_dst_error_while_stopped(void)
{
    boot_dst();
    SDO(d, "2F 00 40 00 00 00 00 00", "60 00 40 00 00 00 00 00");
    h_rx(d, 0x000, "02 7F");
    h_drain(d);
    d->fault = 1;
    h_advance(d, 20000);
    EXPECT_NONE(d);
    h_rx(d, 0x000, "80 7F");
    h_advance(d, 1000);
    EXPECT(d, 0x0FF, "00 10 00 00 01 00 00 00");
    CHECK_EQ(d->node->nmt.state, CO_NMT_PREOP);
    d->fault = 0;
    h_advance(d, 20000);
    EXPECT(d, 0x0FF, "00 00 00 00 00 00 00 00");
}

/* An EEPROM that cannot be read at power-on: defaults, and 0x4001 bit 6
 * with an EMCY, as a corrupt stored set is reported. */
static void test_dst_eeprom_unreadable(void)
{
    boot_dst();
    d->port.nvm_read_fails = true;
    h_power_cycle(d);
    EXPECT(d, 0x77F, "00");
    h_advance(d, 1000);
    EXPECT(d, 0x0FF, "00 10 00 00 40 00 00 00");
    d->port.nvm_read_fails = false;
    CHECK_EQ(h_read(d, 0x4001, 0), 0x40);
}

static void boot_pf(const product_t *p)
{
    h_boot(d, p, false);
    EXPECT(d, 0x701, "00");
}

/* The resolution is fixed at 0.1 deg (P+F manual, section 7.3). */
static void test_pf_resolution_fixed(void)
{
    boot_pf(&pf_inx360d);
    SDO(d, "2B 00 60 00 64 00 00 00", "60 00 60 00 00 00 00 00");
    SDO(d, "2B 00 60 00 0A 00 00 00", "80 00 60 00 30 00 09 06");
    SDO(d, "40 00 60 00 00 00 00 00", "4B 00 60 00 64 00 00 00");
}

/* The err LED (P+F manual, section 5.3): bus-off on (run off), Y out of range 1x flash. */
static void test_pf_leds(void)
{
    boot_pf(&pf_iny360d);
    co_led_pattern_t run;
    co_led_pattern_t err;
    co_node_set_can_state(d->node, CO_CAN_BUSOFF);
    co_node_led_patterns(d->node, &run, &err);
    CHECK(run == CO_LED_OFF && err == CO_LED_ON);
    co_node_set_can_state(d->node, CO_CAN_ACTIVE);
    d->fault = PF_FAULT_RANGE_Y;
    h_advance(d, 10000);
    co_node_led_patterns(d->node, &run, &err);
    CHECK(run == CO_LED_BLINK && err == CO_LED_FLASH1);
}

/* 6300h (CiA 301) for a stored set that cannot be used: unreadable EEPROM,
 * or a node-ID / bit-rate record that fails its check; err LED 2x flash. */
static void test_pf_stored_set_unusable(void)
{
    boot_pf(&pf_inx360d);
    d->port.nvm_read_fails = true;
    h_power_cycle(d);
    EXPECT(d, 0x701, "00");
    h_advance(d, 10000);
    EXPECT(d, 0x081, "00 63 01 00 00 00 00 00");
    co_led_pattern_t run;
    co_led_pattern_t err;
    co_node_led_patterns(d->node, &run, &err);
    CHECK(err == CO_LED_FLASH2);
    d->port.nvm_read_fails = false;
    /* A record header in the node-ID set's first slot with nothing valid behind it. */
    boot_pf(&pf_inx360d);
    static const uint8_t magic[4] = {0x43, 0x6F, 0x50, 0x53}; /* "CoPS" */
    memcpy(&d->port.nvm[2u * CO_STORE_SLOT], magic, 4);
    h_power_cycle(d);
    EXPECT(d, 0x701, "00");
    CHECK_EQ(d->node->store.status[CO_CLS_LSS], CO_STORE_CORRUPT);
    h_advance(d, 10000);
    EXPECT(d, 0x081, "00 63 01 00 00 00 00 00");
}

/* ---- every product: TPDO length = mapped length ------------------------ */

/* Bytes mapped by TPDO n of node k (0: no TPDO n); every entry must name a
 * mappable object of exactly the mapped length (CiA 301). */
static unsigned mapped_bytes(co_node_t *node, unsigned n)
{
    const co_od_entry_t *cnt = co_node_entry(node, (uint16_t)(0x1A00u + n), 0);
    uint32_t count = 0;
    if (cnt == NULL || co_od_get(node, cnt, &count) != CO_OK) {
        return 0;
    }
    unsigned bytes = 0;
    for (uint32_t i = 1; i <= count; i++) {
        uint32_t m = 0;
        const co_od_entry_t *me = co_node_entry(node, (uint16_t)(0x1A00u + n), (uint8_t)i);
        CHECK(me != NULL && co_od_get(node, me, &m) == CO_OK);
        const co_od_entry_t *obj = co_node_entry(node, (uint16_t)(m >> 16), (uint8_t)(m >> 8));
        CHECK(obj != NULL && (obj->attr & CO_A_PDO) != 0u);
        if (obj == NULL || co_od_size(obj) * 8u != (m & 0xFFu)) {
            fprintf(stderr, "  %s: 1A%02Xh:%02X = %08lXh: the object is not %lu bits\n",
                    d->prod->id, n, (unsigned)i, (unsigned long)m, (unsigned long)(m & 0xFFu));
            FAIL("a mapped length differs from its object's");
        }
        bytes += (m & 0xFFu) / 8u;
    }
    return bytes;
}

/* The TPDO frames node k sends within 300 ms of NMT start and two SYNCs:
 * each has the DLC its mapping gives. Returns the frames checked. */
static unsigned check_sent_lengths(unsigned k)
{
    co_node_t *node = d->nodes[k];
    uint16_t cob[CO_TPDO_MAX] = {0};
    unsigned len[CO_TPDO_MAX] = {0};
    for (unsigned n = 0; n < CO_TPDO_MAX; n++) {
        const co_od_entry_t *c = co_node_entry(node, (uint16_t)(0x1800u + n), 1);
        uint32_t v = 0x80000000u;
        if (c != NULL) {
            (void)co_od_get(node, c, &v);
        }
        cob[n] = (v & 0x80000000u) != 0u ? 0u : (uint16_t)(v & 0x7FFu);
        len[n] = mapped_bytes(node, n);
        if (cob[n] != 0u) {
            co_frame_t f;
            co_tpdo_build(node, n, &f);
            CHECK_EQ(f.dlc, len[n]);
        }
    }
    h_drain(d);
    h_rx(d, 0x000, "01 00");
    h_rx(d, 0x080, "");
    h_advance(d, 150000);
    h_rx(d, 0x080, "");
    h_advance(d, 150000);
    unsigned seen = 0;
    for (const co_frame_t *f = h_next(d); f != NULL; f = h_next(d)) {
        for (unsigned n = 0; n < CO_TPDO_MAX; n++) {
            if (cob[n] != 0u && f->id == cob[n] && !f->rtr) {
                CHECK_EQ(f->dlc, len[n]);
                seen++;
            }
        }
    }
    return seen;
}

/* Every product, every node, every TPDO: the frame is as long as its
 * mapping (the DST and GSH-A map all 8 bytes of their fixed frames), and
 * each mapped length is its object's. */
static void test_mapped_length_is_the_dlc(void)
{
    for (size_t i = 0; product_list[i] != NULL; i++) {
        h_boot(d, product_list[i], false);
        for (unsigned k = 0; k < d->nnodes; k++) {
            if (check_sent_lengths(k) == 0u) {
                fprintf(stderr, "  %s node %u: no TPDO sent\n", product_list[i]->id, k);
                FAIL("no TPDO to check");
            }
        }
    }
}

/* Expedited SDO download of len bytes to node 0; the answer's command byte. */
static uint8_t sdo_write(uint16_t index, uint8_t sub, uint32_t value, unsigned len)
{
    co_frame_t f = {.id = (uint16_t)(0x600u + d->node->node_id), .dlc = 8};
    f.data[0] = (uint8_t)(0x23u | ((4u - len) << 2));
    co_put_u16(&f.data[1], index);
    f.data[3] = sub;
    co_put_u32(&f.data[4], value);
    h_drain(d);
    h_rx_frame(d, &f);
    for (const co_frame_t *r = h_next(d); r != NULL; r = h_next(d)) {
        if (r->id == 0x580u + d->node->node_id) {
            return r->data[0];
        }
    }
    return 0;
}

/* The products whose mapping a master may write (JD, P+F): after a new
 * mapping of one object, what the device sends has that object's length. */
static void test_written_mapping_sets_the_dlc(void)
{
    unsigned writable = 0;
    for (size_t i = 0; product_list[i] != NULL; i++) {
        h_boot(d, product_list[i], false);
        const co_od_entry_t *m1 = co_node_entry(d->node, 0x1A00, 1);
        if (m1 == NULL || (m1->attr & CO_A_W) == 0u) {
            continue;
        }
        writable++;
        uint32_t first = (uint32_t)h_read(d, 0x1A00, 1);
        uint32_t cob = (uint32_t)h_read(d, 0x1800, 1);
        CHECK_EQ(sdo_write(0x1800, 1, cob | 0x80000000u, 4), 0x60); /* invalid first */
        CHECK_EQ(sdo_write(0x1A00, 0, 0, 1), 0x60);
        CHECK_EQ(sdo_write(0x1A00, 0, 1, 1), 0x60); /* sub 1 alone */
        CHECK_EQ(sdo_write(0x1800, 1, cob & 0x7FFFFFFFu, 4), 0x60);
        CHECK_EQ(mapped_bytes(d->node, 0), (first & 0xFFu) / 8u);
        CHECK(check_sent_lengths(0) > 0u);
    }
    CHECK(writable >= 2u); /* JD1, JD2, INX, INY */
}

/* The simulated inputs a board offers for the JD models: the angles in
 * deg (level at power-on, PRODUCT_ANGLE_LIMIT), then the PCB temperature
 * (3411h) in degC, 25 degC at power-on, +-200 degC accepted. */
static void test_jd_inputs(void)
{
    const product_t *const p[2] = {&jd2xxx, &jd1xxx};
    for (unsigned k = 0; k < 2u; k++) {
        unsigned angles = k == 0u ? 2u : 1u;
        for (unsigned i = 0; i < angles; i++) {
            CHECK_EQ(p[k]->inputs[i].initial, 0);
            CHECK_EQ(p[k]->inputs[i].limit, PRODUCT_ANGLE_LIMIT);
        }
        const product_input_t *t = &p[k]->inputs[angles];
        CHECK(t->name != NULL && strcmp(t->name, "temp") == 0);
        CHECK_EQ(t->initial, 25000);
        CHECK_EQ(t->limit, 200);
        CHECK(p[k]->inputs[angles + 1u].name == NULL);
    }
}

/* Every product's simulated angles start level and take
 * PRODUCT_ANGLE_LIMIT: a board's inputs in deg. */
static void test_angle_inputs_start_level(void)
{
    for (size_t i = 0; product_list[i] != NULL; i++) {
        const product_t *p = product_list[i];
        for (unsigned k = 0; k < PRODUCT_MAX_INPUTS && p->inputs[k].name != NULL; k++) {
            if (p->inputs[k].unit != NULL && strcmp(p->inputs[k].unit, "deg") == 0) {
                CHECK_EQ(p->inputs[k].initial, 0);
                CHECK_EQ(p->inputs[k].limit, PRODUCT_ANGLE_LIMIT);
            }
        }
    }
}

/* ---- every product: its nodes' ports and EEPROM areas ------------------ */

/* product.h: node i talks through ports[i]. Each port gets its node's
 * boot-up, and only that (a device's nodes on their own buses). */
static void test_each_node_talks_through_its_port(void)
{
    fake_port_t *ports = scratch.ports;
    for (size_t i = 0; product_list[i] != NULL; i++) {
        const product_t *p = product_list[i];
        void *pp[PRODUCT_MAX_NODES];
        for (unsigned k = 0; k < PRODUCT_MAX_NODES; k++) {
            fake_port_init(&ports[k]);
            pp[k] = &ports[k];
        }
        memset(d, 0, sizeof(*d));
        p->create(p, d->mem, pp, d->nodes);
        int32_t in[PRODUCT_MAX_INPUTS];
        for (unsigned k = 0; k < PRODUCT_MAX_INPUTS; k++) {
            in[k] = p->inputs[k].initial;
        }
        p->sample(d->mem, in, 0);
        for (unsigned k = 0; k < p->nodes; k++) {
            co_node_start(d->nodes[k], 1000000u);
        }
        for (unsigned k = 0; k < PRODUCT_MAX_NODES; k++) {
            bool own = k < p->nodes;
            CHECK_EQ(ports[k].ntx, own ? 1u : 0u);
            if (own && ports[k].ntx == 1u) {
                CHECK_EQ(ports[k].tx[0].id, 0x700u + co_node_id(d->nodes[k]));
            }
        }
    }
}

/* Node 0's answers to an upload of each of its first objects, right after
 * power-on (one sensor sample, no poll yet) and again after 100 ms, the
 * instance built in memory that held fill before. */
static unsigned power_on_answers(const product_t *p, uint8_t fill, uint8_t out[2][ANSWERS_MAX][8])
{
    void *ports[PRODUCT_MAX_NODES] = {&d->port, &d->port};
    memset(d, 0, sizeof(*d));
    fake_port_init(&d->port);
    memset(d->mem, fill, sizeof(d->mem));
    d->prod = p;
    p->create(p, d->mem, ports, d->nodes);
    d->nnodes = p->nodes;
    d->node = d->nodes[0];
    d->now = 1000000u;
    for (unsigned k = 0; k < PRODUCT_MAX_INPUTS; k++) {
        d->truth[k] = p->inputs[k].initial;
    }
    p->sample(d->mem, d->truth, 0);
    for (unsigned k = 0; k < d->nnodes; k++) {
        co_node_start(d->nodes[k], d->now);
    }
    d->next_sample = d->now + CO_FILTER_PERIOD_US;
    const co_od_t *od = co_cfg(d->node)->od;
    unsigned n = od->count < ANSWERS_MAX ? od->count : ANSWERS_MAX;
    for (unsigned pass = 0; pass < 2u; pass++) {
        for (unsigned i = 0; i < n; i++) {
            co_frame_t f = {.id = (uint16_t)(0x600u + d->node->node_id), .dlc = 8, .data = {0x40}};
            co_put_u16(&f.data[1], od->entries[i].index);
            f.data[3] = od->entries[i].sub;
            h_drain(d);
            co_node_receive(d->node, &f, d->now);
            const co_frame_t *r = h_next(d);
            memset(out[pass][i], 0, 8);
            if (r != NULL) {
                memcpy(out[pass][i], r->data, 8);
            }
        }
        h_advance(d, 100000);
    }
    return n;
}

/* product.h: create() builds the instance in the memory it is given,
 * whatever that held before (a board's buffer is not known to be zero):
 * every object answers the same right after power-on and 100 ms later
 * whether the memory was zero or full of other bytes. */
static void test_create_on_used_memory(void)
{
    for (size_t i = 0; product_list[i] != NULL; i++) {
        unsigned n = power_on_answers(product_list[i], 0x00, scratch.answers[0]);
        (void)power_on_answers(product_list[i], 0xA5, scratch.answers[1]);
        const co_od_t *od = co_cfg(d->node)->od;
        for (unsigned pass = 0; pass < 2u; pass++) {
            for (unsigned k = 0; k < n; k++) {
                if (memcmp(scratch.answers[0][pass][k], scratch.answers[1][pass][k], 8) != 0) {
                    fprintf(stderr, "  %s %04Xh:%u (pass %u) differs on used memory\n",
                            product_list[i]->id, (unsigned)od->entries[k].index,
                            (unsigned)od->entries[k].sub, pass);
                    FAIL("an object depends on what the memory held before create()");
                }
            }
        }
    }
}

/* What a save stores is the device's parameters and nothing of what the
 * memory held before create(): the same EEPROM bytes whether it was zero
 * or full of other bytes (the parameter structs' padding, and the fields of
 * an axis the product does not have, included), as CiA 301's "save all
 * parameters" (1010h sub 1) writes them. */
static void test_saved_set_independent_of_memory(void)
{
    for (size_t i = 0; product_list[i] != NULL; i++) {
        for (unsigned k = 0; k < 2u; k++) {
            (void)power_on_answers(product_list[i], k == 0u ? 0x00 : 0xA5, scratch.saved.out);
            co_frame_t f = {.id = (uint16_t)(0x600u + d->node->node_id),
                            .dlc = 8,
                            .data = {0x23, 0x10, 0x10, 0x01, 0x73, 0x61, 0x76, 0x65}};
            h_drain(d);
            co_node_receive(d->node, &f, d->now);
            const co_frame_t *r = h_next(d);
            CHECK(r != NULL && r->data[0] == 0x60u);
            memcpy(scratch.saved.nvm[k], d->port.nvm, FAKE_NVM_SIZE);
        }
        if (memcmp(scratch.saved.nvm[0], scratch.saved.nvm[1], FAKE_NVM_SIZE) != 0) {
            fprintf(stderr, "  %s: the saved set depends on the memory before create()\n",
                    product_list[i]->id);
            FAIL("a stored byte depends on what the memory held before create()");
        }
    }
}

/* The GSH-A has two channels at most (the redundant version): a product
 * row asking for more nodes is a programming error, reported (CO_CHECK),
 * and two channels are built, no more. */
static void test_gsh_at_most_two_channels(void)
{
    product_t row = gsh_a_redundant;
    row.nodes = 3;
    void *ports[3] = {&d->port, &d->port, &d->port};
    co_node_t *nodes[3] = {NULL, NULL, NULL};
    memset(d, 0, sizeof(*d));
    fake_port_init(&d->port);
    unsigned before = h_asserts;
    h_expect_assert(1);
    row.create(&row, d->mem, ports, nodes);
    CHECK_EQ(h_asserts, before + 1u);
    CHECK(nodes[0] != NULL && nodes[1] != NULL && nodes[2] == NULL);
    CHECK_EQ(((gsh_dev_t *)h_inst(d))->nchan, 2);
}

/* The store record ("CoPS") at an EEPROM address. */
static bool record_at(uint32_t addr)
{
    static const uint8_t magic[4] = {0x43, 0x6F, 0x50, 0x53};
    return memcmp(&d->port.nvm[addr], magic, sizeof(magic)) == 0;
}

/* co_node_init: node i of a device stores its sets in its own
 * CO_STORE_NVM_SIZE bytes from i x CO_STORE_NVM_SIZE, so that the nodes of
 * one EEPROM never overwrite each other: a "save" (0x1010:1) on node i puts
 * its parameter record at the start of its area. */
static void test_each_node_stores_in_its_area(void)
{
    for (size_t i = 0; product_list[i] != NULL; i++) {
        h_boot(d, product_list[i], false);
        for (unsigned k = 0; k < d->nnodes; k++) {
            co_node_t *node = d->nodes[k];
            uint8_t id = co_node_id(node);
            h_drain(d);
            h_rx(d, (uint16_t)(0x600u + id), "23 10 10 01 73 61 76 65");
            const co_frame_t *f = h_next(d);
            while (f != NULL && f->id != 0x580u + id) {
                f = h_next(d); /* a PDO of a product that starts by itself */
            }
            CHECK(f != NULL && f->data[0] == 0x60u);
            uint32_t base = k * CO_STORE_NVM_SIZE;
            if (!record_at(base) && !record_at(base + CO_STORE_SLOT)) {
                fprintf(stderr, "  %s node %u: no record at %u\n", product_list[i]->id, k,
                        (unsigned)base);
                FAIL("a node's parameter record is not in its area");
            }
        }
    }
}

int main(void)
{
    RUN(test_registry);
    RUN(test_lss_rates_are_the_tables);
    RUN(test_dst_values);
    RUN(test_dst_node_id_pair_unchanged);
    RUN(test_dst_pair_copies_are_their_own);
    RUN(test_dst_sensor_error_holds_the_slope);
    RUN(test_dst_stored_bitrate_codes);
    RUN(test_dst_resolution_kept_without_scaling);
    RUN(test_dst_big_endian_after_reset);
    RUN(test_dst_error_while_stopped);
    RUN(test_dst_eeprom_unreadable);
    RUN(test_pf_resolution_fixed);
    RUN(test_pf_leds);
    RUN(test_pf_stored_set_unusable);
    RUN(test_mapped_length_is_the_dlc);
    RUN(test_written_mapping_sets_the_dlc);
    RUN(test_jd_inputs);
    RUN(test_angle_inputs_start_level);
    RUN(test_each_node_talks_through_its_port);
    RUN(test_each_node_stores_in_its_area);
    RUN(test_create_on_used_memory);
    RUN(test_saved_set_independent_of_memory);
    RUN(test_gsh_at_most_two_channels);
    return h_finish();
}
