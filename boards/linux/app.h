/*
 * app.h - the program's instances and their wiring: each product instance
 * (--product, or one --node) with its nodes, ports, LEDs, simulated inputs
 * and EEPROM file; the pass over the nodes; the state logs; teardown.
 * Nothing here parses a command line or a command (cli.h, cmd.h), and
 * nothing waits for events (loop.h).
 */
#ifndef LINUX_APP_H
#define LINUX_APP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "can_port.h"
#include "leds.h"
#include "nvm_file.h"
#include "product.h"
#include "product_registry.h"
#include "prog.h"
#include "sim.h"

/* Nodes in one process at most: one bus holds CO_NODE_ID_MAX node-IDs. */
#define APP_MAX_NODES CO_NODE_ID_MAX

/* Replay tables one line may load: one per product it names. */
#define APP_REPLAY_TABLES                                                                          \
    (sizeof((const product_t *const[]){PRODUCT_REGISTRY_ROWS PRODUCT_REGISTRY_EXAMPLES}) /         \
     sizeof(const product_t *))

/* One product instance: its nodes are app_t.nodes[first .. first +
 * prod->nodes - 1]; its own inputs (sim), its own EEPROM file (both nodes
 * of a two-node product share it, as they share the device). */
typedef struct app_inst {
    const product_t *prod;
    unsigned first;
    sim_t sim;
    lp_nvm_t nvm;
    uint8_t nvm_mem[PRODUCT_MAX_NODES * CO_STORE_NVM_SIZE];
    bool progdl;    /* --program-download: prog is in use */
    lp_prog_t prog; /* its program area and loader (prog.h) */
    _Alignas(max_align_t) unsigned char mem[sizeof(product_any_t)];
} app_inst_t;

typedef struct app app_t;

struct app {
    unsigned nnodes;
    unsigned ninst;
    uint8_t node_inst[APP_MAX_NODES]; /* each node's instance */
    co_node_t *nodes[APP_MAX_NODES];
    lp_port_t ports[APP_MAX_NODES];
    leds_t leds[APP_MAX_NODES];
    uint8_t last_state[APP_MAX_NODES];
    uint8_t last_id[APP_MAX_NODES]; /* active node-IDs last looked at (app_log_states) */
    const char *ifn[APP_MAX_NODES]; /* each node's interface */
    app_inst_t inst[APP_MAX_NODES];
    bool quit;                              /* stop the loop: `quit`, a signal, the end of input */
    lp_tx_t tx;                             /* the one sending socket (can_port.h) */
    sim_replay_t replay[APP_REPLAY_TABLES]; /* a `replay` line's tables (cmd.c) */
};

/*
 * Add an instance of prod whose node i is on interface ifn[i]: created in
 * its slot (not started), with its factory node-IDs (id, id + 1, ...; 0:
 * the product's) and serial numbers (serial + node index; 0: derived from
 * product, interface and factory node-ID, app_derived_serial). Returns the
 * instance's index, or -1 when the product's instance does not fit.
 */
int app_add(app_t *a, const product_t *prod, const char *const ifn[], uint8_t id, uint32_t serial);

/* A node's serial number without --serial: FNV-1a over its product ID,
 * interface and factory node-ID, never 0. */
uint32_t app_derived_serial(const char *product, const char *iface, uint8_t id);

/* The node sees the CAN state its port shows (link, error frames, simulator). */
void app_sync_can_state(app_t *a, unsigned node);

/* `unplug` (on, for hold_ms; 0: until `unplug off`) and `unplug off` (on
 * false) of a node's port; `heartbeat stop|start` (can_port.h). */
void app_unplug(app_t *a, unsigned node, bool on, uint32_t hold_ms, uint32_t now);
void app_heartbeat(app_t *a, unsigned node, bool on);

/* The simulated controller of node `node` goes to state s (bus-off: the
 * bus stays unusable hold_ms, then 128 x 11 bits at the node's bit rate). */
void app_sim_can(app_t *a, unsigned node, co_can_state_t s, uint32_t hold_ms, uint32_t now);

/* Every instance's motion advances to t, then it samples its inputs. */
void app_sample(app_t *a, uint32_t t);

/* Start every node at time t, each logged with its IDs and bit rate. */
void app_start(app_t *a, uint32_t t);

/* One pass over the nodes at time t: ports, CAN state, timers, LEDs, the
 * transmit queue. Returns the delay until one of them needs the next
 * pass (at most wait); *backlog tells that frames wait for the kernel. */
/* Datagrams on the udp_multicast socket of port reader (lp_udp_share), each
 * given to every node that shares it (can_port.h, lp_udp_take). */
void app_udp_receive(app_t *a, unsigned reader, uint32_t t);

uint32_t app_poll(app_t *a, uint32_t t, uint32_t wait, bool *backlog);

/* Node `node`'s NMT state as a word ("operational", ...). */
const char *app_nmt_name(const app_t *a, unsigned node);

/* NMT state changes in the log; node-ID changes checked for clashes. */
void app_log_states(app_t *a);

/* Which stored sets could not be used at the start, in the log. */
void app_log_store_status(const app_t *a);

/* Autosaved writes still waiting for their pause stored (co_store_flush),
 * what is queued sent, LEDs off, sockets closed, the counts in the log,
 * the EEPROM files' holds given back (app_release_nvm). */
void app_shut_down(app_t *a);

/* Give back the EEPROM files' holds (nvm_file.h), also after a failed
 * start: the instances that took none are skipped. */
void app_release_nvm(app_t *a);

#endif /* LINUX_APP_H */
