/*
 * app.c - the program's instances and their wiring; see app.h.
 */
#include "app.h"

#include <string.h>

#include "log.h"

int app_add(app_t *a, const product_t *prod, const char *const ifn[], uint8_t id, uint32_t serial)
{
    unsigned k = a->ninst;
    app_inst_t *in = &a->inst[k];
    if (prod->inst_size > sizeof(in->mem) || k >= APP_MAX_NODES ||
        a->nnodes + prod->nodes > APP_MAX_NODES) {
        return -1;
    }
    in->prod = prod;
    in->first = a->nnodes;
    sim_init(&in->sim, prod);
    void *ports[PRODUCT_MAX_NODES];
    for (unsigned i = 0; i < prod->nodes; i++) {
        unsigned g = in->first + i;
        a->node_inst[g] = (uint8_t)k;
        a->ifn[g] = ifn[i];
        a->ports[g].nvm = &in->nvm; /* the device's EEPROM, both nodes' */
        ports[i] = &a->ports[g];
    }
    /* create() only keeps the port pointers (co_node_init calls no board
     * function): the factory node-IDs are checked for clashes and name the
     * EEPROM files, which are looked at before any socket opens (a FIFO
     * must not hang the start). */
    prod->create(prod, in->mem, ports, &a->nodes[in->first]);
    a->nnodes += prod->nodes;
    a->ninst++;
    for (unsigned i = 0; i < prod->nodes && id != 0u; i++) {
        co_node_set_factory_id(a->nodes[in->first + i], (uint8_t)(id + i));
    }
    /* Each node its own serial number, so that LSS can address it (CiA 305). */
    for (unsigned i = 0; i < prod->nodes; i++) {
        unsigned g = in->first + i;
        co_node_set_serial(a->nodes[g], serial != 0u
                                            ? serial + g
                                            : app_derived_serial(prod->id, a->ifn[g],
                                                                 co_node_factory_id(a->nodes[g])));
    }
    return (int)k;
}

/*
 * FNV-1a over the product ID, interface and factory node-ID (all three
 * fixed by the command line, so the same at every start), 0 taken as 1.
 * Two nodes of one process differ in one of them (one factory node-ID
 * twice on one interface is refused), so their LSS addresses differ but
 * for a 32-bit hash collision.
 */
uint32_t app_derived_serial(const char *product, const char *iface, uint8_t id)
{
    uint32_t h = 2166136261u;
    const char *parts[2] = {product, iface};
    for (unsigned k = 0; k < 2u; k++) {
        for (const char *c = parts[k]; *c != '\0'; c++) {
            h = (h ^ (uint8_t)*c) * 16777619u;
        }
        h *= 16777619u; /* a separator: "ab"+"c" is not "a"+"bc" */
    }
    h = (h ^ id) * 16777619u;
    return h != 0u ? h : 1u;
}

void app_sync_can_state(app_t *a, unsigned node)
{
    co_can_state_t s = lp_can_state(&a->ports[node]);
    if (s != co_node_can_state(a->nodes[node])) {
        co_node_set_can_state(a->nodes[node], s);
    }
}

void app_sim_can(app_t *a, unsigned node, co_can_state_t s, uint32_t hold_ms, uint32_t now)
{
    lp_sim_can_command(&a->ports[node], s, now, hold_ms);
    app_sync_can_state(a, node);
}

void app_unplug(app_t *a, unsigned node, bool on, uint32_t hold_ms, uint32_t now)
{
    if (on) {
        lp_unplug(&a->ports[node], now, hold_ms);
    } else {
        lp_unplug_off(&a->ports[node]);
    }
}

void app_heartbeat(app_t *a, unsigned node, bool on)
{
    lp_heartbeat(&a->ports[node], on);
}

void app_sample(app_t *a, uint32_t t)
{
    for (unsigned k = 0; k < a->ninst; k++) {
        sim_t *sm = &a->inst[k].sim;
        sim_step(sm, t); /* the world moves on */
        if (a->inst[k].progdl && !lp_prog_running(&a->inst[k].prog)) {
            continue; /* but a halted program does not read the sensor */
        }
        a->inst[k].prod->sample(a->inst[k].mem, sm->values, sm->faults);
    }
}

