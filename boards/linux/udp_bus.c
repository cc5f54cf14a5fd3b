/*
 * udp_bus.c - python-can's udp_multicast bus; see udp_bus.h.
 */
#include "udp_bus.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <msgpack.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

int lp_udp_parse(const char *iface, lp_udp_addr_t *a, char *err, unsigned errlen)
{
    memset(a, 0, sizeof(*a));
    char buf[LP_IFACE_MAX];
    const char *spec = iface + sizeof(LP_UDP_PREFIX) - 1u;
    if (snprintf(buf, sizeof(buf), "%s", spec) >= (int)sizeof(buf)) {
        snprintf(err, errlen, "longer than %u characters", LP_IFACE_MAX - 1u);
        return -1;
    }
    char *pct = strchr(buf, '%');
    if (pct != NULL) {
        *pct = '\0';
        const char *name = pct + 1;
        if (name[0] == '\0' || strlen(name) >= IFNAMSIZ) {
            snprintf(err, errlen, "'%s' after %% is not an interface name", name);
            return -1;
        }
        a->ifindex = if_nametoindex(name);
        if (a->ifindex == 0u) {
            snprintf(err, errlen, "%s: no such network interface", name);
            return -1;
        }
        snprintf(a->ifname, sizeof(a->ifname), "%s", name);
    }
    if (buf[0] == '[') {
        snprintf(err, errlen,
                 "an IPv6 group: only IPv4 groups (224.0.0.0/4, python-can: "
                 "channel='239.74.163.2') are supported");
        return -1;
    }
    unsigned long port = LP_UDP_PORT;
    char *colon = strchr(buf, ':');
    if (colon != NULL) {
        *colon = '\0';
        char *end;
        errno = 0;
        port = strtoul(colon + 1, &end, 10);
        if (colon[1] < '0' || colon[1] > '9' || *end != '\0' || errno != 0 || port == 0u ||
            port > 65535u) {
            snprintf(err, errlen, "'%s' is not a UDP port (1-65535)", colon + 1);
            return -1;
        }
    }
    a->group.sin_family = AF_INET;
    a->group.sin_port = htons((uint16_t)port);
    if (inet_pton(AF_INET, buf, &a->group.sin_addr) != 1) {
        snprintf(err, errlen,
                 "'%s' is not an IPv4 address (an IPv4 multicast group, e.g. "
                 "239.74.163.2)",
                 buf);
        return -1;
    }
    if (!IN_MULTICAST(ntohl(a->group.sin_addr.s_addr))) {
        snprintf(err, errlen, "%s is not a multicast group (224.0.0.0/4)", buf);
        return -1;
    }
    return 0;
}

/* Close fd (when open) and fill err with what failed; -1. */
static int fail(int fd, const char *what, char *err, unsigned errlen)
{
    snprintf(err, errlen, "%s: %s", what, strerror(errno));
    if (fd >= 0) {
        close(fd);
    }
    return -1;
}

