/*
 * bench.c - the operations tools/bench measures under callgrind, each in a
 * function of its own (bench_*) so that callgrind counts exactly its
 * instructions: frame in to response queued, and so on. Usage:
 *   bench OP N     OP: sdo-expedited, sdo-segment, tpdo, idle-poll, sync
 * The port keeps only the last frame sent: the cost measured is the stack's.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "co_port.h"
#include "dst.h"
#include "jd.h"
#include "pf.h"

static co_frame_t last;
static unsigned long sent;
static uint8_t nvm[2 * CO_STORE_NVM_SIZE];

/* No controller here: every bit rate is taken. */
bool co_port_can_bitrate(void *port, uint16_t kbps)
{
    (void)port;
    (void)kbps;
    return true;
}

bool co_port_can_send(void *port, const co_frame_t *f)
{
    (void)port;
    last = *f;
    sent++;
    return true;
}

uint32_t co_port_nvm_size(void *port)
{
    (void)port;
    return sizeof(nvm);
}

bool co_port_nvm_read(void *port, uint32_t addr, void *buf, uint32_t len)
{
    (void)port;
    memcpy(buf, &nvm[addr], len);
    return true;
}

bool co_port_nvm_write(void *port, uint32_t addr, const void *buf, uint32_t len)
{
    (void)port;
    memcpy(&nvm[addr], buf, len);
    return true;
}

static _Alignas(8) unsigned char mem[PRODUCT_INST_MAX];

static co_node_t *boot(const product_t *p)
{
    void *ports[2] = {NULL, NULL};
    co_node_t *nodes[2];
    memset(nvm, 0xFF, sizeof(nvm));
    p->create(p, mem, ports, nodes);
    int32_t v[PRODUCT_MAX_INPUTS] = {12340, -5000, 25000, 0};
    p->sample(mem, v, 0);
    co_node_start(nodes[0], 0);
    return nodes[0];
}

/* The measured operations: never inlined, one call = one operation. */
__attribute__((noinline)) void bench_receive(co_node_t *n, const co_frame_t *f);
__attribute__((noinline)) void bench_receive(co_node_t *n, const co_frame_t *f)
{
    co_node_receive(n, f);
}

__attribute__((noinline)) void bench_tpdo(co_node_t *n);
__attribute__((noinline)) void bench_tpdo(co_node_t *n)
{
    co_frame_t f;
    co_tpdo_build(n, 0, &f);
    (void)co_node_send(n, &f);
}

__attribute__((noinline)) uint32_t bench_poll(co_node_t *n, uint32_t now);
__attribute__((noinline)) uint32_t bench_poll(co_node_t *n, uint32_t now)
{
    return co_node_poll(n, now);
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: bench sdo-expedited|sdo-segment|tpdo|idle-poll|sync N\n");
        return 2;
    }
    const char *op = argv[1];
    long count = strtol(argv[2], NULL, 10);
    if (strcmp(op, "sdo-expedited") == 0) {
        co_node_t *n = boot(&dst_x730_xy30); /* read 0x6010, as a master polls it */
        co_frame_t f = {.id = 0x67F, .dlc = 8, .data = {0x40, 0x10, 0x60, 0x00}};
        for (long i = 0; i < count; i++) {
            bench_receive(n, &f);
        }
    } else if (strcmp(op, "sdo-segment") == 0) {
        co_node_t *n = boot(&pf_iny360d); /* 0x1008: 19 characters, 3 segments */
        co_frame_t init = {.id = 0x601, .dlc = 8, .data = {0x40, 0x08, 0x10, 0x00}};
        for (long i = 0; i < count; i++) {
            co_node_receive(n, &init);
            co_frame_t seg = {.id = 0x601, .dlc = 8, .data = {0x60}};
            bench_receive(n, &seg); /* the first segment: 7 bytes */
            seg.data[0] = 0x70;
            co_node_receive(n, &seg);
            seg.data[0] = 0x60;
            co_node_receive(n, &seg);
        }
    } else if (strcmp(op, "tpdo") == 0) {
        co_node_t *n = boot(&dst_x730_xy30); /* X and Y, 8 bytes */
        co_frame_t start = {.id = 0x000, .dlc = 2, .data = {0x01, 0x7F}};
        co_node_receive(n, &start);
        for (long i = 0; i < count; i++) {
            bench_tpdo(n);
        }
    } else if (strcmp(op, "idle-poll") == 0) {
        co_node_t *n = boot(&dst_x730_xy30); /* pre-operational, nothing due */
        for (long i = 0; i < count; i++) {
            (void)bench_poll(n, (uint32_t)i);
        }
    } else if (strcmp(op, "sync") == 0) {
        co_node_t *n = boot(&jd2xxx); /* two TPDOs, both synchronous (type 1) */
        co_frame_t start = {.id = 0x000, .dlc = 2, .data = {0x01, 0x0A}};
        co_node_receive(n, &start);
        co_frame_t sync = {.id = 0x080, .dlc = 0};
        for (long i = 0; i < count; i++) {
            bench_receive(n, &sync);
        }
    } else {
        fprintf(stderr, "bench: unknown operation %s\n", op);
        return 2;
    }
    printf("%s x %ld: %lu frames sent\n", op, count, sent);
    return sent == 0 && strcmp(op, "idle-poll") != 0 ? 1 : 0;
}
