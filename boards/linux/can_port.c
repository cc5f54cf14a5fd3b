/*
 * can_port.c - a node's port on SocketCAN and the co_port.h hooks; see can_port.h.
 */
#include "can_port.h"

#include <errno.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <linux/if_arp.h>
#include <stddef.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <time.h>
#include <unistd.h>

#include "co_port.h"
#include "co_progdl.h"
#include "log.h"
#include "udp_bus.h"

/* ---- CAN: link watch ---------------------------------------------------- */

static const char *const state_names[] = {"error active", "warning", "error passive", "bus-off"};

/* Frames in the software queue are lost when the controller leaves the bus. */
static void drop_txq(lp_port_t *p)
{
    p->tx_off += p->txn;
    p->txn = 0;
    p->txh = 0;
}

/*
 * Look at the interface: exists, is CAN, bound (again: a deleted and
 * re-created interface has a new index, and the kernel unbinds a socket
 * from an interface that goes away; binding to the same index again does
 * nothing), up. Returns the lp_link_t; for LP_LINK_ABSENT *cause says why.
 */
static lp_link_t link_probe(lp_port_t *p, int *index, const char **cause)
{
    struct ifreq ifr;
    memset(&ifr, 0, sizeof(ifr));
    snprintf(ifr.ifr_name, sizeof(ifr.ifr_name), "%s", p->iface);
    *cause = NULL;
    /* A missing interface is looked for in sysfs first: for root, the
     * kernel answers SIOCGIFINDEX on an unknown name by running modprobe,
     * which blocked the whole process (every node) for 0.16 s a probe. */
    char path[64];
    snprintf(path, sizeof(path), "/sys/class/net/%s", p->iface);
    if (access("/sys/class/net", F_OK) == 0 && access(path, F_OK) != 0) {
        *cause = "no such network interface";
        return LP_LINK_ABSENT;
    }
    if (ioctl(p->fd, SIOCGIFINDEX, &ifr) < 0) {
        *cause = errno == ENODEV ? "no such network interface" : strerror(errno);
        return LP_LINK_ABSENT;
    }
    *index = ifr.ifr_ifindex;
    if (ioctl(p->fd, SIOCGIFHWADDR, &ifr) < 0) {
        *cause = strerror(errno);
        return LP_LINK_ABSENT;
    }
    if (ifr.ifr_hwaddr.sa_family != ARPHRD_CAN) {
        *cause = "not a CAN interface (SocketCAN: can0, vcan0, ...)";
        return LP_LINK_ABSENT;
    }
    struct sockaddr_can addr;
    memset(&addr, 0, sizeof(addr));
    addr.can_family = AF_CAN;
    addr.can_ifindex = *index;
    if (bind(p->fd, (struct sockaddr *)&addr, sizeof(addr)) < 0) {
        *cause = strerror(errno);
        return LP_LINK_ABSENT;
    }
    if (ioctl(p->fd, SIOCGIFFLAGS, &ifr) < 0) {
        *cause = strerror(errno);
        return LP_LINK_ABSENT;
    }
    return (ifr.ifr_flags & IFF_UP) != 0 ? LP_LINK_UP : LP_LINK_DOWN;
}

/*
 * Probe the link now and log a change. lost: the kernel just said the link
 * went down or away (a socket error); should it be up again already, the
 * node still sees a bus-off for a moment (lp_poll ends it), so that no
 * loss of the bus goes unreported.
 */
static void link_check(lp_port_t *p, uint32_t now, bool lost)
{
    if (p->udp) {
        return; /* a udp_multicast bus has no CAN link to watch */
    }
    int index = p->ifindex;
    const char *cause;
    lp_link_t l = link_probe(p, &index, &cause);
    p->link_check_at = now + LP_LINK_POLL_US;
    if (l == (lp_link_t)p->link) {
        if (l == LP_LINK_UP && (lost || index != p->ifindex)) {
            char again[64] = "";
            if (index != p->ifindex) {
                snprintf(again, sizeof(again), " (re-created, index %d: socket bound again)",
                         index);
            }
            lp_log("node %u: %s went down and is up again%s: a moment of CAN bus-off", p->node,
                   p->iface, again);
            p->ifindex = index;
            p->link_blip = true;
            drop_txq(p);
        }
        return;
    }
    if (p->link == LP_LINK_UP) {
        drop_txq(p); /* off the bus: what was waiting is lost */
    }
    char again[64] = "";
    if (l != LP_LINK_ABSENT && index != p->ifindex) {
        snprintf(again, sizeof(again), " (re-created, index %d: socket bound again)", index);
        p->ifindex = index;
    }
    switch (l) {
    case LP_LINK_UP:
        lp_log("node %u: %s is up again%s: CAN on the bus", p->node, p->iface, again);
        break;
    case LP_LINK_DOWN:
        lp_log("node %u: %s is down%s: shown as CAN bus-off until it is up (checked every %u "
               "ms)",
               p->node, p->iface, again, LP_LINK_POLL_US / 1000u);
        break;
    case LP_LINK_ABSENT:
    default:
        lp_log("node %u: %s: %s: shown as CAN bus-off until it is back (checked every %u ms)",
               p->node, p->iface, cause, LP_LINK_POLL_US / 1000u);
        break;
    }
    p->link = (int)l;
}

