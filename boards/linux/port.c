/*
 * port.c - the Linux board's implementation of co_port.h; see port.h.
 */
#include "port.h"

#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <limits.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <linux/if_arp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include "co_port.h"

/* The log is the process's one piece of board state outside the ports
 * (its file, time zero and clock): set once at start-up, only read
 * afterwards. */
static FILE *log_file;
static struct timespec log_t0;
static bool log_wall;

void lp_log_open(FILE *f)
{
    log_file = f;
}

void lp_log_start(void)
{
    clock_gettime(CLOCK_MONOTONIC, &log_t0);
}

void lp_log_clock(bool wall)
{
    log_wall = wall;
}

void lp_log(const char *fmt, ...)
{
    FILE *f = log_file != NULL ? log_file : stderr;
    struct timespec ts;
    if (log_wall) {
        /* UTC: a log compared with another machine's, or read in another
         * zone, needs no zone to be known */
        clock_gettime(CLOCK_REALTIME, &ts);
        struct tm tm;
        char when[32];
        gmtime_r(&ts.tv_sec, &tm);
        strftime(when, sizeof(when), "%Y-%m-%d %H:%M:%S", &tm);
        fprintf(f, "[%s.%03ld] ", when, ts.tv_nsec / 1000000L);
    } else {
        /* Seconds since the start (the kernel's boot meant nothing to a reader) */
        clock_gettime(CLOCK_MONOTONIC, &ts);
        long long ns = ((long long)ts.tv_sec - (long long)log_t0.tv_sec) * 1000000000LL +
                       (ts.tv_nsec - log_t0.tv_nsec);
        fprintf(f, "[%4lld.%03lld] ", ns / 1000000000LL, ns / 1000000LL % 1000LL);
    }
    va_list ap;
    va_start(ap, fmt);
    vfprintf(f, fmt, ap);
    va_end(ap);
    fputc('\n', f);
    fflush(f);
}

bool lp_rate_allow(lp_rate_t *r, uint32_t now, unsigned lines)
{
    if (!r->open || !co_time_before(now, r->start + LP_RATE_US)) {
        r->open = true;
        r->start = now;
        r->shown = 0;
    }
    if (r->shown < lines) {
        r->shown++;
        return true;
    }
    return false;
}

uint32_t lp_rate_wait(const lp_rate_t *r, uint32_t now)
{
    return r->open ? co_time_until(now, r->start + LP_RATE_US) : 0u;
}

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
               "ms)", p->node, p->iface, again, LP_LINK_POLL_US / 1000u);
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
        snprintf(err, errlen, "CAN socket: %s (is CAN supported by this kernel? see tools/vcan-run)",
                 strerror(errno));
    }
    return fd;
}

int lp_open(lp_port_t *p, const char *iface, unsigned node, lp_nvm_t *nvm, uint32_t now,
            char *err, unsigned errlen)
{
    memset(p, 0, sizeof(*p));
    p->iface = iface;
    p->node = node;
    p->nvm = nvm;
    p->now = now;
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
        lp_log("node %u: simulated CAN controller: bus usable again, back from bus-off in "
               "%u.%03u ms", p->node, recovery_us / 1000u, recovery_us % 1000u);
    } else {
        p->sim_state = (int)s;
        lp_log("node %u: simulated CAN controller %s", p->node, state_names[s]);
    }
}

static void report_drops(lp_port_t *p, uint32_t now)
{
    if (p->rx_unlogged != 0u && lp_rate_allow(&p->rx_rate, now, 1u)) {
        lp_log("node %u: %lu received frames dropped on %s (socket receive queue full; "
               "%lu in all)", p->node, p->rx_unlogged, p->iface, p->rx_dropped);
        p->rx_unlogged = 0;
    }
}