int lp_udp_open(const lp_udp_addr_t *a, int *rx, int *tx, struct sockaddr_in *self, char *err,
                unsigned errlen)
{
    *rx = -1;
    *tx = -1;
    int r = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (r < 0) {
        return fail(-1, "UDP socket", err, errlen);
    }
    int one = 1;
    int zero = 0;
    /* Every member on this machine binds the group's port. */
    if (setsockopt(r, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one)) < 0 ||
        setsockopt(r, SOL_SOCKET, SO_REUSEPORT, &one, sizeof(one)) < 0) {
        return fail(r, "SO_REUSEADDR/SO_REUSEPORT", err, errlen);
    }
    /* Only this group's datagrams (bound to its address), only of the
     * groups this socket joined (Linux's default takes every group any
     * socket of the machine joined on this port). */
    (void)setsockopt(r, IPPROTO_IP, IP_MULTICAST_ALL, &zero, sizeof(zero));
    int rcvbuf = 1 << 20; /* bursts of many nodes; the kernel caps it */
    (void)setsockopt(r, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof(rcvbuf));
    (void)setsockopt(r, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof(one));
    if (bind(r, (const struct sockaddr *)&a->group, sizeof(a->group)) < 0) {
        return fail(r, "bind to the group", err, errlen);
    }
    struct ip_mreqn mreq;
    memset(&mreq, 0, sizeof(mreq));
    mreq.imr_multiaddr = a->group.sin_addr;
    mreq.imr_ifindex = (int)a->ifindex;
    if (setsockopt(r, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof(mreq)) < 0) {
        return fail(r,
                    a->ifindex != 0u ? "joining the group on the interface"
                                     : "joining the group (no multicast route? name the "
                                       "interface: %lo for this machine)",
                    err, errlen);
    }
    int t = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (t < 0) {
        close(r);
        return fail(-1, "UDP socket", err, errlen);
    }
    int ttl = 1; /* as python-can's default hop limit: not beyond a router */
    (void)setsockopt(t, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof(ttl));
    (void)setsockopt(t, IPPROTO_IP, IP_MULTICAST_LOOP, &one, sizeof(one));
    struct ip_mreqn ifreq;
    memset(&ifreq, 0, sizeof(ifreq));
    ifreq.imr_ifindex = (int)a->ifindex;
    if (a->ifindex != 0u && setsockopt(t, IPPROTO_IP, IP_MULTICAST_IF, &ifreq, sizeof(ifreq)) < 0) {
        close(r);
        return fail(t, "sending on the interface", err, errlen);
    }
    /* Connected: the kernel chooses the source address and port now, which
     * the receiving side compares with each datagram's sender. */
    if (connect(t, (const struct sockaddr *)&a->group, sizeof(a->group)) < 0) {
        close(r);
        return fail(t, "no route to the group (name the interface: %lo for this machine)", err,
                    errlen);
    }
    socklen_t sl = sizeof(*self);
    if (getsockname(t, (struct sockaddr *)self, &sl) < 0) {
        close(r);
        return fail(t, "getsockname", err, errlen);
    }
    *rx = r;
    *tx = t;
    return 0;
}

/* ---- the wire ------------------------------------------------------------ */

typedef struct outbuf {
    uint8_t *p;
    size_t cap, len;
    bool overflow;
} outbuf_t;

static int out_write(void *data, const char *buf, size_t len)
{
    outbuf_t *o = data;
    if (len > o->cap - o->len) {
        o->overflow = true;
        return -1;
    }
    memcpy(o->p + o->len, buf, len);
    o->len += len;
    return 0;
}

static void key(msgpack_packer *pk, const char *k)
{
    size_t n = strlen(k);
    msgpack_pack_str(pk, n);
    msgpack_pack_str_body(pk, k, n);
}

static void flag(msgpack_packer *pk, const char *k, bool v)
{
    key(pk, k);
    if (v) {
        msgpack_pack_true(pk);
    } else {
        msgpack_pack_false(pk);
    }
}

/* buf is written through the packer's callback (out_write), which the
 * check does not follow. */
/* NOLINTNEXTLINE(readability-non-const-parameter) */
size_t lp_udp_encode(const co_frame_t *f, double ts, uint8_t *buf, size_t cap)
{
    outbuf_t o = {.p = buf, .cap = cap};
    msgpack_packer pk;
    msgpack_packer_init(&pk, &o, out_write);
    uint8_t dlc = f->dlc > 8u ? 8u : f->dlc;
    msgpack_pack_map(&pk, 11);
    key(&pk, "timestamp");
    msgpack_pack_double(&pk, ts);
    key(&pk, "arbitration_id");
    msgpack_pack_uint32(&pk, f->id);
    flag(&pk, "is_extended_id", false);
    flag(&pk, "is_remote_frame", f->rtr);
    flag(&pk, "is_error_frame", false);
    key(&pk, "channel");
    msgpack_pack_nil(&pk);
    key(&pk, "dlc");
    msgpack_pack_uint8(&pk, dlc);
    key(&pk, "data"); /* python-can: a remote frame carries no data, its DLC only */
    size_t n = f->rtr ? 0u : dlc;
    msgpack_pack_bin(&pk, n);
    msgpack_pack_bin_body(&pk, f->data, n);
    flag(&pk, "is_fd", false);
    flag(&pk, "bitrate_switch", false);
    flag(&pk, "error_state_indicator", false);
    return o.overflow ? 0u : o.len;
}

void *lp_udp_zone_new(void)
{
    return msgpack_zone_new(2048);
}

void lp_udp_zone_free(void *zone)
{
    if (zone != NULL) {
        msgpack_zone_free(zone);
    }
}