void app_start(app_t *a, uint32_t t)
{
    for (unsigned i = 0; i < a->nnodes; i++) {
        const product_t *prod = a->inst[a->node_inst[i]].prod;
        co_node_start(a->nodes[i], t);
        lp_log("node %u: %s, node-ID 0x%02X on %s, bit-rate code %u = %u kbit/s (%s); factory "
               "node-ID 0x%02X, serial 0x%08lX",
               i, prod->id, co_node_id(a->nodes[i]), a->ifn[i], co_node_bitrate(a->nodes[i]),
               product_kbps(prod, co_node_bitrate(a->nodes[i])),
               a->ports[i].udp ? "a udp_multicast bus has none" : "vcan ignores it",
               co_node_factory_id(a->nodes[i]), (unsigned long)co_node_serial(a->nodes[i]));
    }
}

void app_udp_receive(app_t *a, unsigned reader, uint32_t t)
{
    lp_port_t *r = &a->ports[reader];
    /* Two batches at most, then the timers again (as a CAN port's 64). */
    for (int b = 0; b < 2; b++) {
        unsigned n = lp_udp_batch(r, t);
        if (n == 0u) {
            break;
        }
        /* Frame by frame, each to every node on the group in turn: the
         * order of the bus, as SocketCAN delivers it to each socket. */
        for (unsigned k = 0; k < n; k++) {
            for (unsigned i = 0; i < a->nnodes; i++) {
                co_frame_t f;
                if (a->ports[i].udp && a->ports[i].udp_reader == reader &&
                    lp_udp_take(&a->ports[i], r, k, &f) == 1) {
                    co_node_receive(a->nodes[i], &f, t);
                }
            }
        }
    }
    for (unsigned i = 0; i < a->nnodes; i++) {
        if (a->ports[i].udp && a->ports[i].udp_reader == reader) {
            app_sync_can_state(a, i);
        }
    }
}

uint32_t app_poll(app_t *a, uint32_t t, uint32_t wait, bool *backlog)
{
    for (unsigned i = 0; i < a->nnodes; i++) {
        wait = co_min_u32(wait, lp_poll(&a->ports[i], t));
        app_sync_can_state(a, i);
        wait = co_min_u32(wait, co_node_poll(a->nodes[i], t));
        lp_filter(&a->ports[i], a->nodes[i]); /* the CAN-IDs it consumes now (can_port.h) */
        bool g;
        bool rd;
        uint32_t led_next;
        co_led_pattern_t gp;
        co_led_pattern_t rp;
        co_node_leds(a->nodes[i], t, &g, &rd, &led_next);
        co_node_led_patterns(a->nodes[i], &gp, &rp);
        leds_set(&a->leds[i], i, g, rd, gp, rp);
        wait = co_min_u32(wait, led_next);
    }
    for (unsigned k = 0; k < a->ninst; k++) {
        wait = co_min_u32(wait, lp_nvm_renew(&a->inst[k].nvm, t)); /* the hold's lease */
    }
    /* What the nodes sent in this pass and before it (answers to frames
     * received since the last pass), in one go. */
    *backlog = lp_tx_flush(&a->tx, a->ports, a->nnodes) > 0u;
    for (unsigned i = 0; i < a->nnodes; i++) {
        app_sync_can_state(a, i); /* a write may have found the link gone */
    }
    return wait;
}

const char *app_nmt_name(const app_t *a, unsigned node)
{
    static const char *const names[] = {[0x00] = "initialising",
                                        [0x04] = "stopped",
                                        [0x05] = "operational",
                                        [0x7F] = "pre-operational"};
    uint8_t s = (uint8_t)co_node_nmt_state(a->nodes[node]);
    return (s < sizeof(names) / sizeof(names[0]) && names[s]) ? names[s] : "?";
}

/*
 * Two nodes of this process with one active node-ID on one interface:
 * logged (a warning each time the node-IDs change into a clash), nothing
 * else. The command line's factory node-IDs are checked at start (exit
 * 2), but a stored node-ID, an SDO write or LSS can make a clash later;
 * the nodes run on, as real devices would, and their frames collide on
 * the bus: the log says why.
 */
