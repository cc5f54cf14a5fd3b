/*
 * test_factory_id.c - a node's own factory node-ID (co_node_set_factory_id,
 * co_node.h): what a blank EEPROM boots with and what "restore defaults"
 * returns to, in every product family (the node-ID lives in the LSS set on
 * the DST, GSH and P+F, in the JD's own 3000h), and the contract around it;
 * a node's own serial number (co_node_set_serial): 1018h:04 and the LSS
 * address in every product, each node of a device its own.
 */
#include "dst.h"
#include "gsh.h"
#include "harness.h"
#include "jd.h"
#include "pf.h"

static h_dev_t dev;
static h_dev_t *const d = &dev;

static const uint8_t ids[PRODUCT_MAX_NODES] = {0x21, 0x22};

/* Every product: a blank EEPROM boots each node on its factory node-ID,
 * and answers SDO and sends its boot-up there, at every power cycle. */
static void test_every_product_boots_on_its_factory_id(void)
{
    for (size_t k = 0; product_list[k] != NULL; k++) {
        h_boot_ids(d, product_list[k], ids);
        for (unsigned i = 0; i < d->nnodes; i++) {
            CHECK_EQ(co_node_id(d->nodes[i]), ids[i]);
            CHECK_EQ(co_node_factory_id(d->nodes[i]), ids[i]);
        }
        EXPECT_ID(d, 0x721, "00");
        CHECK_EQ(h_read(d, 0x1000, 0) >= 0, 1); /* SDO on 0x621 */
        h_power_cycle(d);
        CHECK_EQ(co_node_id(d->node), 0x21);
    }
}

/* SDO upload of 1018h:04 from node k (expedited, 4 bytes), or -1. */
static long long read_serial(unsigned k)
{
    uint8_t id = co_node_id(d->nodes[k]);
    h_drain(d);
    co_frame_t f = {.id = (uint16_t)(0x600u + id), .dlc = 8, .data = {0x40, 0x18, 0x10, 0x04}};
    h_rx_frame(d, &f);
    for (const co_frame_t *r = h_next(d); r != NULL; r = h_next(d)) {
        if (r->id == 0x580u + id) {
            return r->data[0] == 0x43 ? (long long)co_get_u32(&r->data[4]) : -1;
        }
    }
    return -1;
}

/* Every product, every node: 1018h:04 reads the serial number the board
 * gave (not the table's), the same after a power cycle. */
static void test_every_product_reads_its_serial(void)
{
    for (size_t k = 0; product_list[k] != NULL; k++) {
        h_boot(d, product_list[k], false);
        d->serial[0] = 0x5E000010u;
        d->serial[1] = 0x5E000011u;
        h_power_cycle(d);
        for (unsigned i = 0; i < d->nnodes; i++) {
            CHECK_EQ(co_node_serial(d->nodes[i]), 0x5E000010u + i);
            CHECK_EQ(read_serial(i), 0x5E000010ll + i);
        }
        h_power_cycle(d);
        CHECK_EQ(read_serial(d->nnodes - 1u), 0x5E000010ll + d->nnodes - 1u);
    }
}

/* LSS (the JD): switch state selective answers only to the address with
 * this unit's serial; the table's default serial selects nothing. */
static void test_lss_address_has_the_serial(void)
{
    h_boot(d, &jd2xxx, false);
    d->serial[0] = 0x00ABCDEFu;
    h_power_cycle(d);
    h_drain(d);
    static const char *const own[] = {"40 6D 66 69 00 00 00 00", "41 00 00 00 00 00 00 00",
                                      "42 00 00 01 00 00 00 00", "43 EF CD AB 00 00 00 00"};
    static const char *const table[] = {"40 6D 66 69 00 00 00 00", "41 00 00 00 00 00 00 00",
                                        "42 00 00 01 00 00 00 00", "43 01 D0 00 00 00 00 00"};
    /* (D001h: the serial every JD had before each got its own) */
    for (unsigned i = 0; i < 4u; i++) {
        h_rx(d, 0x7E5, table[i]);
    }
    EXPECT_NONE(d);
    for (unsigned i = 0; i < 4u; i++) {
        h_rx(d, 0x7E5, own[i]);
    }
    EXPECT(d, 0x7E4, "44 00 00 00 00 00 00 00");
    EXPECT_NONE(d);
    h_rx(d, 0x7E5, "5D 00 00 00 00 00 00 00"); /* inquire serial number */
    EXPECT(d, 0x7E4, "5D EF CD AB 00 00 00 00");
}

/* Without a serial from the board 1018h:04 reads 0; 0 and a running node
 * are a broken contract that changes nothing. */
