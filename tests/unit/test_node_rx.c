/*
 * test_node_rx.c - co_node_rx_ids(): the CAN-IDs a node consumes, the list
 * a board's receive filter (the Linux port's CAN_RAW_FILTER) is built
 * from. On every product and node: what the list holds, and that every
 * frame outside it leaves the node exactly as it was (so a filter that
 * drops it loses nothing); again after the SYNC COB-ID, a TPDO COB-ID, the
 * heartbeat consumer and the node-ID (LSS) changed.
 */
#include "dst.h"
#include "harness.h"
#include "jd.h"
#include "pf.h"

static h_dev_t dev;
static h_dev_t *const d = &dev;

static void boot(const product_t *p)
{
    h_boot(d, p, false);
    h_advance(d, 1000);
    h_drain(d);
}

static unsigned list(co_node_t *node, co_rx_id_t ids[CO_NODE_RX_IDS_MAX])
{
    unsigned n = co_node_rx_ids(node, ids, CO_NODE_RX_IDS_MAX);
    CHECK(n <= CO_NODE_RX_IDS_MAX);
    return n < CO_NODE_RX_IDS_MAX ? n : CO_NODE_RX_IDS_MAX;
}

/* 1: (id, rtr) passes the list (an entry passes the frames of its kind only). */
static bool passes(const co_rx_id_t *ids, unsigned n, uint16_t id, bool rtr)
{
    for (unsigned k = 0; k < n; k++) {
        if (ids[k].id == id && ids[k].rtr == rtr) {
            return true;
        }
    }
    return false;
}

static bool has(const co_rx_id_t *ids, unsigned n, uint16_t id, bool rtr)
{
    for (unsigned k = 0; k < n; k++) {
        if (ids[k].id == id && ids[k].rtr == rtr) {
            return true;
        }
    }
    return false;
}

/* Every classic frame a filter from the list drops (each CAN-ID, data and
 * remote, 0, 1, 2 and 8 bytes) leaves the node as it was and sends
 * nothing. Returns the frames tried. */
static unsigned dropped_frames_unused(co_node_t *node)
{
    co_rx_id_t ids[CO_NODE_RX_IDS_MAX];
    unsigned n = list(node, ids);
    static const uint8_t lens[] = {0, 1, 2, 8};
    unsigned tried = 0;
    for (uint16_t id = 0; id < 0x800u; id++) {
        for (unsigned r = 0; r < 2u; r++) {
            if (passes(ids, n, id, r != 0u)) {
                continue;
            }
            for (unsigned l = 0; l < sizeof(lens); l++) {
                co_frame_t f = {.id = id,
                                .rtr = r != 0u,
                                .dlc = lens[l],
                                .data = {0x01, 0x40, 0x05, 0, 0, 0, 0, 0}};
                if (id == 0x000u) {
                    f.data[1] = 0; /* NMT to all nodes (in the list anyway) */
                }
                co_node_t before = *node;
                unsigned ntx = d->port.ntx;
                co_node_receive(node, &f, node->now);
                node->dirty = before.dirty;
                if (memcmp(&before, node, sizeof(before)) != 0 || d->port.ntx != ntx) {
                    fprintf(stderr, "  %s: frame %03X rtr %u dlc %u outside the list was used\n",
                            d->prod->id, id, r, f.dlc);
                    FAIL("a frame the filter drops changed the node");
                    return tried;
                }
                tried++;
            }
        }
    }
    return tried;
}

/* Every product, every node, pre-operational and operational: the fixed
 * entries, and nothing outside the list serves the node. */
static void test_rx_ids_every_product(void)
{
    for (size_t i = 0; product_list[i] != NULL; i++) {
        const product_t *p = product_list[i];
        boot(p);
        for (unsigned k = 0; k < d->nnodes; k++) {
            co_node_t *node = d->nodes[k];
            co_rx_id_t ids[CO_NODE_RX_IDS_MAX];
            unsigned n = list(node, ids);
            uint8_t id = co_node_id(node);
            CHECK(has(ids, n, 0x000, false));
            CHECK(has(ids, n, 0x600u + id, false));
            CHECK(has(ids, n, node->sync.cob_id, false));
            CHECK_EQ(has(ids, n, 0x7E5, false), co_cfg_has_service(node->cfg, &co_lss_service));
            for (unsigned a = 0; a < n; a++) {
                CHECK(ids[a].id <= 0x7FFu);
                for (unsigned b = a + 1u; b < n; b++) {
                    CHECK(ids[a].id != ids[b].id || ids[a].rtr != ids[b].rtr);
                }
            }
            CHECK(dropped_frames_unused(node) > 4000u);
        }
        h_rx(d, 0x000, "01 00"); /* all nodes operational */
        h_drain(d);
        for (unsigned k = 0; k < d->nnodes; k++) {
            CHECK_EQ(co_node_nmt_state(d->nodes[k]), CO_NMT_OPERATIONAL);
            CHECK(dropped_frames_unused(d->nodes[k]) > 4000u);
        }
    }
}