/* A raw CAN socket, non-blocking; -1 with the cause in err. */
static int can_socket(char *err, unsigned errlen)
{
    int fd = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (fd < 0) {
        snprintf(err, errlen,
                 "CAN socket: %s (is CAN supported by this kernel? see tools/vcan-run)",
                 strerror(errno));
    }
    return fd;
}

/* lp_open on a udp_multicast bus: always "up" (no cable to watch). */
static int udp_open(lp_port_t *p, char *err, unsigned errlen)
{
    p->fd = -1;
#ifdef HAVE_MSGPACK
    lp_udp_addr_t a;
    if (lp_udp_parse(p->iface, &a, err, errlen) != 0) {
        return -1;
    }
    p->zone = lp_udp_zone_new();
    if (p->zone == NULL) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    if (lp_udp_open(&a, &p->fd, &p->txfd, &p->self, err, errlen) != 0) {
        lp_udp_zone_free(p->zone);
        p->zone = NULL;
        return -1;
    }
    p->udp = true;
    p->ifindex = (int)a.ifindex;
    p->link = LP_LINK_UP;
    return 0;
#else
    snprintf(err, errlen,
             "this build has no udp_multicast bus (msgpack-c, Debian's libmsgpack-dev, was "
             "missing when it was built)");
    return -1;
#endif
}

int lp_open(lp_port_t *p, const char *iface, unsigned node, lp_nvm_t *nvm, uint32_t now, char *err,
            unsigned errlen)
{
    memset(p, 0, sizeof(*p));
    p->iface = iface;
    p->node = node;
    p->nvm = nvm;
    p->now = now;
    p->txfd = -1;
    if (lp_udp_is(iface)) {
        return udp_open(p, err, errlen);
    }
    p->fd = can_socket(err, errlen);
    if (p->fd < 0) {
        return -1;
    }
    can_err_mask_t mask = CAN_ERR_MASK;
    (void)setsockopt(p->fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &mask, sizeof(mask));
    /* The kernel's count of frames it dropped for this socket (receive
     * queue full) comes with each frame read. */
    int one = 1;
    (void)setsockopt(p->fd, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof(one));
    int index = 0;
    const char *cause;
    lp_link_t l = link_probe(p, &index, &cause);
    if (l == LP_LINK_ABSENT) {
        /* At start a missing interface is a mistake to report, not a cable
         * to wait for: the user named it a moment ago. */
        snprintf(err, errlen, "%s", cause); /* the caller names the option and interface */
        close(p->fd);
        p->fd = -1;
        return -1;
    }
    p->ifindex = index;
    p->link = (int)l;
    p->link_check_at = now + LP_LINK_POLL_US;
    if (l == LP_LINK_DOWN) {
        lp_log("node %u: %s is down: shown as CAN bus-off until it is up (checked every %u ms)",
               node, iface, LP_LINK_POLL_US / 1000u);
    }
    return 0;
}

void lp_close(lp_port_t *p)
{
    if (p->fd >= 0) {
        close(p->fd);
        p->fd = -1;
    }
    if (p->txfd >= 0) {
        close(p->txfd);
        p->txfd = -1;
    }
#ifdef HAVE_MSGPACK
    lp_udp_zone_free(p->zone);
#endif
    p->zone = NULL;
}

co_can_state_t lp_can_state(const lp_port_t *p)
{
    if (p->link != LP_LINK_UP || p->link_blip) {
        return CO_CAN_BUSOFF;
    }
    return (co_can_state_t)(p->ctrl_state > p->sim_state ? p->ctrl_state : p->sim_state);
}

