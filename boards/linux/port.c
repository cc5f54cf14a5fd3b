/*
 * port.c - the Linux board's implementation of co_port.h.
 */
#include "port.h"

#include <errno.h>
#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <stdarg.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "co_port.h"

/* The log is the process's one piece of board state outside the ports:
 * set once at start-up, only read afterwards. */
static FILE *log_file;

void lp_log_open(FILE *f)
{
    log_file = f;
}

void lp_log(const char *fmt, ...)
{
    FILE *f = log_file != NULL ? log_file : stderr;
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    fprintf(f, "[%5lld.%03ld] ", (long long)ts.tv_sec, ts.tv_nsec / 1000000L);
    va_list ap;
    va_start(ap, fmt);
    vfprintf(f, fmt, ap);
    va_end(ap);
    fputc('\n', f);
    fflush(f);
}

int lp_open(lp_port_t *p, const char *iface, unsigned node, lp_nvm_t *nvm)
{
    memset(p, 0, sizeof(*p));
    p->iface = iface;
    p->node = node;
    p->nvm = nvm;
    p->fd = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (p->fd < 0) {
        lp_log("error: CAN socket: %s (is CAN supported by this kernel? see tools/vcan-run)",
               strerror(errno));
        return -1;
    }
    struct ifreq ifr;
    memset(&ifr, 0, sizeof(ifr));
    snprintf(ifr.ifr_name, sizeof(ifr.ifr_name), "%s", iface);
    if (ioctl(p->fd, SIOCGIFINDEX, &ifr) < 0) {
        lp_log("error: interface %s: %s", iface, strerror(errno));
        close(p->fd);
        p->fd = -1;
        return -1;
    }
    can_err_mask_t mask = CAN_ERR_MASK;
    (void)setsockopt(p->fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &mask, sizeof(mask));
    struct sockaddr_can addr;
    memset(&addr, 0, sizeof(addr));
    addr.can_family = AF_CAN;
    addr.can_ifindex = ifr.ifr_ifindex;
    if (bind(p->fd, (struct sockaddr *)&addr, sizeof(addr)) < 0) {
        lp_log("error: bind %s: %s", iface, strerror(errno));
        close(p->fd);
        p->fd = -1;
        return -1;
    }
    return 0;
}

static int write_frame(lp_port_t *p, const co_frame_t *f)
{
    struct can_frame cf;
    memset(&cf, 0, sizeof(cf));
    cf.can_id = f->id | (f->rtr ? CAN_RTR_FLAG : 0u);
    cf.len = f->dlc;
    memcpy(cf.data, f->data, f->dlc);
    ssize_t n = write(p->fd, &cf, sizeof(cf));
    if (n == (ssize_t)sizeof(cf)) {
        return 1;
    }
    if (n < 0 && (errno == EAGAIN || errno == ENOBUFS)) {
        return 0; /* the kernel's queue is full: keep it for later */
    }
    lp_log("node %u: CAN write on %s failed: %s", p->node, p->iface,
           n < 0 ? strerror(errno) : "short write");
    return -1;
}

unsigned lp_flush(lp_port_t *p)
{
    while (p->txn > 0u) {
        int r = write_frame(p, &p->txq[p->txh]);
        if (r == 0) {
            break;
        }
        /* sent, or failed for good (logged): either way it leaves the queue */
        p->txh = (p->txh + 1u) % LP_TXQ;
        p->txn--;
    }
    return p->txn;
}