/* A list cut at max: the full count comes back, nothing beyond max is written. */
static void test_rx_ids_cut(void)
{
    boot(&jd2xxx);
    co_rx_id_t ids[3] = {{0}, {0}, {.id = 0xABC, .rtr = true}};
    unsigned n = co_node_rx_ids(d->node, ids, 2);
    CHECK(n > 2u);
    CHECK_EQ(ids[0].id, 0x000);
    CHECK_EQ(ids[2].id, 0xABC);
    CHECK(ids[2].rtr);
}

/* Each (CAN-ID, kind) once: two RTR TPDOs on one COB-ID give one entry
 * (the node's TPDOs set by hand: the dictionary may allow it). And a list
 * cut at max (no duplicates) counts every entry and never reads past max:
 * the caller's entry there (here a copy of the third entry) is no reason
 * to leave that ID out. */
static void test_rx_ids_once_each(void)
{
    unsigned tried = 0;
    for (size_t i = 0; product_list[i] != NULL; i++) {
        boot(product_list[i]);
        co_node_t *node = d->node;
        co_rx_id_t ids[CO_NODE_RX_IDS_MAX];
        unsigned n = list(node, ids);
        CHECK(n >= 3u); /* NMT, SYNC, SDO at least */
        co_rx_id_t cut[2] = {{0}, ids[2]};
        CHECK_EQ(co_node_rx_ids(node, cut, 1), n);
        CHECK_EQ(cut[0].id, 0x000);
        CHECK(cut[1].id == ids[2].id && cut[1].rtr == ids[2].rtr);
        for (unsigned k = 0; k < CO_TPDO_MAX; k++) {
            co_tpdo_t *t = &node->tpdo[k];
            if (!t->valid || !t->rtr_allowed || !has(ids, n, t->cob_id, true)) {
                continue;
            }
            unsigned other = k == 0u ? 1u : 0u;
            if (other >= CO_TPDO_MAX) {
                break;
            }
            node->tpdo[other] = *t; /* the same COB-ID, RTR allowed */
            n = list(node, ids);
            unsigned count = 0;
            for (unsigned a = 0; a < n; a++) {
                count += ids[a].id == t->cob_id && ids[a].rtr ? 1u : 0u;
                for (unsigned b = a + 1u; b < n; b++) {
                    CHECK(ids[a].id != ids[b].id || ids[a].rtr != ids[b].rtr);
                }
            }
            CHECK_EQ(count, 1);
            tried++;
            break;
        }
    }
    CHECK(tried > 0u); /* some product answers RTRs */
}

/* A node without a node-ID (LSS: 255) takes no SDO requests (no 0x6FF);
 * node-ID 127 does (0x67F). Guarding and the heartbeat consumer by their
 * state (set by hand here). */
static void test_rx_ids_conditions(void)
{
    boot(&jd2xxx);
    co_rx_id_t ids[CO_NODE_RX_IDS_MAX];
    uint8_t own = d->node->node_id;
    d->node->node_id = 0xFF;
    unsigned n = list(d->node, ids);
    for (unsigned k = 0; k < n; k++) {
        CHECK(ids[k].id < 0x600u || ids[k].id > 0x6FFu);
    }
    CHECK(!has(ids, n, 0x7FF, true)); /* nor guarding */
    d->node->node_id = 0;             /* below 1..127: no node-ID either */
    n = list(d->node, ids);
    CHECK(!has(ids, n, 0x600, false));
    CHECK(!has(ids, n, 0x700, true));
    d->node->node_id = 127;
    n = list(d->node, ids);
    CHECK(has(ids, n, 0x67F, false));
    d->node->node_id = own;
    /* Guarding's RTR only while guarding runs; the heartbeat consumer's ID
     * for any producer node-ID, 1 too. */
    d->node->guard.enabled = false;
    n = list(d->node, ids);
    CHECK(!has(ids, n, (uint16_t)(0x700u + own), true));
    d->node->guard.enabled = true;
    n = list(d->node, ids);
    CHECK(has(ids, n, (uint16_t)(0x700u + own), true));
    d->node->hbc.node_id = 1;
    d->node->hbc.time_ms = 100;
    n = list(d->node, ids);
    CHECK(has(ids, n, 0x701, false));
    d->node->hbc.time_ms = 1;
    n = list(d->node, ids);
    CHECK(has(ids, n, 0x701, false));
    d->node->hbc.time_ms = 0;
    n = list(d->node, ids);
    CHECK(!has(ids, n, 0x701, false));
    d->node->hbc.node_id = 0; /* a time without a producer: off too */
    d->node->hbc.time_ms = 100;
    n = list(d->node, ids);
    CHECK(!has(ids, n, 0x700, false));
    /* A TPDO whose COB-ID forbids RTR (bit 30 set) is not listed for one. */
    d->node->tpdo[0].valid = true;
    d->node->tpdo[0].rtr_allowed = false;
    n = list(d->node, ids);
    CHECK(!has(ids, n, d->node->tpdo[0].cob_id, true));
    d->node->tpdo[0].rtr_allowed = true;
    n = list(d->node, ids);
    CHECK(has(ids, n, d->node->tpdo[0].cob_id, true));
    d->node->tpdo[0].valid = false; /* an invalid TPDO answers no RTR */
    n = list(d->node, ids);
    CHECK(!has(ids, n, d->node->tpdo[0].cob_id, true));
    /* A product without the RTR service (DST X730) lists no TPDO's RTR,
     * even with its COB-ID's bit 30 clear. */
    boot(&dst_x730_xy10);
    d->node->tpdo[0].valid = true;
    d->node->tpdo[0].rtr_allowed = true;
    n = list(d->node, ids);
    CHECK(!has(ids, n, d->node->tpdo[0].cob_id, true));
}

