/*
 * udp_bus.h - python-can's udp_multicast bus: CAN frames as MessagePack
 * maps in UDP datagrams sent to an IP multicast group, so that processes
 * on one machine (or one network) share a bus without CAN in the kernel.
 *
 * The interface form (--iface, --node .../IFACE):
 *   udp_multicast:GROUP[:PORT][%IFNAME]
 * GROUP an IPv4 multicast address (224.0.0.0/4), PORT default 43113 (the
 * python-can default), IFNAME the interface the group is joined and sent
 * on (lo: the machine only). Without %IFNAME the kernel's routing table
 * chooses, as python-can does: on a networked host that is the default
 * route's interface, and the frames leave the host (TTL 1: the local
 * network, not beyond a router). docs/simulated-bus.md says more.
 *
 * The wire format is python-can's (can/interfaces/udp_multicast/utils.py,
 * pack_message): one datagram a frame, a map of eleven entries in this
 * order: "timestamp" (float, seconds), "arbitration_id" (unsigned),
 * "is_extended_id", "is_remote_frame", "is_error_frame" (booleans),
 * "channel" (nil here), "dlc" (unsigned), "data" (binary: the data bytes,
 * none for a remote frame), "is_fd", "bitrate_switch",
 * "error_state_indicator" (booleans). It is encoded and decoded with
 * msgpack-c (Debian's libmsgpack-dev).
 */
#ifndef LINUX_UDP_BUS_H
#define LINUX_UDP_BUS_H

#include <linux/can.h>
#include <net/if.h>
#include <netinet/in.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "co_common.h"

#define LP_UDP_PREFIX "udp_multicast:"
#define LP_UDP_PORT 43113u
/* An interface name in this form is longer than a kernel's (IFNAMSIZ). */
#define LP_IFACE_MAX 64u
/* A datagram larger than this is no classic CAN frame of python-can's
 * (about 170 bytes): ignored. */
#define LP_UDP_DGRAM_MAX 1024u

typedef struct lp_udp_addr {
    struct sockaddr_in group; /* address and port */
    unsigned ifindex;         /* 0: the routing table chooses */
    char ifname[IFNAMSIZ];    /* "" with ifindex 0 */
} lp_udp_addr_t;

/* Whether iface names a udp_multicast bus (the prefix; also in a build
 * without msgpack-c, which refuses it by name). */
static inline bool lp_udp_is(const char *iface)
{
    return strncmp(iface, LP_UDP_PREFIX, sizeof(LP_UDP_PREFIX) - 1u) == 0;
}

/*
 * Parse the interface form above into *a. Returns 0, or -1 with a one-line
 * cause in err (errlen bytes). The interface, when named, must exist.
 */
int lp_udp_parse(const char *iface, lp_udp_addr_t *a, char *err, unsigned errlen);

/*
 * Open the two sockets of one node on the bus: *rx bound to the group and
 * its port, joined on the interface (every member's datagrams, its own
 * included); *tx connected to the group, TTL 1, loopback on (other
 * processes of this machine hear it), whose own address goes to *self, by
 * which *rx tells the node's own datagrams from the others'. Both
 * non-blocking. Returns 0, or -1 with the cause in err.
 */
int lp_udp_open(const lp_udp_addr_t *a, int *rx, int *tx, struct sockaddr_in *self, char *err,
                unsigned errlen);

/*
 * One frame as python-can packs it, into buf (cap bytes), its wall-clock
 * time ts (seconds). Returns the datagram's length, 0 if it does not fit.
 */
size_t lp_udp_encode(const co_frame_t *f, double ts, uint8_t *buf, size_t cap);

typedef enum lp_udp_verdict {
    LP_UDP_FRAME = 0,   /* a classic CAN frame: *cf filled */
    LP_UDP_NOT_CLASSIC, /* a CAN FD, error or 29-bit frame: not CANopen's */
    LP_UDP_MALFORMED,   /* not a frame python-can would accept */
} lp_udp_verdict_t;

/*
 * Decode one datagram (len bytes) into *cf (can_id with CAN_RTR_FLAG /
 * CAN_EFF_FLAG, len, data). Missing entries take python-can's defaults
 * (an identifier without "is_extended_id" is a 29-bit one). Allocates
 * nothing per call beyond what the datagram's size bounds (msgpack-c's
 * zone, one per port, cleared each time).
 */
lp_udp_verdict_t lp_udp_decode(const uint8_t *buf, size_t len, void *zone, struct can_frame *cf);

/* A decoding zone (msgpack-c's), its first chunk allocated here once; NULL
 * when memory is short. */
void *lp_udp_zone_new(void);
void lp_udp_zone_free(void *zone);

#endif