void lp_sim_can(lp_port_t *p, co_can_state_t s, uint32_t now, uint32_t hold_us,
                uint32_t recovery_us)
{
    if (s == CO_CAN_BUSOFF) {
        p->sim_state = CO_CAN_BUSOFF;
        p->sim_back = CO_CAN_ACTIVE;
        /* hold + recovery can exceed half the 32-bit clock: cap it there */
        uint64_t off = (uint64_t)hold_us + recovery_us;
        p->sim_recover_at = now + (uint32_t)(off < 0x7FFFFFFFu ? off : 0x7FFFFFFFu);
        drop_txq(p);
        lp_log("node %u: simulated CAN controller bus-off: bus unusable for %u ms, then back "
               "after 128 x 11 bits (%u.%03u ms)",
               p->node, hold_us / 1000u, recovery_us / 1000u, recovery_us % 1000u);
    } else if (p->sim_state == CO_CAN_BUSOFF) {
        if (co_time_before(now + recovery_us, p->sim_recover_at)) {
            p->sim_recover_at = now + recovery_us;
        }
        p->sim_back = (int)s;
        lp_log("node %u: simulated CAN controller: bus usable again, back from bus-off in "
               "%u.%03u ms, %s",
               p->node, recovery_us / 1000u, recovery_us % 1000u, state_names[s]);
    } else {
        p->sim_state = (int)s;
        lp_log("node %u: simulated CAN controller %s", p->node, state_names[s]);
    }
}

void lp_sim_can_command(lp_port_t *p, co_can_state_t s, uint32_t now, uint32_t hold_ms)
{
    uint32_t kbps = p->kbps;
    if (kbps == 0u) {
        kbps = 125u; /* a code the product does not define: the usual default */
    }
    /* 128 x 11 recessive bits at the node's bit rate, rounded up */
    uint32_t recovery_us = (LP_BUSOFF_RECOVERY_BITS * 1000u + kbps - 1u) / kbps;
    lp_sim_can(p, s, now, hold_ms * 1000u, recovery_us);
}

static void report_drops(lp_port_t *p, uint32_t now)
{
    if (p->rx_unlogged != 0u && lp_rate_allow(&p->rx_rate, now, 1u)) {
        lp_log("node %u: %lu received frames dropped on %s (socket receive queue full; "
               "%lu in all)",
               p->node, p->rx_unlogged, p->iface, p->rx_dropped);
        p->rx_unlogged = 0;
    }
}

void lp_unplug(lp_port_t *p, uint32_t now, uint32_t hold_ms)
{
    p->unplugged = true;
    p->unplug_timed = hold_ms != 0u;
    p->unplug_until = now +
                      hold_ms * 1000u; /* hold_ms <= CMD_HOLD_MAX_S s: within half the clock */
    drop_txq(p);
    if (p->unplug_timed) {
        lp_log("node %u: cable pulled for %u ms: no frame in or out, the error counters as they "
               "were",
               p->node, hold_ms);
    } else {
        lp_log("node %u: cable pulled until `unplug off`: no frame in or out, the error counters "
               "as they were",
               p->node);
    }
}

void lp_unplug_off(lp_port_t *p)
{
    if (p->unplugged) {
        lp_log("node %u: cable plugged in again (%lu frames lost to it)", p->node, p->tx_unplugged);
    }
    p->unplugged = false;
    p->unplug_timed = false;
}

void lp_heartbeat(lp_port_t *p, bool on)
{
    p->hb_stopped = !on;
    lp_log("node %u: heartbeat %s", p->node,
           on ? "sent again" : "stopped (and guarding answers): boot-up only");
}

uint32_t lp_poll(lp_port_t *p, uint32_t now)
{
    p->now = now;
    uint32_t next = CO_NEVER;
    if (p->unplugged && p->unplug_timed) {
        if (!co_time_before(now, p->unplug_until)) {
            lp_unplug_off(p);
        } else {
            next = co_time_until(now, p->unplug_until);
        }
    }
    p->link_blip = false;
    if (p->link != LP_LINK_UP) {
        if (!co_time_before(now, p->link_check_at)) {
            link_check(p, now, false);
        }
        if (p->link != LP_LINK_UP) {
            next = co_time_until(now, p->link_check_at);
        }
    }
    if (p->sim_state == CO_CAN_BUSOFF) {
        if (!co_time_before(now, p->sim_recover_at)) {
            p->sim_state = p->sim_back;
            lp_log("node %u: simulated CAN controller back from bus-off: %s", p->node,
                   state_names[p->sim_back]);
        } else {
            next = co_min_u32(next, co_time_until(now, p->sim_recover_at));
        }
    }
    report_drops(p, now);
    if (p->rx_unlogged != 0u) {
        next = co_min_u32(next, lp_rate_wait(&p->rx_rate, now));
    }
    return next;
}