bool co_port_can_send(void *port, const co_frame_t *frame)
{
    lp_port_t *p = port;
    if (p->txn == 0u && write_frame(p, frame) != 0) {
        return true; /* sent (or a hard error, already logged) */
    }
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

int lp_read(lp_port_t *p, co_frame_t *f, co_can_state_t *state)
{
    struct can_frame cf;
    ssize_t n = read(p->fd, &cf, sizeof(cf));
    if (n < 0) {
        if (errno == EAGAIN || errno == EINTR) {
            return 0;
        }
        lp_log("node %u: CAN read on %s failed: %s", p->node, p->iface, strerror(errno));
        return -1;
    }
    if (n != (ssize_t)sizeof(cf)) {
        return 0; /* not a classic CAN frame: ignored */
    }
    if ((cf.can_id & CAN_ERR_FLAG) != 0u) {
        co_can_state_t s = (co_can_state_t)p->can_state;
        if ((cf.can_id & CAN_ERR_BUSOFF) != 0u) {
            s = CO_CAN_BUSOFF;
        } else if ((cf.can_id & CAN_ERR_RESTARTED) != 0u) {
            s = CO_CAN_ACTIVE;
        } else if ((cf.can_id & CAN_ERR_CRTL) != 0u) {
            uint8_t c = cf.data[1];
            if ((c & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0u) {
                s = CO_CAN_PASSIVE;
            } else if ((c & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0u) {
                s = CO_CAN_WARNING;
            } else if ((c & CAN_ERR_CRTL_ACTIVE) != 0u) {
                s = CO_CAN_ACTIVE;
            }
        }
        static const char *const names[] = {"error active", "warning", "error passive", "bus-off"};
        lp_log("node %u: CAN error frame on %s (id %08X): %s", p->node, p->iface,
               (unsigned)cf.can_id, names[s]);
        p->can_state = (int)s;
        *state = s;
        return 2;
    }
    if ((cf.can_id & CAN_EFF_FLAG) != 0u || cf.len > 8u) {
        return 0; /* 29-bit identifiers are not CANopen: ignored */
    }
    memset(f, 0, sizeof(*f));
    f->id = (uint16_t)(cf.can_id & CAN_SFF_MASK);
    f->rtr = (cf.can_id & CAN_RTR_FLAG) != 0u;
    f->dlc = cf.len;
    memcpy(f->data, cf.data, cf.len);
    return 1;
}

/* ---- EEPROM file ------------------------------------------------------ */

/* Write the whole mirror to a temporary file, fsync, rename: the file is
 * never half-written, whatever happens to the process. */
static bool commit(lp_nvm_t *n)
{
    if (n->path == NULL) {
        return true;
    }
    char tmp[4096];
    if (snprintf(tmp, sizeof(tmp), "%s.tmp", n->path) >= (int)sizeof(tmp)) {
        return false;
    }
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) {
        lp_log("error: EEPROM file %s: %s", tmp, strerror(errno));
        return false;
    }
    bool ok = write(fd, n->mem, n->size) == (ssize_t)n->size && fsync(fd) == 0;
    ok = (close(fd) == 0) && ok;
    if (!ok || rename(tmp, n->path) != 0) {
        lp_log("error: EEPROM file %s: write failed: %s", n->path, strerror(errno));
        (void)unlink(tmp);
        return false;
    }
    n->writes++;
    return true;
}

int lp_nvm_open(lp_nvm_t *n, const char *path, uint8_t *mem, uint32_t size)
{
    n->path = path;
    n->mem = mem;
    n->size = size;
    memset(mem, 0xFF, size);
    if (path == NULL) {
        lp_log("no --nvm file: parameters live in RAM and are lost at exit");
        return 0;
    }
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        if (errno != ENOENT) {
            lp_log("error: EEPROM file %s: %s", path, strerror(errno));
            return -1;
        }
        lp_log("EEPROM file %s created blank: factory defaults", path);
        return commit(n) ? 0 : -1;
    }
    ssize_t got = read(fd, mem, size);
    close(fd);
    if (got < 0) {
        lp_log("error: EEPROM file %s: %s", path, strerror(errno));
        return -1;
    }
    if ((uint32_t)got != size) {
        /* A shorter file reads as erased beyond its end, like a fresh chip. */
        memset(mem + got, 0xFF, size - (uint32_t)got);
        lp_log("EEPROM file %s has %zd of %u bytes; the rest reads as erased", path, got, size);
    }
    return 0;
}

uint32_t co_port_nvm_size(void *port)
{
    return ((lp_port_t *)port)->nvm->size;
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
    memcpy(n->mem + addr, buf, len);
    return commit(n);
}
