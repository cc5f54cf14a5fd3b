/*
 * mcu_main.c - the bare-metal main loop shared by the MCU boards: one
 * product (PRODUCT_SYM, chosen at build time), its instance in static
 * storage, the sensor sampled every CO_FILTER_PERIOD_US, the node polled,
 * received frames fed in, LEDs driven, and the core asleep in between.
 */
#include "board.h"
#include "boot.h"
#include "co_filter.h"
#include "co_node.h"
#include "product.h"

#ifdef PRODUCT_HEADER
#include PRODUCT_HEADER /* the product family's instance type, for PRODUCT_INST_SIZE */
#endif

#ifndef PRODUCT_SYM
#error "build with -DPRODUCT_SYM=<product symbol> (see boards/CMakeLists.txt)"
#endif
#ifndef PRODUCT_INST_SIZE
#error "build with -DPRODUCT_INST_SIZE=<bytes>"
#endif

extern const product_t PRODUCT_SYM;

/* The stack's bit-rate requests (at start, after a reset that activated
 * another code, LSS activate bit timing) go to the board; an unusable code
 * (0 kbit/s) gets the common default, 250 kbit/s, so that the node is on
 * the bus somewhere. A rate the controller refuses leaves it where it was
 * (the boards here take every bit rate the products name). */
bool co_port_can_bitrate(void *port, uint16_t kbps)
{
    (void)port;
    return board_can_bitrate(kbps != 0u ? kbps : 250u);
}

/* The LEDs; not inlined, so that its locals are not part of main's frame,
 * on which every other call of the loop stacks. Returns the delay until
 * either LED changes. */
static CO_NOINLINE uint32_t leds(co_node_t *node, uint32_t now)
{
    bool g;
    bool r;
    uint32_t next;
    co_node_leds(node, now, &g, &r, &next);
    board_leds(g, r);
    return next;
}

#ifdef BOARD_RX_FILTER
/* The nodes' receive lists together, to the board's acceptance filter. */
static CO_NOINLINE void rx_filter(co_node_t *const nodes[], unsigned n)
{
    co_rx_id_t ids[PRODUCT_MAX_NODES * CO_NODE_RX_IDS_MAX];
    unsigned k = 0;
    for (unsigned i = 0; i < n; i++) {
        k += co_node_rx_ids(nodes[i], &ids[k], CO_NODE_RX_IDS_MAX); /* never more */
    }
    board_can_filter(ids, k);
}
#endif

int main(void)
{
    /* The instance: static storage of this image's one product, sized for it.
     * Board code, not the stack: the stack itself holds no globals. */
    static _Alignas(8) unsigned char mem[PRODUCT_INST_SIZE];
    static int32_t values[PRODUCT_MAX_INPUTS];
    const product_t *p = &PRODUCT_SYM;
    co_node_t *nodes[PRODUCT_MAX_NODES];
    void *ports[PRODUCT_MAX_NODES] = {NULL, NULL};
    uint32_t faults = 0;

    if (!board_init()) {
        for (;;) {
            board_leds(false, true);
        }
    }
    p->create(p, mem, ports, nodes);
    for (unsigned i = 0; i < p->nodes; i++) {
        co_node_set_serial(nodes[i], board_serial(i)); /* the unit's own LSS address */
    }
#ifdef CO_FIXED_CFG
    for (unsigned i = 0; i < p->nodes; i++) {
        if (nodes[i]->cfg != &CO_FIXED_CFG) { /* the build paired it with another config */
            for (;;) {
                board_leds(false, true);
            }
        }
    }
#endif
    board_sensor(p, values, &faults);
    p->sample(mem, values, faults);
    uint32_t now = board_now_us();
    for (unsigned i = 0; i < p->nodes; i++) {
        co_node_start(nodes[i], now); /* brings the controller to its bit rate */
    }
    uint32_t next_sample = now + CO_FILTER_PERIOD_US;
    for (;;) {
        now = board_now_us();
        if (!co_time_before(now, next_sample)) {
            board_sensor(p, values, &faults);
            p->sample(mem, values, faults);
            next_sample += CO_FILTER_PERIOD_US;
        }
        uint32_t wait = co_time_until(now, next_sample);
        co_frame_t f;
        while (board_can_receive(&f)) {
            for (unsigned i = 0; i < p->nodes; i++) {
                co_node_receive(nodes[i], &f, now);
            }
            if (p->nodes > 1u) { /* one flash: a request to one node delays every node's erase */
                co_store_share_pause(nodes, p->nodes);
            }
            for (unsigned i = 0; i < p->nodes; i++) {
                co_node_poll(nodes[i], now); /* what the frame left to do, before the next one */
            }
        }
#ifdef BOARD_RX_FILTER
        /* Before the board sends what the frames just received produced
         * (board_can_state): a boot-up under a new node-ID leaves with the
         * filter passing its SDO requests. */
        rx_filter(nodes, p->nodes);
#endif
        for (unsigned i = 0; i < p->nodes; i++) {
            co_node_set_can_state(nodes[i], (co_can_state_t)board_can_state());
            wait = co_min_u32(wait, co_node_poll(nodes[i], now));
        }
#ifdef BOARD_RX_FILTER
        rx_filter(nodes, p->nodes);
#endif
        boot_handover_poll(nodes[0]); /* after a stop, its answer on its way (board_can_state) */
        board_sleep(co_min_u32(wait, leds(nodes[0], now)));
    }
}