/* The list follows SDO writes of the SYNC COB-ID, a TPDO COB-ID and the
 * heartbeat consumer, and a node-ID set by LSS at reset communication. */
static void test_rx_ids_follow_changes(void)
{
    co_rx_id_t ids[CO_NODE_RX_IDS_MAX];
    boot(&jd2xxx); /* node 0x0A: LSS, guarding, heartbeat consumer, RTR */
    unsigned n = list(d->node, ids);
    CHECK(has(ids, n, 0x080, false));
    CHECK(has(ids, n, 0x60A, false));
    CHECK(has(ids, n, 0x70A, true)); /* guarding: remote frames only */
    CHECK(has(ids, n, 0x18A, true)); /* TPDO 1 on request */
    CHECK(!passes(ids, n, 0x18A, false));
    CHECK(!passes(ids, n, 0x705, false));
    SDO(d, "23 05 10 00 81 00 00 00", "60 05 10 00 00 00 00 00"); /* SYNC on 0x081 */
    n = list(d->node, ids);
    CHECK(has(ids, n, 0x081, false));
    CHECK(!passes(ids, n, 0x080, false));
    SDO(d, "23 16 10 01 64 00 0A 00", "60 16 10 01 00 00 00 00"); /* watch 0x0A: its own ID */
    n = list(d->node, ids);
    CHECK(has(ids, n, 0x70A, false)); /* one CAN-ID, both kinds: two entries */
    CHECK(has(ids, n, 0x70A, true));
    CHECK(dropped_frames_unused(d->node) > 4000u);
    SDO(d, "23 16 10 01 64 00 05 00", "60 16 10 01 00 00 00 00"); /* watch node 5 */
    n = list(d->node, ids);
    CHECK(has(ids, n, 0x705, false));
    CHECK(!passes(ids, n, 0x705, true));
    CHECK(!passes(ids, n, 0x70A, false));
    SDO(d, "23 00 18 01 8A 01 00 C0", "60 00 18 01 00 00 00 00"); /* TPDO 1: no RTR */
    n = list(d->node, ids);
    CHECK(!passes(ids, n, 0x18A, true));
    CHECK(dropped_frames_unused(d->node) > 4000u);
    /* LSS: node-ID 0x25, active from reset communication on. */
    h_rx(d, 0x7E5, "04 01 00 00 00 00 00 00");
    h_rx(d, 0x7E5, "11 25 00 00 00 00 00 00");
    h_rx(d, 0x7E5, "04 00 00 00 00 00 00 00");
    n = list(d->node, ids);
    CHECK(has(ids, n, 0x60A, false)); /* not yet */
    h_rx(d, 0x000, "82 00");
    h_drain(d);
    CHECK_EQ(co_node_id(d->node), 0x25);
    n = list(d->node, ids);
    CHECK(has(ids, n, 0x625, false));
    CHECK(!passes(ids, n, 0x60A, false));
    CHECK(has(ids, n, 0x725, true));
    CHECK(dropped_frames_unused(d->node) > 4000u);
    /* Without a node-ID (LSS 0xFF): NMT, SYNC and LSS only, no SDO. */
    h_rx(d, 0x7E5, "04 01 00 00 00 00 00 00");
    h_rx(d, 0x7E5, "11 FF 00 00 00 00 00 00");
    h_rx(d, 0x7E5, "04 00 00 00 00 00 00 00");
    h_rx(d, 0x000, "82 00");
    h_drain(d);
    CHECK_EQ(co_node_id(d->node), CO_LSS_UNCONFIGURED);
    n = list(d->node, ids);
    CHECK(has(ids, n, 0x7E5, false));
    CHECK(!passes(ids, n, 0x625, false));
    CHECK(dropped_frames_unused(d->node) > 4000u);
    /* A product without LSS or RTR service: the P+F's guarding and RTR. */
    boot(&pf_inx360d);
    n = list(d->node, ids);
    CHECK(!has(ids, n, 0x7E5, false));
    CHECK(has(ids, n, (uint16_t)(0x700u + co_node_id(d->node)), true));
}

int main(void)
{
    RUN(test_rx_ids_every_product);
    RUN(test_rx_ids_cut);
    RUN(test_rx_ids_once_each);
    RUN(test_rx_ids_conditions);
    RUN(test_rx_ids_follow_changes);
    return h_finish();
}
