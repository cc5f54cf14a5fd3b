/*
 * bench.c - the operations tools/bench measures under callgrind, each in a
 * function of its own (bench_*) so that callgrind counts exactly its
 * instructions: frame in to response queued, and so on. Usage:
 *   bench OP N     OP: sdo-expedited, sdo-segment, tpdo, idle-poll, sync
 * The port keeps only the last frame sent: the cost measured is the stack's
 * and that one copy of the frame (as a real port copies it to the
 * controller). The last frame is checked at the end (finish()): the figure
 * is of the path named, not of an abort; and since it is read, the compiler
 * keeps the copy (until tools/bench checked it, nothing read it and the
 * copy was dropped: 4 instructions a frame on x86-64, 81 on the Cortex-M0
 * with the byte-wise memcpy of boards/common/libc_min.c), and with LTO it
 * cannot drop the stack's work that only fed the frame either.
 *
 * The same file is the Cortex-M0 benchmark (tests/bench/m0.cmake): built
 * with BENCH_BARE=<operation number> it is one image per operation, linked
 * with that product's fixed config as its MCU image is, and counted by
 * tools/m0count.py under qemu-system-arm's instruction trace. There main()
 * runs BENCH_N operations (no command line), prints over semihosting and
 * exits with the same status as here.
 */
#include <string.h>
#ifdef BENCH_BARE
#include "bare_io.h"
#else
#include <stdio.h>
#include <stdlib.h>
#endif

#include "co_port.h"
#include "dst.h"
#include "jd.h"
#include "pf.h"
#include "product_registry.h"

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

void co_port_nvm_prepare(void *port, uint32_t addr, uint32_t len)
{
    (void)port;
    (void)addr;
    (void)len;
}

static _Alignas(8) unsigned char mem[sizeof(product_any_t)];

static co_node_t *boot(const product_t *p)
{
#ifdef CO_FIXED_CFG
    /* An image of one fixed config runs only that config's products. */
    if (p->cfg != &CO_FIXED_CFG) {
        printf("bench: %s is not built with this image's config\n", p->id);
        bare_exit(2);
    }
#endif
    void *ports[2] = {NULL, NULL};
    co_node_t *nodes[2];
    memset(nvm, 0xFF, sizeof(nvm));
    p->create(p, mem, ports, nodes);
    int32_t v[PRODUCT_MAX_INPUTS] = {12340, -5000, 25000, 0};
    p->sample(mem, v, 0);
    co_node_start(nodes[0], 0);
    return nodes[0];
}

/* The measured operations: never inlined, one call = one operation. On the
 * Cortex-M0 not cloned either: tools/m0count.py finds them by name. */
#ifdef BENCH_BARE
#define BENCH_MEASURED __attribute__((noinline, noclone, used))
#else
#define BENCH_MEASURED __attribute__((noinline))
#endif
BENCH_MEASURED void bench_receive(co_node_t *n, const co_frame_t *f, uint32_t now);
BENCH_MEASURED void bench_receive(co_node_t *n, const co_frame_t *f, uint32_t now)
{
    co_node_receive(n, f, now);
}

BENCH_MEASURED void bench_tpdo(co_node_t *n);
BENCH_MEASURED void bench_tpdo(co_node_t *n)
{
    co_frame_t f;
    co_tpdo_build(n, 0, &f);
    (void)co_node_send(n, &f);
}

BENCH_MEASURED uint32_t bench_poll(co_node_t *n, uint32_t now);
BENCH_MEASURED uint32_t bench_poll(co_node_t *n, uint32_t now)
{
    return co_node_poll(n, now);
}

/* The operations, by number: BENCH_BARE picks one per Cortex-M0 image
 * (another family's products are not in that image). */
#define BENCH_SDO_EXPEDITED 1
#define BENCH_SDO_SEGMENT 2
#define BENCH_TPDO 3
#define BENCH_IDLE_POLL 4
#define BENCH_SYNC 5
#define BENCH_SAVE 6
#define BENCH_SAVE_JD 7
#ifdef BENCH_BARE
#define BENCH_HAS(op) (BENCH_BARE == (op))
#else
#define BENCH_HAS(op) 1
#endif