/* ---- CAN: frames -------------------------------------------------------- */

/* The kernel's filter from the list: data frames on the CAN-ID, or remote
 * frames on it, each an exact match. The RTR bit in the mask puts a data
 * entry in the kernel's table indexed by CAN-ID (constant time); without
 * it every entry of every socket was tried on every frame on the bus. */
static void filter_install(lp_port_t *p)
{
    if (p->udp) {
        p->filt_changes++;
        return; /* no kernel filter on a UDP socket: lp_read applies filt[] */
    }
    struct can_filter cf[CO_NODE_RX_IDS_MAX];
    for (unsigned k = 0; k < p->nfilt; k++) {
        cf[k].can_id = p->filt[k].id | (p->filt[k].rtr ? CAN_RTR_FLAG : 0u);
        cf[k].can_mask = CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG;
    }
    p->filt_changes++;
    if (setsockopt(p->fd, SOL_CAN_RAW, CAN_RAW_FILTER, cf, (socklen_t)(p->nfilt * sizeof(cf[0]))) ==
        0) {
        return;
    }
    int e = errno;
    /* Receive everything rather than miss a frame: the node ignores what
     * is not its own, at a cost in CPU only. */
    struct can_filter all = {.can_id = 0, .can_mask = 0};
    (void)setsockopt(p->fd, SOL_CAN_RAW, CAN_RAW_FILTER, &all, sizeof(all));
    if (lp_rate_allow(&p->err_rate, p->now, 3u)) {
        lp_log("node %u: CAN receive filter on %s refused (%s): receiving every frame", p->node,
               p->iface, strerror(e));
    }
}

void lp_filter(lp_port_t *p, const co_node_t *node)
{
    p->filt_node = node;
    co_rx_id_t ids[CO_NODE_RX_IDS_MAX];
    unsigned n = co_node_rx_ids(node, ids, CO_NODE_RX_IDS_MAX);
    if (n > CO_NODE_RX_IDS_MAX) {
        n = CO_NODE_RX_IDS_MAX; /* cannot happen: the stack's own bound */
    }
    bool same = p->filt_set && n == p->nfilt;
    for (unsigned k = 0; same && k < n; k++) {
        same = ids[k].id == p->filt[k].id && ids[k].rtr == p->filt[k].rtr;
    }
    if (same) {
        return; /* unchanged: the usual case, no system call */
    }
    for (unsigned k = 0; k < n; k++) {
        p->filt[k] = ids[k];
    }
    p->nfilt = n;
    p->filt_set = true;
    filter_install(p);
}

/* Errors that mean the interface went down or away. */
static bool link_errno(int e)
{
    return e == ENETDOWN || e == ENODEV || e == ENXIO || e == ENETUNREACH;
}

int lp_tx_open(lp_tx_t *tx, char *err, unsigned errlen)
{
    memset(tx, 0, sizeof(*tx));
    tx->addressed = true;
    tx->fd = can_socket(err, errlen);
    if (tx->fd < 0) {
        return -1;
    }
    /* Never bound: it receives nothing (the empty filter says so twice);
     * each message carries its interface. */
    (void)setsockopt(tx->fd, SOL_CAN_RAW, CAN_RAW_FILTER, NULL, 0);
    return 0;
}

void lp_tx_close(lp_tx_t *tx)
{
    if (tx->fd >= 0) {
        close(tx->fd);
        tx->fd = -1;
    }
}

/* The first frame of p's queue leaves it (sent, or lost for good). */
static void txq_pop(lp_port_t *p)
{
    p->txh = (p->txh + 1u) % LP_TXQ;
    p->txn--;
}

/* Frames queued in all n ports. */
static unsigned txq_total(const lp_port_t *ports, unsigned n)
{
    unsigned total = 0;
    for (unsigned i = 0; i < n; i++) {
        total += ports[i].txn;
    }
    return total;
}

/* A udp_multicast port's queue through its own socket (as many
 * datagrams a call as lp_tx_flush's frames); the frames left queued. */
