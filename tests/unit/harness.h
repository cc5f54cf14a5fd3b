/*
 * harness.h - unit-test harness: checks, a fake port and a virtual clock.
 *
 * The fake port records every frame the node sends and emulates an EEPROM
 * that can be told to lose power after a given number of written bytes.
 * Tests drive time explicitly (h_advance), so every timing is exact.
 */
#ifndef HARNESS_H
#define HARNESS_H

#include <stdio.h>
#include <string.h>

#include "co_node.h"
#include "product.h"
#include "product_registry.h"

#ifdef HARNESS_BARE
#include "bare_io.h" /* printf and friends over semihosting (tests/qemu) */
#endif

extern int h_failures;
extern int h_checks;

#define CHECK(cond)                                                                                \
    do {                                                                                           \
        h_checks++;                                                                                \
        if (!(cond)) {                                                                             \
            h_failures++;                                                                          \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);               \
        }                                                                                          \
    } while (0)

/* A check that fails where it is reached (a path that must not be taken), saying why. */
#define FAIL(why)                                                                                  \
    do {                                                                                           \
        h_checks++;                                                                                \
        h_failures++;                                                                              \
        fprintf(stderr, "%s:%d: FAIL: %s\n", __FILE__, __LINE__, why);                             \
    } while (0)