#if BENCH_HAS(BENCH_SDO_EXPEDITED)
static void op_sdo_expedited(long count)
{
    co_node_t *n = boot(&dst_x730_xy30); /* read 0x6010, as a master polls it */
    co_frame_t f = {.id = 0x67F, .dlc = 8, .data = {0x40, 0x10, 0x60, 0x00}};
    for (long i = 0; i < count; i++) {
        bench_receive(n, &f, 0);
    }
}
#endif

#if BENCH_HAS(BENCH_SDO_SEGMENT)
static void op_sdo_segment(long count)
{
    co_node_t *n = boot(&pf_iny360d); /* 0x1008: 19 characters, 3 segments */
    co_frame_t init = {.id = 0x601, .dlc = 8, .data = {0x40, 0x08, 0x10, 0x00}};
    for (long i = 0; i < count; i++) {
        co_node_receive(n, &init, 0);
        co_frame_t seg = {.id = 0x601, .dlc = 8, .data = {0x60}};
        bench_receive(n, &seg, 0); /* the first segment: 7 bytes */
        seg.data[0] = 0x70;
        co_node_receive(n, &seg, 0);
        seg.data[0] = 0x60;
        co_node_receive(n, &seg, 0);
    }
}
#endif

#if BENCH_HAS(BENCH_TPDO)
static void op_tpdo(long count)
{
    co_node_t *n = boot(&dst_x730_xy30); /* X and Y, 8 bytes */
    co_frame_t start = {.id = 0x000, .dlc = 2, .data = {0x01, 0x7F}};
    co_node_receive(n, &start, 0);
    for (long i = 0; i < count; i++) {
        bench_tpdo(n);
    }
}
#endif

#if BENCH_HAS(BENCH_IDLE_POLL)
static void op_idle_poll(long count)
{
    co_node_t *n = boot(&dst_x730_xy30); /* pre-operational, nothing due */
    for (long i = 0; i < count; i++) {
        (void)bench_poll(n, (uint32_t)i);
    }
}
#endif

#if BENCH_HAS(BENCH_SYNC)
static void op_sync(long count)
{
    co_node_t *n = boot(&jd2xxx); /* two TPDOs, both synchronous (type 1) */
    co_frame_t start = {.id = 0x000, .dlc = 2, .data = {0x01, 0x0A}};
    co_node_receive(n, &start, 0);
    co_frame_t sync = {.id = 0x080, .dlc = 0};
    for (long i = 0; i < count; i++) {
        bench_receive(n, &sync, 0);
    }
}
#endif

#if BENCH_HAS(BENCH_SAVE) || BENCH_HAS(BENCH_SAVE_JD)
/* 0x1010:1 "save", frame in to answer queued: the CPU's part of a save's
 * answer (the records built, CRCs, both slots read back), the flash's own
 * time left out (this port's EEPROM is RAM). Each save a changed value, so
 * each writes its record. */
static void saves(const product_t *p, long count)
{
    co_node_t *n = boot(p);
    uint16_t id = (uint16_t)(0x600u + n->node_id);
    co_frame_t hb = {.id = id, .dlc = 8, .data = {0x2B, 0x17, 0x10, 0x00}};
    co_frame_t save = {
        .id = id, .dlc = 8, .data = {0x23, 0x10, 0x10, 0x01, 0x73, 0x61, 0x76, 0x65}};
    for (long i = 0; i < count; i++) {
        hb.data[4] = (uint8_t)(100u + (unsigned)(i & 1)); /* the heartbeat 100 or 101 ms */
        co_node_receive(n, &hb, 0);
        bench_receive(n, &save, 0);
    }
}
#endif
#if BENCH_HAS(BENCH_SAVE)
static void op_save(long count)
{
    saves(&dst_x730_xy30, count); /* PARA, and the LSS set when changed (unchanged here) */
}
#endif
#if BENCH_HAS(BENCH_SAVE_JD)
static void op_save_jd(long count)
{
    saves(&jd2xxx, count); /* the largest stored set of the products */
}
#endif