static void log_id_clashes(const app_t *a)
{
    for (unsigned i = 0; i < a->nnodes; i++) {
        uint8_t id = co_node_id(a->nodes[i]);
        for (unsigned j = 0; j < i && id >= 1u && id <= CO_NODE_ID_MAX; j++) {
            if (co_node_id(a->nodes[j]) == id && strcmp(a->ifn[i], a->ifn[j]) == 0) {
                lp_log("warning: node %u (%s) and node %u (%s) both have node-ID 0x%02X on %s: "
                       "their frames collide",
                       j, a->inst[a->node_inst[j]].prod->id, i, a->inst[a->node_inst[i]].prod->id,
                       id, a->ifn[i]);
            }
        }
    }
}

void app_log_states(app_t *a)
{
    bool ids_changed = false;
    for (unsigned i = 0; i < a->nnodes; i++) {
        uint8_t s = (uint8_t)co_node_nmt_state(a->nodes[i]);
        if (s != a->last_state[i]) {
            lp_log("node %u (ID 0x%02X): NMT %s", i, co_node_id(a->nodes[i]), app_nmt_name(a, i));
            a->last_state[i] = s;
        }
        uint8_t id = co_node_id(a->nodes[i]);
        if (id != a->last_id[i]) {
            a->last_id[i] = id;
            ids_changed = true;
        }
    }
    if (ids_changed) {
        log_id_clashes(a);
    }
}

/* The stack flags an unusable stored set over CAN too, per product
 * (0x4001, EMCY, LEDs); the log says which file and why. */
void app_log_store_status(const app_t *a)
{
    static const struct {
        co_cls_t cls;
        const char *what;
    } sets[] = {{CO_CLS_PARA, "parameters"}, {CO_CLS_LSS, "node-ID and bit rate"}};
    for (unsigned i = 0; i < a->nnodes; i++) {
        const lp_nvm_t *nvm = &a->inst[a->node_inst[i]].nvm;
        const char *file = nvm->path != NULL ? nvm->real : "(RAM)";
        for (unsigned k = 0; k < sizeof(sets) / sizeof(sets[0]); k++) {
            if (co_cfg(a->nodes[i])->ram_size[sets[k].cls] == 0u) {
                continue;
            }
            co_store_status_t st = co_node_store_status(a->nodes[i], sets[k].cls);
            if (st == CO_STORE_CORRUPT || st == CO_STORE_HW) {
                lp_log("node %u: EEPROM file %s: stored %s %s: factory defaults in use until "
                       "the next save (the file is left as it is until then)",
                       i, file, sets[k].what,
                       st == CO_STORE_CORRUPT ? "corrupt (neither blank nor a valid record)"
                                              : "unreadable (read error)");
            }
        }
    }
}

void app_shut_down(app_t *a)
{
    /* An orderly stop is not a power cut: what a product stores on its own
     * after a pause (co_store_poll) is stored now, not lost with the
     * process. SIGKILL is the power cut, and loses it as a device would. */
    for (unsigned i = 0; i < a->nnodes; i++) {
        co_store_flush(a->nodes[i]);
    }
    if (a->nnodes != 0u) {
        (void)lp_tx_flush(&a->tx, a->ports, a->nnodes);
        lp_log("%lu frames sent in %lu system calls", a->tx.frames, a->tx.calls);
    }
    for (unsigned i = 0; i < a->nnodes; i++) {
        lp_port_t *p = &a->ports[i];
        leds_close(&a->leds[i], i); /* both LEDs off */
        lp_report_drops(p);
        lp_log("node %u: %lu frames received, %lu dropped by the kernel (receive queue full)", i,
               p->rx_frames, p->rx_dropped);
        if (co_node_tx_dropped(a->nodes[i]) != 0u) {
            lp_log("node %u: %u frames could not be sent (%lu while off the bus)", i,
                   co_node_tx_dropped(a->nodes[i]), p->tx_off);
        }
        lp_close(p);
    }
    lp_tx_close(&a->tx);
    app_release_nvm(a);
    lp_log("stopped");
}

void app_release_nvm(app_t *a)
{
    for (unsigned k = 0; k < a->ninst; k++) {
        if (a->inst[k].progdl) {
            lp_prog_close(&a->inst[k].prog); /* a download's file: the next start removes it */
        }
        lp_nvm_unlock(&a->inst[k].nvm); /* the EEPROM files free for the next user */
    }
}