static bool key_is(const msgpack_object *k, const char *s)
{
    size_t n = strlen(s);
    return k->type == MSGPACK_OBJECT_STR && k->via.str.size == n &&
           memcmp(k->via.str.ptr, s, n) == 0;
}

/* A boolean entry: its value, false when it is no boolean (*ok cleared). */
static bool as_bool(const msgpack_object *v, bool *ok)
{
    if (v->type != MSGPACK_OBJECT_BOOLEAN) {
        *ok = false;
        return false;
    }
    return v->via.boolean;
}

lp_udp_verdict_t lp_udp_decode(const uint8_t *buf, size_t len, void *zone, struct can_frame *cf)
{
    msgpack_zone *z = zone;
    if (z == NULL) {
        return LP_UDP_MALFORMED;
    }
    msgpack_zone_clear(z);
    msgpack_object obj;
    size_t off = 0;
    msgpack_unpack_return ur = msgpack_unpack((const char *)buf, len, &off, z, &obj);
    if (ur != MSGPACK_UNPACK_SUCCESS || off != len || obj.type != MSGPACK_OBJECT_MAP) {
        return LP_UDP_MALFORMED;
    }
    /* python-can's Message defaults for what a datagram leaves out */
    uint64_t id = 0;
    bool ext = true;
    bool rtr = false;
    bool error = false;
    bool fd = false;
    bool has_dlc = false;
    uint64_t dlc = 0;
    const uint8_t *data = NULL;
    size_t ndata = 0;
    bool ok = true;
    for (uint32_t k = 0; k < obj.via.map.size && ok; k++) {
        const msgpack_object *kk = &obj.via.map.ptr[k].key;
        const msgpack_object *v = &obj.via.map.ptr[k].val;
        if (key_is(kk, "arbitration_id")) {
            ok = v->type == MSGPACK_OBJECT_POSITIVE_INTEGER;
            id = v->via.u64;
        } else if (key_is(kk, "is_extended_id")) {
            ext = as_bool(v, &ok);
        } else if (key_is(kk, "is_remote_frame")) {
            rtr = as_bool(v, &ok);
        } else if (key_is(kk, "is_error_frame")) {
            error = as_bool(v, &ok);
        } else if (key_is(kk, "is_fd")) {
            fd = as_bool(v, &ok);
        } else if (key_is(kk, "bitrate_switch") || key_is(kk, "error_state_indicator")) {
            (void)as_bool(v, &ok);
        } else if (key_is(kk, "dlc")) {
            if (v->type != MSGPACK_OBJECT_NIL) {
                ok = v->type == MSGPACK_OBJECT_POSITIVE_INTEGER;
                dlc = v->via.u64;
                has_dlc = true;
            }
        } else if (key_is(kk, "data")) {
            if (v->type == MSGPACK_OBJECT_BIN) {
                data = (const uint8_t *)v->via.bin.ptr;
                ndata = v->via.bin.size;
            } else {
                ok = v->type == MSGPACK_OBJECT_NIL;
            }
        } else if (key_is(kk, "timestamp")) {
            ok = v->type == MSGPACK_OBJECT_FLOAT64 || v->type == MSGPACK_OBJECT_FLOAT32 ||
                 v->type == MSGPACK_OBJECT_POSITIVE_INTEGER;
        } else if (key_is(kk, "channel")) {
            /* any value: python-can passes it through */
        } else {
            ok = false; /* python-can's Message() takes no other argument */
        }
    }
    if (!ok) {
        return LP_UDP_MALFORMED;
    }
    if (!has_dlc) {
        dlc = ndata;
    }
    /* python-can's own check (Message(check=True)) */
    if (ndata > 64u || dlc > (fd ? 64u : 8u) || (!rtr && dlc != ndata) || (rtr && ndata != 0u) ||
        id > CAN_EFF_MASK || (!ext && id > CAN_SFF_MASK) || (rtr && (error || fd))) {
        return LP_UDP_MALFORMED;
    }
    if (error || fd || ext) {
        return LP_UDP_NOT_CLASSIC;
    }
    memset(cf, 0, sizeof(*cf));
    cf->can_id = (canid_t)id | (rtr ? CAN_RTR_FLAG : 0u);
    cf->len = (uint8_t)dlc;
    if (!rtr && ndata != 0u) {
        memcpy(cf->data, data, ndata);
    }
    return LP_UDP_FRAME;
}
