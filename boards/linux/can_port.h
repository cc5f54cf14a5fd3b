/*
 * can_port.h - a node's port (what co_port.h's hooks reach): one SocketCAN
 * raw socket per node with the link watch, the kernel's receive filter and
 * the simulated CAN controller; the process's one sending socket; the
 * node's EEPROM (nvm_file.h).
 *
 * The CAN state a node sees (lp_can_state) is the worst of three sources:
 *  - the link: an interface that is down, deleted or not CAN is a cable
 *    pull, shown as bus-off until the interface is back (looked for every
 *    LP_LINK_POLL_US, and re-bound when it was deleted and re-created);
 *  - the kernel's error frames (a real controller: warning, passive, bus-off);
 *  - the simulated controller (the line language's `can`, cmd.h),
 *    which recovers from bus-off by itself after 128 x 11 recessive bits.
 * While the state is bus-off the port transmits nothing and discards what
 * it receives, as a controller off the bus does.
 * Everything here runs in the program's one thread; nothing blocks.
 */
#ifndef LINUX_CAN_PORT_H
#define LINUX_CAN_PORT_H

#include <linux/can.h>
#include <net/if.h>
#include <netinet/in.h>
#include <stdio.h>

#include "co_node.h"
#include "log.h"
#include "nvm_file.h"

#define LP_TXQ 64u
/* Frames handed to the kernel in one system call (sendmmsg, lp_tx_flush). */
#define LP_TXB 128u
/* Frames taken from the kernel in one system call (recvmmsg). */
#define LP_RXB 32u
/* While the interface is down or missing, look at it this often. */
#define LP_LINK_POLL_US 200000u
/* A bus-off controller is back after 128 occurrences of 11 recessive bits
 * (ISO 11898-1); the board turns that into time at the node's bit rate. */
#define LP_BUSOFF_RECOVERY_BITS (128u * 11u)

typedef enum lp_link {
    LP_LINK_UP = 0, /* bound, interface up */
    LP_LINK_DOWN,   /* the interface exists but is down */
    LP_LINK_ABSENT, /* no such interface (deleted), or not a CAN interface */
} lp_link_t;

/*
 * The process's sending socket (lp_tx_open), shared by every node: each
 * node's frames wait in its port's queue until the pass ends, and then go
 * to the kernel together, one sendmmsg() for all nodes and interfaces
 * (lp_tx_flush), each message addressed to its node's interface. 127
 * nodes at a 10 ms TPDO made 12 700 write() calls a second, one socket
 * each; a pass now makes one call for what its nodes sent (tools/busbench).
 * The kernel loops each frame back to every other CAN socket on the host,
 * the nodes' receiving sockets included (as a bus does), never to the one
 * that sent it: a node does not hear itself. It receives nothing.
 */
typedef struct lp_tx {
    int fd;               /* CAN_RAW socket bound to no interface, receiving nothing */
    bool addressed;       /* each message names its port's interface (false: fd is a
                           * connected socket, the unit tests') */
    unsigned long calls;  /* sendmmsg() calls that sent something */
    unsigned long frames; /* frames sent */
} lp_tx_t;