/* What an operation must have sent last: a measured figure is only worth
 * something on the path it names, not on an abort or with nothing sent. */
enum bench_kind { BENCH_ANSWER, BENCH_PDO, BENCH_NOTHING };

typedef struct bench_op {
    const char *name;
    void (*run)(long count);
    enum bench_kind kind; /* SDO answer (no abort), a TPDO, or nothing due */
} bench_op_t;

/* Prints what op sent; 0 if it sent what it must, else 1. */
static int finish(const bench_op_t *op, long count)
{
    printf("%s x %ld: %lu frames sent, the last %03lX %02X\n", op->name, count, sent,
           (unsigned long)last.id, (unsigned)last.data[0]);
    bool ok = true;
    switch (op->kind) {
    case BENCH_ANSWER: /* an SDO server answer, not an abort (0x80) */
        ok = last.id >= 0x581u && last.id <= 0x5FFu && last.data[0] != 0x80u;
        break;
    case BENCH_PDO: /* TPDO1 to TPDO4 */
        ok = last.id >= 0x181u && last.id <= 0x4FFu;
        break;
    case BENCH_NOTHING:
        break;
    }
    if (!ok) {
        printf("bench: %s did not send what it measures\n", op->name);
    }
    return ok ? 0 : 1;
}

#ifdef BENCH_BARE
/* One operation, BENCH_N times (tests/bench/m0.cmake sets both). */
int main(void);
int main(void)
{
    static const bench_op_t op =
#if BENCH_HAS(BENCH_SDO_EXPEDITED)
        {"sdo-expedited", op_sdo_expedited, BENCH_ANSWER};
#elif BENCH_HAS(BENCH_SDO_SEGMENT)
        {"sdo-segment", op_sdo_segment, BENCH_ANSWER};
#elif BENCH_HAS(BENCH_TPDO)
        {"tpdo", op_tpdo, BENCH_PDO};
#elif BENCH_HAS(BENCH_IDLE_POLL)
        {"idle-poll", op_idle_poll, BENCH_NOTHING};
#elif BENCH_HAS(BENCH_SYNC)
        {"sync", op_sync, BENCH_PDO};
#elif BENCH_HAS(BENCH_SAVE)
        {"save", op_save, BENCH_ANSWER};
#elif BENCH_HAS(BENCH_SAVE_JD)
        {"save-jd", op_save_jd, BENCH_ANSWER};
#else
#error "BENCH_BARE: no such operation"
#endif
    op.run(BENCH_N);
    return finish(&op, BENCH_N);
}
#else
int main(int argc, char **argv)
{
    static const bench_op_t ops[] = {
        {"sdo-expedited", op_sdo_expedited, BENCH_ANSWER},
        {"sdo-segment", op_sdo_segment, BENCH_ANSWER},
        {"tpdo", op_tpdo, BENCH_PDO},
        {"idle-poll", op_idle_poll, BENCH_NOTHING},
        {"sync", op_sync, BENCH_PDO},
        {"save", op_save, BENCH_ANSWER},
        {"save-jd", op_save_jd, BENCH_ANSWER},
    };
    if (argc != 3) {
        fprintf(stderr,
                "usage: bench sdo-expedited|sdo-segment|tpdo|idle-poll|sync|save|save-jd N\n");
        return 2;
    }
    const char *op = argv[1];
    long count = strtol(argv[2], NULL, 10);
    for (size_t i = 0; i < sizeof(ops) / sizeof(ops[0]); i++) {
        if (strcmp(op, ops[i].name) == 0) {
            ops[i].run(count);
            return finish(&ops[i], count);
        }
    }
    fprintf(stderr, "bench: unknown operation %s\n", op);
    return 2;
}
#endif