static unsigned udp_flush(lp_tx_t *tx, lp_port_t *p)
{
    (void)tx;
#ifdef HAVE_MSGPACK
    uint8_t dg[LP_TXB][256];
    struct iovec iov[LP_TXB];
    struct mmsghdr mm[LP_TXB];
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    double now = (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
    while (p->txn != 0u) {
        unsigned cnt = 0;
        for (unsigned k = 0; k < p->txn && cnt < LP_TXB; k++, cnt++) {
            const co_frame_t *f = &p->txq[(p->txh + k) % LP_TXQ];
            iov[cnt].iov_base = dg[cnt];
            iov[cnt].iov_len = lp_udp_encode(f, now, dg[cnt], sizeof(dg[cnt]));
            memset(&mm[cnt], 0, sizeof(mm[cnt]));
            mm[cnt].msg_hdr.msg_iov = &iov[cnt];
            mm[cnt].msg_hdr.msg_iovlen = 1;
        }
        int r = sendmmsg(p->txfd, mm, cnt, MSG_DONTWAIT);
        if (r > 0) {
            for (unsigned k = 0; k < co_min_u32((unsigned)r, cnt); k++) {
                txq_pop(p);
            }
            tx->calls++;
            tx->frames += co_min_u32((unsigned)r, cnt);
            continue;
        }
        int e = errno;
        if (r < 0 && (e == EAGAIN || e == ENOBUFS || e == EINTR)) {
            break; /* the socket's queue is full: later */
        }
        txq_pop(p); /* refused: lost (the interface went down or away) */
        if (lp_rate_allow(&p->err_rate, p->now, 3u)) {
            lp_log("node %u: UDP send on %s failed: %s", p->node, p->iface,
                   r < 0 ? strerror(e) : "nothing sent");
        }
    }
#endif
    return p->txn;
}

unsigned lp_tx_flush(lp_tx_t *tx, lp_port_t *ports, unsigned n)
{
    struct can_frame cf[LP_TXB];
    struct iovec iov[LP_TXB];
    struct sockaddr_can to[LP_TXB];
    struct mmsghdr mm[LP_TXB];
    lp_port_t *from[LP_TXB];
    for (;;) {
        /* Gather: each port's queue from its head, ports in order. */
        unsigned cnt = 0;
        for (unsigned i = 0; i < n && cnt < LP_TXB; i++) {
            lp_port_t *p = &ports[i];
            if (p->txn != 0u && lp_can_state(p) == CO_CAN_BUSOFF) {
                drop_txq(p); /* off the bus since it queued them */
            }
            if (p->udp) {
                continue; /* sent through its own socket, below */
            }
            for (unsigned k = 0; k < p->txn && cnt < LP_TXB; k++, cnt++) {
                const co_frame_t *f = &p->txq[(p->txh + k) % LP_TXQ];
                memset(&cf[cnt], 0, sizeof(cf[cnt]));
                cf[cnt].can_id = f->id | (f->rtr ? CAN_RTR_FLAG : 0u);
                cf[cnt].len = f->dlc;
                memcpy(cf[cnt].data, f->data, f->dlc);
                iov[cnt].iov_base = &cf[cnt];
                iov[cnt].iov_len = sizeof(cf[cnt]);
                memset(&mm[cnt], 0, sizeof(mm[cnt]));
                mm[cnt].msg_hdr.msg_iov = &iov[cnt];
                mm[cnt].msg_hdr.msg_iovlen = 1;
                if (tx->addressed) {
                    memset(&to[cnt], 0, sizeof(to[cnt]));
                    to[cnt].can_family = AF_CAN;
                    to[cnt].can_ifindex = p->ifindex;
                    mm[cnt].msg_hdr.msg_name = &to[cnt];
                    mm[cnt].msg_hdr.msg_namelen = sizeof(to[cnt]);
                }
                from[cnt] = p;
            }
        }
        if (cnt == 0u) {
            unsigned left = 0;
            for (unsigned i = 0; i < n; i++) {
                if (ports[i].udp) {
                    left += udp_flush(tx, &ports[i]);
                }
            }
            return left;
        }
        int r = sendmmsg(tx->fd, mm, cnt, MSG_DONTWAIT);
        if (r > 0) {
            /* A port's frames are consecutive from its head: pop in order.
             * (The kernel never reports more than it was given.) */
            unsigned sent = co_min_u32((unsigned)r, cnt);
            for (unsigned k = 0; k < sent; k++) {
                txq_pop(from[k]);
            }
            tx->calls++;
            tx->frames += sent;
            continue; /* the rest, or the error of the first not sent */
        }
        int e = errno;
        if (r < 0 && (e == EAGAIN || e == ENOBUFS || e == EINTR)) {
            return txq_total(ports, n); /* the kernel's queue is full: later */
        }
        lp_port_t *p = from[0];
        txq_pop(p); /* refused for good: lost (its link, or logged below) */
        if (r < 0 && link_errno(e)) {
            link_check(p, p->now, true);
        } else if (lp_rate_allow(&p->err_rate, p->now, 3u)) {
            lp_log("node %u: CAN write on %s failed: %s", p->node, p->iface,
                   r < 0 ? strerror(e) : "nothing sent");
        }
    }
}

/* vcan has no bit rate: the rate is kept (bus-off recovery time) and a
 * change after the start (reset node with a new code, LSS activate bit
 * timing) is logged. */
bool co_port_can_bitrate(void *port, uint16_t kbps)
{
    lp_port_t *p = port;
    if (p->kbps_set && kbps != p->kbps) {
        lp_log("node %u: bit rate now %u kbit/s (vcan has no bit rate to set)", p->node, kbps);
    }
    p->kbps = kbps;
    p->kbps_set = true;
    return true;
}

bool lp_halted_may_send(uint32_t id)
{
    return (id >= 0x580u && id <= 0x5FFu) || (id >= 0x700u && id <= 0x77Fu) || id == 0x7E4u;
}

bool co_port_can_send(void *port, const co_frame_t *frame)
{
    lp_port_t *p = port;
    if (p->filt_node != NULL) {
        lp_filter(p, p->filt_node); /* the filter first, then the answer (can_port.h) */
    }
    if (lp_can_state(p) == CO_CAN_BUSOFF) {
        p->tx_off++; /* a controller off the bus sends nothing */
        return false;
    }
    if (p->unplugged) {
        p->tx_unplugged++;
        return true; /* onto a cable that leads nowhere */
    }
    if (p->hb_stopped && frame->id >= 0x701u && frame->id <= 0x77Fu && frame->dlc == 1u &&
        frame->data[0] != 0u) {
        return true; /* `heartbeat stop`: the boot-up (0) alone still goes */
    }
    if (p->progdl != NULL && co_progdl_state(p->progdl) != CO_PROGDL_STARTED &&
        !lp_halted_may_send(frame->id)) {
        return true; /* the program is halted: what it would send is not made */
    }
    /* Every frame waits for the pass's end (lp_tx_flush): microseconds,
     * and one system call for all nodes. */
    if (p->txn >= LP_TXQ) {
        if (p->tx_lost++ % 100u == 0u) {
            lp_log("node %u: transmit queue full, frame %03X dropped (%lu so far)", p->node,
                   frame->id, p->tx_lost);
        }
        return false;
    }
    p->txq[(p->txh + p->txn) % LP_TXQ] = *frame;
    p->txn++;
    return true;
}

/* An error frame from the kernel (a real controller): its new state. */
static void error_frame(lp_port_t *p, const struct can_frame *cf)
{
    co_can_state_t s = (co_can_state_t)p->ctrl_state;
    if ((cf->can_id & CAN_ERR_BUSOFF) != 0u) {
        s = CO_CAN_BUSOFF;
    } else if ((cf->can_id & CAN_ERR_RESTARTED) != 0u) {
        s = CO_CAN_ACTIVE;
    } else if ((cf->can_id & CAN_ERR_CRTL) != 0u) {
        uint8_t c = cf->data[1];
        if ((c & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0u) {
            s = CO_CAN_PASSIVE;
        } else if ((c & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0u) {
            s = CO_CAN_WARNING;
        } else if ((c & CAN_ERR_CRTL_ACTIVE) != 0u) {
            s = CO_CAN_ACTIVE;
        }
    }
    lp_log("node %u: CAN error frame on %s (id %08X): %s", p->node, p->iface, (unsigned)cf->can_id,
           state_names[s]);
    if (s == CO_CAN_BUSOFF) {
        drop_txq(p);
    }
    p->ctrl_state = (int)s;
}

/* The drop count in a message's control data (SO_RXQ_OVFL). */
static void rx_overflow(lp_port_t *p, struct msghdr *mh)
{
    for (struct cmsghdr *c = CMSG_FIRSTHDR(mh); c != NULL; c = CMSG_NXTHDR(mh, c)) {
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL) {
            uint32_t total;
            memcpy(&total, CMSG_DATA(c), sizeof(total));
            uint32_t d = total - p->rx_ovfl; /* the kernel's counter wraps at 2^32 */
            p->rx_ovfl = total;
            p->rx_dropped += d;
            p->rx_unlogged += d;
        }
    }
}

#ifdef HAVE_MSGPACK
/* read_batch on a udp_multicast bus: each datagram decoded into p->rxb;
 * its rxlen 0 when it is no frame for the node (its own, malformed, FD,
 * 29-bit, truncated), a classic frame's size otherwise. */
static unsigned udp_read_batch(lp_port_t *p, uint32_t now)
{
    struct mmsghdr mm[LP_RXB];
    struct iovec iov[LP_RXB];
    struct sockaddr_in from[LP_RXB];
    uint8_t dg[LP_RXB][LP_UDP_DGRAM_MAX];
    _Alignas(size_t) char ctrl[LP_RXB][CMSG_SPACE(sizeof(uint32_t))];
    memset(mm, 0, sizeof(mm));
    for (unsigned k = 0; k < LP_RXB; k++) {
        iov[k].iov_base = dg[k];
        iov[k].iov_len = sizeof(dg[k]);
        mm[k].msg_hdr.msg_iov = &iov[k];
        mm[k].msg_hdr.msg_iovlen = 1;
        mm[k].msg_hdr.msg_name = &from[k];
        mm[k].msg_hdr.msg_namelen = sizeof(from[k]);
        mm[k].msg_hdr.msg_control = ctrl[k];
        mm[k].msg_hdr.msg_controllen = sizeof(ctrl[k]);
    }
    int n = recvmmsg(p->fd, mm, LP_RXB, MSG_DONTWAIT, NULL);
    if (n < 0) {
        if (errno != EAGAIN && errno != EINTR && lp_rate_allow(&p->err_rate, now, 3u)) {
            lp_log("node %u: UDP read on %s failed: %s", p->node, p->iface, strerror(errno));
        }
        return 0;
    }
    for (int k = 0; k < n; k++) {
        struct msghdr *mh = &mm[k].msg_hdr;
        rx_overflow(p, mh);
        p->rxlen[k] = 0;
        if (mh->msg_namelen == sizeof(from[k])) {
            p->rxfrom[k] = from[k];
        } else {
            memset(&p->rxfrom[k], 0, sizeof(p->rxfrom[k]));
        }
        if ((mh->msg_flags & MSG_TRUNC) != 0 ||
            lp_udp_decode(dg[k], mm[k].msg_len, p->zone, &p->rxb[k]) != LP_UDP_FRAME) {
            p->rx_ignored++;
            continue;
        }
        p->rxlen[k] = (uint8_t)sizeof(p->rxb[k]);
    }
    report_drops(p, now);
    return (unsigned)n;
}
#endif

/* Whether the node consumes frame cf (udp: the filter kept in software). */
static bool filter_passes(const lp_port_t *p, const struct can_frame *cf)
{
    if (!p->filt_set) {
        return true;
    }
    uint16_t id = (uint16_t)(cf->can_id & CAN_SFF_MASK);
    bool rtr = (cf->can_id & CAN_RTR_FLAG) != 0u;
    for (unsigned k = 0; k < p->nfilt; k++) {
        if (p->filt[k].id == id && p->filt[k].rtr == rtr) {
            return true;
        }
    }
    return false;
}

/* Read the next batch of messages into p->rxb; their count (0: none). */
static unsigned read_batch(lp_port_t *p, uint32_t now)
{
#ifdef HAVE_MSGPACK
    if (p->udp) {
        return udp_read_batch(p, now);
    }
#endif
    struct mmsghdr mm[LP_RXB];
    struct iovec iov[LP_RXB];
    /* control data: the drop count; aligned as a cmsghdr (size_t fields) */
    _Alignas(size_t) char ctrl[LP_RXB][CMSG_SPACE(sizeof(uint32_t))];
    memset(mm, 0, sizeof(mm));
    for (unsigned k = 0; k < LP_RXB; k++) {
        iov[k].iov_base = &p->rxb[k];
        iov[k].iov_len = sizeof(p->rxb[k]);
        mm[k].msg_hdr.msg_iov = &iov[k];
        mm[k].msg_hdr.msg_iovlen = 1;
        mm[k].msg_hdr.msg_control = ctrl[k];
        mm[k].msg_hdr.msg_controllen = sizeof(ctrl[k]);
    }
    int n = recvmmsg(p->fd, mm, LP_RXB, MSG_DONTWAIT, NULL);
    if (n < 0) {
        if (errno == EAGAIN || errno == EINTR) {
            return 0;
        }
        if (link_errno(errno)) {
            link_check(p, now, true);
        } else if (lp_rate_allow(&p->err_rate, now, 3u)) {
            lp_log("node %u: CAN read on %s failed: %s", p->node, p->iface, strerror(errno));
        }
        return 0;
    }
    for (int k = 0; k < n; k++) {
        p->rxlen[k] = (uint8_t)(mm[k].msg_len < 255u ? mm[k].msg_len : 255u);
        rx_overflow(p, &mm[k].msg_hdr);
    }
    report_drops(p, now);
    return (unsigned)n;
}

void lp_udp_share(lp_port_t *ports, unsigned n)
{
    for (unsigned i = 0; i < n; i++) {
        lp_port_t *p = &ports[i];
        if (!p->udp) {
            continue;
        }
        p->udp_reader = i;
        for (unsigned j = 0; j < i; j++) {
            const lp_port_t *q = &ports[j];
            if (q->udp && q->udp_reader == j && strcmp(q->iface, p->iface) == 0) {
                p->udp_reader = j; /* the same form: the same group, port and interface */
                close(p->fd);
                p->fd = -1;
                break;
            }
        }
    }
}

unsigned lp_udp_batch(lp_port_t *reader, uint32_t now)
{
    reader->now = now;
    reader->rxi = 0;
    reader->rxn = read_batch(reader, now);
    return reader->rxn;
}

int lp_udp_take(lp_port_t *m, const lp_port_t *reader, unsigned k, co_frame_t *f)
{
    if (k >= reader->rxn || reader->rxlen[k] == 0u) {
        return 0; /* no classic frame (udp_read_batch) */
    }
    if (reader->rxfrom[k].sin_port == m->self.sin_port &&
        reader->rxfrom[k].sin_addr.s_addr == m->self.sin_addr.s_addr) {
        return 0; /* m's own frame: a node does not hear itself */
    }
    const struct can_frame *cf = &reader->rxb[k];
    if (lp_can_state(m) == CO_CAN_BUSOFF || m->unplugged) {
        return 0; /* a controller off the bus, or its cable pulled: nothing */
    }
    if (!filter_passes(m, cf)) {
        m->rx_filtered++;
        return 0; /* not m's (the kernel's filter does this on SocketCAN) */
    }
    m->rx_frames++;
    memset(f, 0, sizeof(*f));
    f->id = (uint16_t)(cf->can_id & CAN_SFF_MASK);
    f->rtr = (cf->can_id & CAN_RTR_FLAG) != 0u;
    f->dlc = cf->len;
    memcpy(f->data, cf->data, cf->len);
    return 1;
}

int lp_read(lp_port_t *p, co_frame_t *f, uint32_t now)
{
    p->now = now;
    if (p->rxi >= p->rxn) {
        p->rxi = 0;
        p->rxn = read_batch(p, now);
        if (p->rxn == 0u) {
            return 0;
        }
    }
    if (p->udp) {
        unsigned k = p->rxi++;
        return lp_udp_take(p, p, k, f) == 1 ? 1 : 2;
    }
    const struct can_frame *cf = &p->rxb[p->rxi];
    bool classic = p->rxlen[p->rxi] == sizeof(*cf);
    p->rxi++;
    if (!classic) {
        return 2; /* not a classic CAN frame: ignored */
    }
    if ((cf->can_id & CAN_ERR_FLAG) != 0u) {
        error_frame(p, cf);
        return 2;
    }
    if (lp_can_state(p) == CO_CAN_BUSOFF || p->unplugged) {
        return 2; /* a controller off the bus, or its cable pulled: nothing */
    }
    if ((cf->can_id & CAN_EFF_FLAG) != 0u || cf->len > 8u) {
        return 2; /* 29-bit identifiers are not CANopen: ignored */
    }
    p->rx_frames++;
    memset(f, 0, sizeof(*f));
    f->id = (uint16_t)(cf->can_id & CAN_SFF_MASK);
    f->rtr = (cf->can_id & CAN_RTR_FLAG) != 0u;
    f->dlc = cf->len;
    memcpy(f->data, cf->data, cf->len);
    return 1;
}

void lp_report_drops(lp_port_t *p)
{
    if (p->rx_unlogged != 0u) {
        p->rx_rate.open = false; /* the last count goes out whatever the rate */
        report_drops(p, p->now);
    }
}

bool co_port_nvm_read(void *port, uint32_t addr, void *buf, uint32_t len)
{
    return lp_nvm_read(((lp_port_t *)port)->nvm, addr, buf, len);
}

bool co_port_nvm_write(void *port, uint32_t addr, const void *buf, uint32_t len)
{
    return lp_nvm_write(((lp_port_t *)port)->nvm, addr, buf, len);
}

/* A file is written in place: nothing to erase ahead. */
void co_port_nvm_prepare(void *port, uint32_t addr, uint32_t len)
{
    (void)port;
    (void)addr;
    (void)len;
}