typedef struct lp_port {
    int fd; /* CAN_RAW socket, non-blocking; kept across link changes;
             * receives (frames go out through an lp_tx_t); on a
             * udp_multicast bus the group's receiving socket */
    const char *iface;
    unsigned node; /* index, for log lines */
    uint16_t kbps; /* the node's bit rate (co_port_can_bitrate; vcan has none) */
    bool kbps_set; /* kbps was given (at the node's start) */
    lp_nvm_t *nvm;
    /* The instance's program download (prog.h; --program-download), NULL:
     * off; set after lp_open. While its state is not "started" the port
     * sends only what a bootloader sends (lp_halted_may_send). */
    struct lp_prog *prog;
    const struct co_progdl *progdl;
    co_frame_t txq[LP_TXQ]; /* frames the kernel could not take yet */
    unsigned txh, txn;
    unsigned long tx_lost; /* frames dropped because txq was full */
    unsigned long tx_off;  /* frames not sent because the controller was off the bus */
    /* link watch */
    int link;               /* lp_link_t */
    int ifindex;            /* of the interface last bound (0: never) */
    uint32_t link_check_at; /* next look while not up */
    bool link_blip;         /* the link went down and came back before it was
                             * looked at: bus-off until the next lp_poll */
    /* CAN controller */
    int ctrl_state;          /* co_can_state_t from the kernel's error frames */
    int sim_state;           /* co_can_state_t of the simulated controller */
    uint32_t sim_recover_at; /* simulated bus-off: back on the bus then */
    int sim_back;            /* the state it comes back in (error active unless told) */
    /* received frames: a batch read in one call, served one by one */
    struct can_frame rxb[LP_RXB];
    uint8_t rxlen[LP_RXB];     /* bytes each message had (a classic frame: 16) */
    unsigned rxi, rxn;         /* next to serve, how many */
    unsigned long rx_frames;   /* frames read */
    uint32_t rx_ovfl;          /* the kernel's drop count (SO_RXQ_OVFL) last seen */
    unsigned long rx_dropped;  /* frames the kernel dropped for this socket, in all */
    unsigned long rx_unlogged; /* of those, not logged yet */
    lp_rate_t rx_rate;         /* one drop line a second at most */
    lp_rate_t err_rate;        /* unexpected socket errors: a few lines a second */
    uint32_t now;              /* latest time given to lp_poll / lp_read */
    /* the kernel's receive filter (CAN_RAW_FILTER): the node's CAN-IDs as
     * last installed (lp_filter) */
    co_rx_id_t filt[CO_NODE_RX_IDS_MAX];
    unsigned nfilt;
    bool filt_set;              /* filt[] is what the kernel has */
    const co_node_t *filt_node; /* the node filtered for (lp_filter), or NULL */
    unsigned long filt_changes; /* times the filter was (re)installed */
    /* A udp_multicast bus (udp_bus.h) instead of SocketCAN (udp): the
     * node sends through its own socket txfd, whose address self tells
     * its own datagrams from the others' (a node does not hear itself, as
     * on SocketCAN); the receive filter is kept here, not in the kernel.
     * udp_reader: the port whose socket receives for every node of the
     * process on the same group (lp_udp_share): its own index, or the
     * first such port's; the others' fd is closed. One socket reads each
     * datagram once, where a socket a node made 127 nodes read 127 copies
     * (a core's worth). */
    struct sockaddr_in self;
    struct sockaddr_in rxfrom[LP_RXB]; /* the reader's batch: each sender */
    void *zone;                        /* the decoder's (udp_bus.h) */
    unsigned long rx_ignored;          /* datagrams no classic frame (malformed, FD, 29-bit) */
    unsigned long rx_filtered;         /* frames the node does not consume (udp) */
    int txfd;
    unsigned udp_reader;
    /* Faults a master must survive (the line language's `unplug`,
     * `heartbeat`): the cable pulled, no frame in or out and the error
     * counters unchanged, until unplug_until (unplug_timed) or `unplug
     * off`; the node's heartbeats (and guarding answers: the NMT error
     * control frames other than its boot-up) not sent (hb_stopped). */
    unsigned long tx_unplugged; /* frames lost to the pulled cable */
    uint32_t unplug_until;
    bool udp;
    bool unplugged;
    bool unplug_timed;
    bool hb_stopped;
} lp_port_t;

/* Whether a node whose program is halted (stopped, or no valid program:
 * co_progdl.h) sends frame ID id: its SDO answers (580h-5FFh), its
 * boot-up, heartbeat and guarding answers (700h-77Fh) and LSS answers
 * (7E4h), what a bootloader sends. PDOs and EMCY are the program's. */
bool lp_halted_may_send(uint32_t id);

/*
 * Open a non-blocking raw CAN socket on iface, error frames and the drop
 * count enabled; or, when iface is a udp_multicast bus (udp_bus.h:
 * "udp_multicast:GROUP[:PORT][%IFNAME]"), the node's two sockets on it
 * (an error when the program was built without msgpack-c). A down
 * interface is accepted (bus-off until it comes up).
 * Returns 0, or -1 with a one-line cause in err (errlen bytes; the
 * interface not named: the caller says which option named it) when the
 * interface does not exist, is not a CAN interface, or the kernel has no CAN.
 */
int lp_open(lp_port_t *p, const char *iface, unsigned node, lp_nvm_t *nvm, uint32_t now, char *err,
            unsigned errlen);

/* Close the socket. */
void lp_close(lp_port_t *p);

/*
 * The port's timers at time now: the link watch while the interface is
 * down or missing, the simulated bus-off recovery, the dropped-frame log.
 * Returns the delay (us) until it needs to run again.
 */
uint32_t lp_poll(lp_port_t *p, uint32_t now);