static void test_serial_contract(void)
{
    h_boot(d, &jd2xxx, false);
    CHECK_EQ(co_node_serial(d->node), 0);
    CHECK_EQ(read_serial(0), 0);
    unsigned before = h_asserts;
    h_expect_assert(1);
    co_node_set_serial(d->node, 0x1234u); /* running */
    CHECK_EQ(h_asserts, before + 1u);
    CHECK_EQ(read_serial(0), 0);
    d->serial[0] = 7u;
    h_power_cycle(d);
    CHECK_EQ(read_serial(0), 7);
    /* 0 before the start: refused, the table's default stays. */
    co_node_t probe;
    void *const ram[CO_CLS_COUNT] = {NULL, NULL, NULL, NULL};
    co_node_init(&probe, jd2xxx.cfg, &d->port, NULL, ram, 0);
    h_expect_assert(1);
    co_node_set_serial(&probe, 0);
    CHECK_EQ(h_asserts, before + 2u);
    CHECK_EQ(co_node_serial(&probe), 0);
    co_node_set_serial(&probe, 9u);
    CHECK_EQ(co_node_serial(&probe), 9);
}

/* Without one the config's default holds (the product's manual). */
static void test_without_one_the_config_default(void)
{
    h_boot(d, &jd2xxx, false);
    CHECK_EQ(co_node_id(d->node), 10);
    CHECK_EQ(co_node_factory_id(d->node), 10);
    CHECK_EQ(h_read(d, 0x3000, 0), 9);
}

/* JD: 3000h holds node-ID - 1; its default is the factory node-ID's. A
 * saved node number survives power cycles; 0x1011 "load" goes back. */
static void test_jd_restore_defaults_returns_to_it(void)
{
    h_boot_ids(d, &jd2xxx, ids);
    CHECK_EQ(h_read(d, 0x3000, 0), 0x20);
    SDO(d, "22 00 30 00 31 00 00 00", "60 00 30 00 00 00 00 00");
    SDO(d, "22 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    h_power_cycle(d);
    CHECK_EQ(co_node_id(d->node), 50);
    SDO(d, "22 11 10 01 6C 6F 61 64", "60 11 10 01 00 00 00 00");
    h_power_cycle(d);
    CHECK_EQ(co_node_id(d->node), 0x21);
    CHECK_EQ(h_read(d, 0x3000, 0), 0x20);
}

/* DST: node-ID pair 0x20F0/0x20F1 (LSS set); 0x1011 and reset node go back. */
static void test_dst_restore_defaults_returns_to_it(void)
{
    h_boot_ids(d, &dst_x730_xy30, ids);
    SDO(d, "2F F0 20 00 06 00 00 00", "60 F0 20 00 00 00 00 00");
    SDO(d, "2F F1 20 00 06 00 00 00", "60 F1 20 00 00 00 00 00");
    SDO(d, "23 10 10 01 73 61 76 65", "60 10 10 01 00 00 00 00");
    h_power_cycle(d);
    CHECK_EQ(co_node_id(d->node), 6);
    SDO(d, "23 11 10 01 6C 6F 61 64", "60 11 10 01 00 00 00 00");
    h_drain(d);
    h_rx(d, 0x000, "81 06");
    EXPECT(d, 0x721, "00");
}

/* GSH redundant: two nodes, each its own factory node-ID in 0x3001. */
static void test_gsh_two_nodes(void)
{
    h_boot_ids(d, &gsh_a_redundant, ids);
    CHECK_EQ(co_node_id(d->nodes[0]), 0x21);
    CHECK_EQ(co_node_id(d->nodes[1]), 0x22);
    CHECK_EQ(h_read(d, 0x3001, 0), 0x21);
}

/* P+F: 0x2000 (LSS set) has the factory node-ID as its default. */
static void test_pf_object_default(void)
{
    h_boot_ids(d, &pf_inx360d, ids);
    CHECK_EQ(h_read(d, 0x2000, 0), 0x21);
}

/* The contract: only before the start (NMT state INIT), only 1..127. */
static void test_contract(void)
{
    h_boot(d, &jd2xxx, false);
    h_expect_assert(1);
    co_node_set_factory_id(d->node, 0x30); /* running: refused */
    CHECK_EQ(h_asserts, 1);
    CHECK_EQ(co_node_factory_id(d->node), 10);
    co_node_t n;
    void *ram[CO_CLS_COUNT] = {0};
    co_node_init(&n, d->node->cfg, &d->port, NULL, ram, 0);
    h_expect_assert(2);
    co_node_set_factory_id(&n, 0);
    co_node_set_factory_id(&n, 128);
    CHECK_EQ(h_asserts, 3);
    CHECK_EQ(co_node_factory_id(&n), 10);
    co_node_set_factory_id(&n, 127);
    CHECK_EQ(co_node_factory_id(&n), 127);
    CHECK_EQ(co_node_id(&n), 127);
}

int main(void)
{
    RUN(test_every_product_boots_on_its_factory_id);
    RUN(test_without_one_the_config_default);
    RUN(test_jd_restore_defaults_returns_to_it);
    RUN(test_dst_restore_defaults_returns_to_it);
    RUN(test_gsh_two_nodes);
    RUN(test_pf_object_default);
    RUN(test_contract);
    RUN(test_every_product_reads_its_serial);
    RUN(test_lss_address_has_the_serial);
    RUN(test_serial_contract);
    return h_finish();
}