#define CHECK_EQ(a, b)                                                                             \
    do {                                                                                           \
        long long a_ = (long long)(a), b_ = (long long)(b);                                        \
        h_checks++;                                                                                \
        if (a_ != b_) {                                                                            \
            h_failures++;                                                                          \
            fprintf(stderr, "%s:%d: %s == %lld, expected %s == %lld\n", __FILE__, __LINE__, #a,    \
                    a_, #b, b_);                                                                   \
        }                                                                                          \
    } while (0)

/*
 * Runs one test function and reports it ("ok", "FAIL").
 * A build of one fixed node config (CO_FIXED_CFG with its table sizes, as
 * an MCU image: od/<family>/family.cmake) runs its family's tests: a test
 * that boots a product of another config ends at that boot (h_boot jumps
 * back into h_run) and is reported "n/a" with the product; what it checked
 * before counts. h_finish() fails a build where no test applied.
 */
#define RUN(fn) h_run(fn, #fn)
void h_run(void (*fn)(void), const char *name);

#ifdef CO_FIXED_CFG
/* Leave the running test: it booted product id of another config. */
void h_foreign_boot(const char *id) __attribute__((noreturn));
/* The running test booted a product of this build's config. */
void h_own_boot(void);
#endif

extern int h_tests;
extern int h_failed_tests;

/*
 * The stack's CO_CHECK (co_common.h) reports a broken contract through
 * co_assert_failed(): a failed check, unless the test announced it with
 * h_expect_assert(n) (then it counts down; h_asserts counts every report).
 */
void h_expect_assert(unsigned n);
extern unsigned h_asserts;

/* Prints "N passed, M failed" and returns the exit status. */
int h_finish(void);
/* Most sent frames ever left unread at once (printed by h_finish). */
extern unsigned h_tx_high_water;

/*
 * Sizes. The bare-metal build (tests/qemu, 16 KB of RAM) makes them small;
 * the host keeps room to spare. FAKE_TX_MAX frames are kept unread at most:
 * sending more without reading them fails the test loudly (an overrun is a
 * harness limit, never silently lost frames).
 */
#ifndef FAKE_TX_MAX
#define FAKE_TX_MAX 4096u
#endif
#ifndef FAKE_NVM_SIZE
#define FAKE_NVM_SIZE 2048u
#endif
/* Instance bytes of a device under test: the largest family's instance
 * (the union of every family's instance type, from their declarations). */
#define H_INST_MAX sizeof(product_any_t)

/* The fake program area (co_port.h, "Program download"): pages erased
 * (0xFF) before written; a write ANDs its bytes in, as flash programs
 * only 1 -> 0 bits, so a page written twice without an erase reads wrong. */
#ifndef FAKE_PROG_SIZE
#ifdef HARNESS_BARE
#define FAKE_PROG_SIZE 64u /* no bare test downloads a program (test_progdl is the host's) */
#else
#define FAKE_PROG_SIZE 4096u
#endif
#endif
#define FAKE_PROG_PAGE (FAKE_PROG_SIZE < 1024u ? FAKE_PROG_SIZE : 1024u)

typedef struct fake_prog {
    struct co_progdl *pd; /* co_port_progdl's answer: the test's state */
    uint8_t area[FAKE_PROG_SIZE];
    uint32_t board;     /* the board code co_port_prog_check accepts */
    const char *id;     /* the product ID it accepts */
    uint32_t limit;     /* image bytes the area takes (co_port_prog_check) */
    uint32_t accepted;  /* the length co_port_prog_check last accepted */
    uint32_t erased_to; /* pages 0 .. erased_to - 1 erased since the last clear */
    unsigned clears, erases, writes, reads, commits;
    bool fail_clear, fail_write, fail_read, fail_commit; /* that call fails */
    long cut_after;        /* image bytes that may still be written; -1: no power cut */
    long flip_at;          /* the area byte that programs with bit 0 wrong; -1: none */
    uint32_t committed_id; /* the last commit's program ID */
    unsigned starts, stops, handovers;
    unsigned start_ntx, stop_ntx, handover_ntx; /* frames sent when the last one was called */
} fake_prog_t;

typedef struct fake_port {
    co_frame_t tx[FAKE_TX_MAX]; /* ring of sent frames, index = count % FAKE_TX_MAX */
    unsigned ntx;               /* frames sent */
    unsigned rd;                /* frames consumed by h_next() */
    bool tx_full;               /* co_port_can_send() refuses */
    uint8_t nvm[FAKE_NVM_SIZE];
    long cut_after;       /* bytes that may still be written; -1 = no power cut */
    unsigned fail_writes; /* the next this many writes fail (nothing written), then they work */
    unsigned nvm_writes;
    bool nvm_read_fails;
    long reads_left;      /* NVM reads that still succeed; -1 = all (a read fault after that) */
    unsigned read_faults; /* reads refused because reads_left ran out */
    uint16_t kbps;        /* last co_port_can_bitrate() */
    unsigned bitrate_calls;
    unsigned prepares;      /* co_port_nvm_prepare() calls */
    uint32_t prepared_addr; /* the last one's address */
    uint32_t prepared_at;   /* the virtual time of the last one (h_dev_t.now) */
    const uint32_t *clock;  /* the device's virtual clock, for prepared_at */
    fake_prog_t prog;       /* program download's area and calls */
} fake_port_t;

void fake_port_init(fake_port_t *p);

/* A product under test: its memory, port, node and virtual clock. */
typedef struct h_dev {
    _Alignas(max_align_t) unsigned char mem[H_INST_MAX];
    const product_t *prod;
    fake_port_t port;
    co_node_t *node; /* node 0 (SDO helpers talk to it) */
    co_node_t *nodes[PRODUCT_MAX_NODES];
    unsigned nnodes;
    uint32_t now;                          /* virtual time, us */
    uint32_t next_sample;                  /* time of the next sensor sample */
    int32_t truth[PRODUCT_MAX_INPUTS];     /* true inputs, milli-units */
    uint32_t fault;                        /* bit i: the product's fault i */
    uint8_t factory_id[PRODUCT_MAX_NODES]; /* co_node_set_factory_id() at each boot; 0: none */
    uint32_t serial[PRODUCT_MAX_NODES];    /* co_node_set_serial() at each boot; 0: none */
    /* The config node 0 runs instead of its product's, set between create
     * and start at each boot (a board's derived config, as the Linux
     * program's program download); NULL: the product's. */
    const co_node_cfg_t *cfg;
} h_dev_t;

/* The product instance (aligned for any type: cast it to the family's type). */
static inline void *h_inst(h_dev_t *d)
{
    return d->mem;
}

/* Create (port and NVM fresh unless keep_nvm) and power on. */
void h_boot(h_dev_t *d, const product_t *p, bool keep_nvm);
/* h_boot with fresh NVM, each node i given factory node-ID ids[i] (0: none)
 * before its start, at this and every later power cycle. */
void h_boot_ids(h_dev_t *d, const product_t *p, const uint8_t ids[PRODUCT_MAX_NODES]);
/* Power cycle: keep the NVM, rebuild everything else. */
void h_power_cycle(h_dev_t *d);

/* Advance virtual time by us, sampling the sensor and polling as a board does. */
void h_advance(h_dev_t *d, uint32_t us);

/* Deliver a frame: data as hex bytes "2B 00 18 05 14 00 00 00". */
void h_rx(h_dev_t *d, uint16_t id, const char *hex);
void h_rx_frame(h_dev_t *d, const co_frame_t *f);

/* Next unread sent frame, or NULL. */
const co_frame_t *h_next(h_dev_t *d);
/* Drop every unread sent frame. */
void h_drain(h_dev_t *d);
/* Unread sent frames. */
unsigned h_pending(const h_dev_t *d);

/* Check the next sent frame against id and hex bytes (DLC = byte count). */
#define EXPECT(d, id, hex) h_expect((d), (id), (hex), __FILE__, __LINE__)
void h_expect(h_dev_t *d, uint16_t id, const char *hex, const char *file, int line);
/* Like EXPECT, skipping frames with other identifiers first. */
#define EXPECT_ID(d, id, hex) h_expect_id((d), (id), (hex), __FILE__, __LINE__)
void h_expect_id(h_dev_t *d, uint16_t id, const char *hex, const char *file, int line);
/* Check that nothing more was sent. */
#define EXPECT_NONE(d) h_expect_none((d), __FILE__, __LINE__)
void h_expect_none(h_dev_t *d, const char *file, int line);

/* SDO request to the node, expect this exact response. */
#define SDO(d, req, resp) h_sdo((d), (req), (resp), __FILE__, __LINE__)
void h_sdo(h_dev_t *d, const char *req, const char *resp, const char *file, int line);

/* Read a numeric object through SDO (expedited); -1 on abort. */
long long h_read(h_dev_t *d, uint16_t index, uint8_t sub);

/* Parse hex bytes; returns count. */
unsigned h_hex(const char *hex, uint8_t *out, unsigned cap);

#endif /* HARNESS_H */