uint32_t lp_poll(lp_port_t *p, uint32_t now)
{
    p->now = now;
    uint32_t next = CO_NEVER;
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
            p->sim_state = CO_CAN_ACTIVE;
            lp_log("node %u: simulated CAN controller back from bus-off: error active", p->node);
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
    struct can_filter cf[CO_NODE_RX_IDS_MAX];
    for (unsigned k = 0; k < p->nfilt; k++) {
        cf[k].can_id = p->filt[k].id | (p->filt[k].rtr ? CAN_RTR_FLAG : 0u);
        cf[k].can_mask = CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG;
    }
    p->filt_changes++;
    if (setsockopt(p->fd, SOL_CAN_RAW, CAN_RAW_FILTER, cf,
                   (socklen_t)(p->nfilt * sizeof(cf[0]))) == 0) {
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
            return 0;
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

bool co_port_can_send(void *port, const co_frame_t *frame)
{
    lp_port_t *p = port;
    if (p->filt_node != NULL) {
        lp_filter(p, p->filt_node); /* the filter first, then the answer (port.h) */
    }
    if (lp_can_state(p) == CO_CAN_BUSOFF) {
        p->tx_off++; /* a controller off the bus sends nothing */
        return false;
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
    lp_log("node %u: CAN error frame on %s (id %08X): %s", p->node, p->iface,
           (unsigned)cf->can_id, state_names[s]);
    if (s == CO_CAN_BUSOFF) {
        drop_txq(p);
    }
    p->ctrl_state = (int)s;
}

/* Read the next batch of messages into p->rxb; their count (0: none). */
static unsigned read_batch(lp_port_t *p, uint32_t now)
{
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
        struct msghdr *mh = &mm[k].msg_hdr;
        p->rxlen[k] = (uint8_t)(mm[k].msg_len < 255u ? mm[k].msg_len : 255u);
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
    report_drops(p, now);
    return (unsigned)n;
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
    if (lp_can_state(p) == CO_CAN_BUSOFF) {
        return 2; /* a controller off the bus receives nothing */
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

/* ---- EEPROM file ------------------------------------------------------ */

/* Write all of len bytes; false with errno set (a short write: ENOSPC). */
static bool write_all(int fd, const struct iovec *iov, int cnt)
{
    struct iovec v[3];
    memcpy(v, iov, (size_t)cnt * sizeof(v[0]));
    int i = 0;
    while (i < cnt) {
        ssize_t n = writev(fd, &v[i], cnt - i);
        if (n < 0) {
            if (errno == EINTR) {
                continue;
            }
            return false;
        }
        if (n == 0) {
            errno = ENOSPC;
            return false;
        }
        size_t left = (size_t)n;
        while (i < cnt && left >= v[i].iov_len) {
            left -= v[i].iov_len;
            i++;
        }
        if (i < cnt) {
            v[i].iov_base = (char *)v[i].iov_base + left;
            v[i].iov_len -= left;
        }
    }
    return true;
}

/*
 * The file with len bytes at addr replaced by buf: written whole to a
 * temporary file beside it, fsync, rename, fsync of the directory, so the
 * file is never half-written, whatever happens to the process. The mirror
 * is changed only when all of that worked, so it always equals the file.
 * The cause of a failure is logged (strerror).
 */
static bool commit(lp_nvm_t *n, uint32_t addr, const void *buf, uint32_t len)
{
    if (n->path == NULL) {
        memcpy(n->mem + addr, buf, len);
        return true;
    }
    char tmp[sizeof(n->real) + 8];
    snprintf(tmp, sizeof(tmp), "%s.tmp", n->real);
    /* O_NOFOLLOW: a symbolic link at the temporary name is an error, not
     * a way to write elsewhere. */
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0) {
        lp_log("error: EEPROM file %s: save failed: cannot create %s: %s (the file keeps its "
               "previous contents)", n->real, tmp, strerror(errno));
        return false;
    }
    const struct iovec iov[3] = {
        {.iov_base = n->mem, .iov_len = addr},
        /* iov_base is not const, writev only reads it: const dropped through uintptr_t */
        {.iov_base = (void *)(uintptr_t)buf, .iov_len = len}, /* NOLINT(performance-no-int-to-ptr) */
        {.iov_base = n->mem + addr + len, .iov_len = n->size - addr - len},
    };
    const char *step = "write";
    bool ok = write_all(fd, iov, 3);
    if (ok && fsync(fd) != 0) {
        step = "fsync";
        ok = false;
    }
    int e = errno;
    if (close(fd) != 0 && ok) {
        step = "close";
        ok = false;
        e = errno;
    }
    if (ok && rename(tmp, n->real) != 0) {
        step = "rename";
        ok = false;
        e = errno;
    }
    if (!ok) {
        lp_log("error: EEPROM file %s: save failed (%s): %s (the file keeps its previous "
               "contents)", n->real, step, strerror(e));
        (void)unlink(tmp);
        return false;
    }
    /* The rename is durable once the directory is on disk too. */
    char dir[sizeof(n->real)];
    snprintf(dir, sizeof(dir), "%s", n->real);
    int dfd = open(dirname(dir), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
        (void)fsync(dfd);
        close(dfd);
    }
    memcpy(n->mem + addr, buf, len);
    return true;
}

static const char *file_kind(mode_t m)
{
    return S_ISDIR(m) ? "a directory" : S_ISFIFO(m) ? "a FIFO" : S_ISCHR(m) ? "a character device"
         : S_ISBLK(m) ? "a block device" : S_ISSOCK(m) ? "a socket" : "not a regular file";
}

int lp_nvm_open(lp_nvm_t *n, const char *opt, const char *path, uint8_t *mem, uint32_t size,
                char *err, unsigned errlen)
{
    memset(n, 0, sizeof(*n));
    n->mem = mem;
    n->size = size;
    memset(mem, 0xFF, size);
    if (path == NULL) {
        lp_log("no --nvm file: parameters live in RAM and are lost at exit");
        return 0;
    }
    /* Look before opening anything: open() of a FIFO blocks, and a save
     * would replace a device or a FIFO by a regular file. */
    struct stat st;
    if (stat(path, &st) == 0) {
        if (!S_ISREG(st.st_mode)) {
            snprintf(err, errlen, "%s %s: %s, not a regular file", opt, path,
                     file_kind(st.st_mode));
            return -2;
        }
        if (realpath(path, n->real) == NULL) {
            snprintf(err, errlen, "%s %s: %s", opt, path, strerror(errno));
            return -2;
        }
    } else if (errno == ENOENT && lstat(path, &st) == 0 && S_ISLNK(st.st_mode)) {
        /* A link to nothing: the first save would replace the link by a
         * file (rename over it), not create what it names. Refused. */
        char to[256];
        ssize_t tl = readlink(path, to, sizeof(to) - 1u);
        to[tl > 0 ? tl : 0] = '\0';
        snprintf(err, errlen, "%s %s: a symbolic link to %s, which does not exist (create the "
                 "file, or give the path without the link)", opt, path, to);
        return -2;
    } else if (errno == ENOENT) {
        /* A new file: its directory must exist (the first save creates the file). */
        char d[sizeof(n->real)];
        char b[sizeof(n->real)];
        if (snprintf(d, sizeof(d), "%s", path) >= (int)sizeof(d)) {
            snprintf(err, errlen, "%s %s: path too long", opt, path);
            return -2;
        }
        snprintf(b, sizeof(b), "%s", path);
        const char *dir = dirname(d);
        const char *base = basename(b);
        struct stat ds;
        char rdir[PATH_MAX];
        if (stat(dir, &ds) != 0 || !S_ISDIR(ds.st_mode) || realpath(dir, rdir) == NULL) {
            snprintf(err, errlen, "%s %s: directory %s does not exist", opt, path, dir);
            return -2;
        }
        if (strcmp(base, "/") == 0 || strcmp(base, ".") == 0 || strcmp(base, "..") == 0 ||
            snprintf(n->real, sizeof(n->real), "%s/%s", strcmp(rdir, "/") == 0 ? "" : rdir,
                     base) >= (int)sizeof(n->real)) {
            snprintf(err, errlen, "%s %s: not a file name", opt, path);
            return -2;
        }
        n->path = n->real;
        lp_log("EEPROM file %s does not exist yet: factory defaults; the first save creates it",
               n->real);
        return 0;
    } else {
        snprintf(err, errlen, "%s %s: %s", opt, path, strerror(errno));
        return -2;
    }
    n->path = n->real;
    /* O_NONBLOCK: should the path have become a FIFO since stat(), open
     * returns at once; fstat then refuses it. */
    int fd = open(n->real, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        snprintf(err, errlen, "%s %s: cannot read: %s", opt, path, strerror(errno));
        return -1;
    }
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        snprintf(err, errlen, "%s %s: not a regular file", opt, path);
        return -2;
    }
    size_t got = 0;
    while (got < size) {
        ssize_t r = read(fd, mem + got, size - got);
        if (r < 0 && errno == EINTR) {
            continue;
        }
        if (r < 0) {
            int e = errno;
            close(fd);
            memset(mem, 0xFF, size);
            snprintf(err, errlen, "%s %s: cannot read: %s", opt, path, strerror(e));
            return -1;
        }
        if (r == 0) {
            break;
        }
        got += (size_t)r;
    }
    close(fd);
    if (got < size) {
        /* A shorter file reads as erased beyond its end, like a fresh chip;
         * the file itself is left alone until a save. */
        memset(mem + got, 0xFF, size - got);
        lp_log("EEPROM file %s has %zu of %u bytes; the rest reads as erased", n->real, got,
               size);
    } else if (st.st_size > (off_t)size) {
        lp_log("EEPROM file %s has %lld bytes, more than the %u used; the rest is ignored (and "
               "left out at the next save)", n->real, (long long)st.st_size, size);
    }
    return 0;
}

int lp_nvm_lock(lp_nvm_t *n, const char *opt, const char *path, char *err, unsigned errlen)
{
    n->lock_fd = -1;
    if (n->path == NULL) {
        return 0;
    }
    /* Not flock() on the file, as tools/emu does for its flash: every save
     * replaces the file (a new inode, whose lock nobody holds), and the
     * first save creates it. The name is held instead: an abstract unix
     * socket (no file on disk; gone with the process, however it ends)
     * named by a hash (FNV-1a, 64 bits) of the resolved path. */
    uint64_t h = 0xCBF29CE484222325u;
    for (const char *c = n->real; *c != '\0'; c++) {
        h = (h ^ (uint8_t)*c) * 0x100000001B3u;
    }
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    int len = snprintf(sa.sun_path + 1, sizeof(sa.sun_path) - 1u, "canopen-sensor/nvm/%016llx",
                       (unsigned long long)h);
    int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    socklen_t salen = (socklen_t)(offsetof(struct sockaddr_un, sun_path) + 1u + (size_t)len);
    if (fd < 0 || bind(fd, (const struct sockaddr *)&sa, salen) != 0) {
        int e = errno;
        if (fd >= 0) {
            close(fd);
        }
        if (e == EADDRINUSE) {
            snprintf(err, errlen, "%s %s: EEPROM file %s is in use by another canopen-sensor "
                     "process (two users would overwrite each other's saves)", opt, path, n->real);
            return -2;
        }
        snprintf(err, errlen, "%s %s: cannot hold the file: %s", opt, path, strerror(e));
        return -1;
    }
    n->lock_fd = fd;
    return 0;
}

void lp_nvm_unlock(lp_nvm_t *n)
{
    if (n->lock_fd > 0) {
        close(n->lock_fd);
    }
    n->lock_fd = -1;
}

bool co_port_nvm_read(void *port, uint32_t addr, void *buf, uint32_t len)
{
    lp_nvm_t *n = ((lp_port_t *)port)->nvm;
    if (addr > n->size || len > n->size - addr) {
        return false;
    }
    memcpy(buf, n->mem + addr, len);
    return true;
}

bool co_port_nvm_write(void *port, uint32_t addr, const void *buf, uint32_t len)
{
    lp_nvm_t *n = ((lp_port_t *)port)->nvm;
    if (addr > n->size || len > n->size - addr) {
        return false;
    }
    return commit(n, addr, buf, len);
}