/* The CAN state the node should see now (see the top of this file). */
co_can_state_t lp_can_state(const lp_port_t *p);

/*
 * The simulated controller: s = bus-off enters bus-off; the bus then stays
 * unusable for hold_us, after which the controller is back after
 * recovery_us (128 x 11 bits at its bit rate), error active. Warning and
 * passive stay until changed; active ends them. During a bus-off, any
 * other state ends the hold: the controller is back after the recovery
 * alone, in that state (the emulated boards' serial line does the same).
 */
void lp_sim_can(lp_port_t *p, co_can_state_t s, uint32_t now, uint32_t hold_us,
                uint32_t recovery_us);

/* A `can` command (cmd.h) on this port at time now: lp_sim_can with the
 * recovery of 128 x 11 bits at the node's bit rate (125 kbit/s when its
 * code means none), a bus-off's hold given in milliseconds. */
void lp_sim_can_command(lp_port_t *p, co_can_state_t s, uint32_t now, uint32_t hold_ms);

/*
 * udp_multicast: the n ports (an array, all open) that are on one group,
 * port and interface share the first one's receiving socket (udp_reader);
 * the others' are closed. Call once, after every port is open.
 */
void lp_udp_share(lp_port_t *ports, unsigned n);

/*
 * udp_multicast, the reader's side: read the next batch of datagrams into
 * reader (the port whose udp_reader is its own index). Returns how many
 * (0: none); each is then offered to every member with lp_udp_take.
 */
unsigned lp_udp_batch(lp_port_t *reader, uint32_t now);

/*
 * Datagram k of reader's batch for member m (a port that shares reader's
 * socket, reader itself included): 1 with *f filled when it is a classic
 * frame that m receives (not its own, m on the bus, on m's receive list),
 * else 0.
 */
int lp_udp_take(lp_port_t *m, const lp_port_t *reader, unsigned k, co_frame_t *f);

/* `unplug`: the cable pulled for hold_ms (0: until lp_unplug_off). */
void lp_unplug(lp_port_t *p, uint32_t now, uint32_t hold_ms);
void lp_unplug_off(lp_port_t *p);

/* `heartbeat stop|start`: the node's NMT error-control frames other than
 * its boot-up (heartbeats, guarding answers) not sent / sent again. */
void lp_heartbeat(lp_port_t *p, bool on);

/* Log the dropped frames not logged yet, whatever the rate (at exit). */
void lp_report_drops(lp_port_t *p);

/*
 * Keep the socket's kernel filter (CAN_RAW_FILTER) on the CAN-IDs node
 * consumes (co_node_rx_ids): the first call installs it, later calls
 * compare the list and call setsockopt only when it changed (a COB-ID or
 * the node-ID did: SDO write, reset, LSS). Call it after every
 * co_node_poll(); from then on the port also calls it before each frame
 * the node sends, so that an answer which changed an ID (the SDO answer
 * to a write of 0x1005, the boot-up after a reset with a new node-ID)
 * goes out only once the filter takes the new ID: a master that sends on
 * it as soon as it has the answer is heard. Error frames are
 * not affected (CAN_RAW_ERR_FILTER, set by lp_open). A filter the kernel
 * refuses is logged and the socket then receives every frame, as before
 * filters existed. node is only read.
 */
void lp_filter(lp_port_t *p, const co_node_t *node);

/*
 * Open the shared sending socket (lp_tx_t). Returns 0, or -1 with a
 * one-line cause in err (errlen bytes).
 */
int lp_tx_open(lp_tx_t *tx, char *err, unsigned errlen);
void lp_tx_close(lp_tx_t *tx);

/*
 * Hand what the n ports (an array) queued to the kernel through tx, in as
 * few sendmmsg() calls as the kernel allows (LP_TXB frames a call), each
 * port's frames in their order. A port off the bus loses its queue; a
 * frame the interface refuses for good (went down or away: the port's
 * link watch takes note) is lost with it; a full kernel queue keeps the
 * rest for the next call. Returns the frames still queued.
 */
unsigned lp_tx_flush(lp_tx_t *tx, lp_port_t *ports, unsigned n);

/*
 * Read one frame. Returns 1 with *f filled, 0 when nothing (more) is
 * pending. Socket errors (the interface went down or away) are handled
 * here: they change the link state, which lp_can_state() then shows.
 */
int lp_read(lp_port_t *p, co_frame_t *f, uint32_t now);

#endif /* LINUX_CAN_PORT_H */
