/*
 * test_board_common.c - what boards/common gives every MCU image besides
 * the flash EEPROM and the division helpers (their own tests): the four
 * memory functions of libc_min.c (renamed here, so that they run beside
 * the host's C library and are compared with it), and the bare-metal main
 * loop of mcu_main.c on a fake board with a virtual clock: start-up, bit
 * rate, a sample every 5 ms, received frames served, LEDs, sleeping no
 * longer than the next deadline, and the red LED when it cannot run.
 * Host only: under qemu the images use libc_min.c for real, and mcu_main.c
 * is the program itself.
 */
#include <setjmp.h>

#include "board.h"
#include "boot.h"
#include "co_filter.h"
#include "co_port.h"
#include "dst.h"
#include "harness.h"
#include "uid_serial.h"

/* ---- libc_min.c, renamed -------------------------------------------- */

#define memcpy lm_memcpy
#define memmove lm_memmove
#define memset lm_memset
#define memcmp lm_memcmp
#include "libc_min.c"
#undef memcpy
#undef memmove
#undef memset
#undef memcmp

static void test_libc_min(void)
{
    uint8_t a[32];
    uint8_t b[32];
    for (unsigned i = 0; i < sizeof(a); i++) {
        a[i] = (uint8_t)(i * 7u + 1u);
    }
    memset(b, 0xEE, sizeof(b));
    CHECK(lm_memcpy(b + 1, a, 10) == b + 1);
    CHECK(memcmp(b + 1, a, 10) == 0);
    CHECK_EQ(b[0], 0xEE);
    CHECK_EQ(b[11], 0xEE); /* not one byte more */
    CHECK(lm_memcpy(b, a, 0) == b);
    /* Overlapping moves, both directions, against the C library's. */
    uint8_t want[32];
    memcpy(want, a, sizeof(a));
    memmove(want + 3, want, 20);
    memcpy(b, a, sizeof(a));
    CHECK(lm_memmove(b + 3, b, 20) == b + 3);
    CHECK(memcmp(b, want, sizeof(b)) == 0);
    memcpy(want, a, sizeof(a));
    memmove(want, want + 5, 20);
    memcpy(b, a, sizeof(a));
    CHECK(lm_memmove(b, b + 5, 20) == b);
    CHECK(memcmp(b, want, sizeof(b)) == 0);
    /* memset takes an int and stores its low byte. */
    CHECK(lm_memset(b, 0x1AB, 5) == b);
    CHECK(b[0] == 0xAB && b[4] == 0xAB && b[5] == want[5]);
    /* memcmp: sign of the first difference, bytes as unsigned. */
    uint8_t x[3] = {1, 0x80, 3};
    uint8_t y[3] = {1, 0x7F, 3};
    CHECK(lm_memcmp(x, y, 3) > 0);
    CHECK(lm_memcmp(y, x, 3) < 0);
    CHECK_EQ(lm_memcmp(x, x, 3), 0);
    CHECK_EQ(lm_memcmp(x, y, 1), 0);
    CHECK_EQ(lm_memcmp(x, y, 0), 0);
    CHECK(lm_memcmp(y + 1, x + 1, 2) < 0); /* the first byte decides */
    CHECK(lm_memcmp(x + 1, y + 1, 2) > 0);
}

/* ---- mcu_main.c on a fake board ------------------------------------------- */

#define main mcu_main_any
#define BOARD_RX_FILTER /* as rv32-virt builds it: the receive lists to board_can_filter */
#define PRODUCT_SYM dst_x730_xy30
#define PRODUCT_HEADER "dst.h"
#define PRODUCT_INST_SIZE sizeof(dst_dev_t)
int main(void); /* mcu_main_any: declared, for -Wmissing-prototypes */
#include "mcu_main.c"
#undef main

/* Again as the image of a product with two nodes, the redundant GSH-A
 * (nodes 0x13 and 0x14); its statics renamed, so that both copies link. */
#undef PRODUCT_SYM
#undef PRODUCT_HEADER
#undef PRODUCT_INST_SIZE
#define main mcu_main_two
#define leds mcu_main_two_leds
#define rx_filter mcu_main_two_rx_filter
#define co_port_can_bitrate mcu_main_two_can_bitrate
#define PRODUCT_SYM gsh_a_redundant
#define PRODUCT_HEADER "gsh.h"
#define PRODUCT_INST_SIZE sizeof(gsh_dev_t)
int main(void); /* mcu_main_two: declared, for -Wmissing-prototypes */
bool co_port_can_bitrate(void *port, uint16_t kbps);
#include "mcu_main.c"
#undef main
#undef leds
#undef rx_filter
#undef co_port_can_bitrate

/* And as a JD2xxx's image (node 0x0A): its 2300h resets the node after
 * the confirmation, at the poll after the frame. */
#undef PRODUCT_SYM
#undef PRODUCT_HEADER
#undef PRODUCT_INST_SIZE
#define main mcu_main_jd
#define leds mcu_main_jd_leds
#define rx_filter mcu_main_jd_rx_filter
#define co_port_can_bitrate mcu_main_jd_can_bitrate
#define PRODUCT_SYM jd2xxx
#define PRODUCT_HEADER "jd.h"
#define PRODUCT_INST_SIZE sizeof(jd_dev_t)
int main(void); /* mcu_main_jd: declared, for -Wmissing-prototypes */
bool co_port_can_bitrate(void *port, uint16_t kbps);
#include "mcu_main.c"
#undef main
#undef leds
#undef rx_filter
#undef co_port_can_bitrate

/* Images built with a fixed node config (CO_FIXED_CFG): the DST X730 with
 * its own, which runs; the redundant GSH-A with channel 1's, whose second
 * node has channel 2's, which must not. */
#undef PRODUCT_SYM
#undef PRODUCT_HEADER
#undef PRODUCT_INST_SIZE
#define main mcu_main_paired
#define leds mcu_main_paired_leds
#define rx_filter mcu_main_paired_rx_filter
#define co_port_can_bitrate mcu_main_paired_can_bitrate
#define PRODUCT_SYM dst_x730_xy30
#define PRODUCT_HEADER "dst.h"
#define PRODUCT_INST_SIZE sizeof(dst_dev_t)
#define CO_FIXED_CFG dst_x730_cfg
int main(void); /* mcu_main_paired: declared, for -Wmissing-prototypes */
bool co_port_can_bitrate(void *port, uint16_t kbps);
#include "mcu_main.c"
#undef main
#undef leds
#undef rx_filter
#undef co_port_can_bitrate
#undef CO_FIXED_CFG
#undef PRODUCT_SYM
#undef PRODUCT_HEADER
#undef PRODUCT_INST_SIZE
#define main mcu_main_two_fixed
#define leds mcu_main_two_fixed_leds
#define rx_filter mcu_main_two_fixed_rx_filter
#define co_port_can_bitrate mcu_main_two_fixed_can_bitrate
#define PRODUCT_SYM gsh_a_redundant
#define PRODUCT_HEADER "gsh.h"
#define PRODUCT_INST_SIZE sizeof(gsh_dev_t)
#define CO_FIXED_CFG gsh_ch1_cfg
int main(void); /* mcu_main_two_fixed: declared, for -Wmissing-prototypes */
bool co_port_can_bitrate(void *port, uint16_t kbps);
#include "mcu_main.c"
#undef main
#undef leds
#undef rx_filter
#undef co_port_can_bitrate
#undef CO_FIXED_CFG

int mcu_main_fixed(void); /* mcu_main_fixed.c: the X730 with the X710's fixed config */

#define TX_MAX 1024u
#define RX_MAX 8u
#define TXQ_MAX 32u

static struct board {
    jmp_buf out; /* where the endless loop is left */
    bool init_ok;
    bool bitrate_ok;
    uint16_t kbps[4]; /* bit rates asked for */
    unsigned nkbps;
    uint32_t now;
    uint32_t end; /* leave the loop once the clock gets here */
    uint32_t max_sleep;
    unsigned sleeps;
    unsigned samples;
    uint32_t last_sample;
    uint32_t max_gap;       /* longest time between two samples */
    uint32_t min_gap;       /* shortest */
    uint32_t x_change_at;   /* x reads 20 deg from here on (relative to the start; 0: never) */
    co_frame_t rx[RX_MAX];  /* frames to receive, in order ... */
    uint32_t rx_at[RX_MAX]; /* ... each at its time */
    unsigned nrx;
    unsigned irx;           /* the next to receive */
    uint32_t passive_from;  /* board_can_state() reports error passive from ... */
    uint32_t passive_until; /* ... until here (relative to the start; equal: never) */
    uint32_t start;
    unsigned state_calls;        /* board_can_state() calls */
    unsigned unfiltered_bootups; /* boot-ups whose SDO request the filter stopped */
    co_frame_t txq[TXQ_MAX];     /* frames the node queued, not yet sent ... */
    unsigned ntxq;
    unsigned slept_queued; /* ... while the board went to sleep */
    co_frame_t tx[TX_MAX];
    uint32_t tx_at[TX_MAX];
    unsigned ntx;
    unsigned leds;         /* board_leds() calls */
    unsigned red_only;     /* of which (green off, red on) */
    bool green_seen[2];    /* green off / on seen */
    bool red_seen;         /* red on seen ... */
    uint32_t red_first;    /* ... first at this time */
    unsigned red_limit;    /* leave after this many red-only calls (0: never) */
    unsigned serial_calls; /* board_serial() calls */
    co_rx_id_t filter[2u * CO_NODE_RX_IDS_MAX]; /* the last board_can_filter() list */
    unsigned nfilter;
    unsigned filter_calls;
    unsigned sleeps_at_filter; /* board_sleep() calls before the last board_can_filter() */
} bd;

static void bd_reset(bool init_ok, bool bitrate_ok, uint32_t run_us)
{
    memset(&bd, 0, sizeof(bd));
    bd.init_ok = init_ok;
    bd.bitrate_ok = bitrate_ok;
    bd.now = 0xFFF00000u; /* 1 s before the 32-bit clock wraps */
    bd.end = bd.now + run_us;
    bd.start = bd.now;
    bd.min_gap = UINT32_MAX;
}

/* A frame from the bus at time at (frames are queued in time order). */
static void deliver(co_frame_t f, uint32_t at)
{
    if (bd.nrx < RX_MAX) {
        bd.rx[bd.nrx] = f;
        bd.rx_at[bd.nrx++] = at;
    }
}

static bool rx_pending(void)
{
    return bd.irx < bd.nrx;
}

/* The hand-over to the bootloader (boot.h): the block it writes, and the
 * reset that follows, which leaves the loop. */
boot_handover_t boot_handover_block;
static unsigned resets;         /* board_reset() calls */
static unsigned tx_at_reset;    /* frames sent when it came */
static bool handover_on_answer; /* the next SDO answer asks for the hand-over */

void board_reset(void)
{
    resets++;
    tx_at_reset = bd.ntx;
    longjmp(bd.out, 1);
}

bool board_init(void)
{
    return bd.init_ok;
}

bool board_can_bitrate(uint16_t kbps)
{
    if (bd.nkbps < 4u) {
        bd.kbps[bd.nkbps++] = kbps;
    }
    return bd.bitrate_ok;
}

uint32_t board_now_us(void)
{
    return bd.now;
}

bool board_can_receive(co_frame_t *f)
{
    if (!rx_pending() || co_time_before(bd.now, bd.rx_at[bd.irx])) {
        return false;
    }
    *f = bd.rx[bd.irx++];
    return true;
}

static bool in_filter(uint16_t id, bool rtr);

/* The fake board is one with a transmit queue, as rv32-virt's SJA1000:
 * co_port_can_send() only queues, the frames leave when the board is
 * asked for its state or given a receive list (its driver's service and
 * filter calls start the transmitter). A boot-up leaving must find its
 * node's SDO request in the receive filter already. */
static void flush(void)
{
    for (unsigned k = 0; k < bd.ntxq && bd.ntx < TX_MAX; k++) {
        const co_frame_t *t = &bd.txq[k];
        if (t->id > 0x700u && t->id <= 0x77Fu && t->dlc == 1u && t->data[0] == 0x00u &&
            !in_filter((uint16_t)(t->id - 0x100u), false)) {
            bd.unfiltered_bootups++;
        }
        bd.tx_at[bd.ntx] = bd.now;
        bd.tx[bd.ntx++] = *t;
    }
    bd.ntxq = 0;
}

uint8_t board_can_state(void)
{
    bd.state_calls++;
    flush();
    uint32_t t = bd.now - bd.start;
    return t >= bd.passive_from && t < bd.passive_until ? CO_CAN_PASSIVE : CO_CAN_ACTIVE;
}

void board_leds(bool green, bool red)
{
    bd.leds++;
    bd.green_seen[green ? 1 : 0] = true;
    if (red && !bd.red_seen) {
        bd.red_seen = true;
        bd.red_first = bd.now;
    }
    if (!green && red) {
        bd.red_only++;
        if (bd.red_limit != 0u && bd.red_only >= bd.red_limit) {
            longjmp(bd.out, 1);
        }
    }
}

void board_sensor(const product_t *p, int32_t values[], uint32_t *faults)
{
    (void)p;
    if (bd.samples > 0u && bd.now - bd.last_sample > bd.max_gap) {
        bd.max_gap = bd.now - bd.last_sample;
    }
    if (bd.samples > 0u && bd.now - bd.last_sample < bd.min_gap) {
        bd.min_gap = bd.now - bd.last_sample;
    }
    bd.last_sample = bd.now;
    bd.samples++;
    bool changed = bd.x_change_at != 0u && bd.now - bd.start >= bd.x_change_at;
    values[0] = changed ? 20000 : 12500; /* x = 12.5 deg, later 20 deg */
    values[1] = -3000;
    *faults = 0;
}

/* A chip ID of the fake board's, folded as the real boards do. */
uint32_t board_serial(unsigned node)
{
    bd.serial_calls++;
    return board_uid_serial(0x00470021u ^ 0x31385107u ^ 0x20363650u, node);
}

void board_sleep(uint32_t us)
{
    bd.sleeps++;
    bd.slept_queued += bd.ntxq != 0u ? 1u : 0u;
    bd.max_sleep = us > bd.max_sleep ? us : bd.max_sleep;
    uint32_t wake = bd.now + us;
    if (rx_pending() && co_time_before(bd.rx_at[bd.irx], wake)) {
        /* the receive interrupt */
        wake = co_time_before(bd.now, bd.rx_at[bd.irx]) ? bd.rx_at[bd.irx] : bd.now;
    }
    bd.now = wake;
    if (!co_time_before(bd.now, bd.end) || bd.sleeps > 100000u) {
        longjmp(bd.out, 1);
    }
}

void board_can_filter(const co_rx_id_t *ids, unsigned n)
{
    bd.filter_calls++;
    bd.sleeps_at_filter = bd.sleeps;
    bd.nfilter = n <= 2u * CO_NODE_RX_IDS_MAX ? n : 0u;
    memcpy(bd.filter, ids, bd.nfilter * sizeof ids[0]);
    flush();
}

static bool in_filter(uint16_t id, bool rtr)
{
    for (unsigned k = 0; k < bd.nfilter; k++) {
        if (bd.filter[k].id == id && bd.filter[k].rtr == rtr) {
            return true;
        }
    }
    return false;
}

bool co_port_can_send(void *port, const co_frame_t *frame)
{
    (void)port;
    if (bd.ntxq >= TXQ_MAX) {
        return false;
    }
    if (handover_on_answer && frame->id == 0x5FFu) {
        co_port_prog_handover(NULL); /* as 1F51h:1's write hook does while it answers */
    }
    bd.txq[bd.ntxq++] = *frame;
    return true;
}

static uint8_t nvm[CO_STORE_NVM_SIZE];

bool co_port_nvm_read(void *port, uint32_t addr, void *buf, uint32_t len)
{
    (void)port;
    if (addr + len > sizeof(nvm)) {
        return false;
    }
    memcpy(buf, &nvm[addr], len);
    return true;
}

bool co_port_nvm_write(void *port, uint32_t addr, const void *buf, uint32_t len)
{
    (void)port;
    if (addr + len > sizeof(nvm)) {
        return false;
    }
    memcpy(&nvm[addr], buf, len);
    return true;
}

/* Erasing ahead, as flash does: the bytes read as erased. */
void co_port_nvm_prepare(void *port, uint32_t addr, uint32_t len)
{
    (void)port;
    if (addr <= sizeof(nvm) && len <= sizeof(nvm) - addr) {
        memset(&nvm[addr], 0xFF, len);
    }
}

/* Frames sent on id at or after time t (relative to the start). */
static unsigned sent_on(uint16_t id, uint32_t t, uint32_t start)
{
    unsigned n = 0;
    for (unsigned i = 0; i < bd.ntx; i++) {
        n += bd.tx[i].id == id && bd.tx_at[i] - start >= t;
    }
    return n;
}

/* One second of a DST X730 (node 0x7F, 250 kbit/s) across the clock's wrap. */
static void test_main_loop_runs_the_product(void)
{
    bd_reset(true, true, 1000000u);
    memset(nvm, 0xFF, sizeof(nvm));
    uint32_t start = bd.now;
    deliver((co_frame_t){.id = 0x67F, .dlc = 8, .data = {0x40, 0x00, 0x10, 0x00}}, start + 500000u);
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_any();
    }
    CHECK_EQ(bd.nkbps, 1);
    CHECK_EQ(bd.kbps[0], 250);
    CHECK(bd.ntx >= 2u);
    CHECK(bd.tx[0].id == 0x77F && bd.tx[0].dlc == 1 && bd.tx[0].data[0] == 0x00); /* boot-up */
    CHECK_EQ(bd.tx_at[0], start);
    /* The SDO request of t = 0.5 s answered at once, with 0x1000. */
    unsigned i = 1;
    while (i < bd.ntx && bd.tx[i].id != 0x5FF) {
        i++;
    }
    CHECK(i < bd.ntx);
    if (i < bd.ntx) {
        CHECK_EQ(bd.tx_at[i] - start, 500000);
        CHECK(bd.tx[i].data[0] == 0x43 && bd.tx[i].data[1] == 0x00 && bd.tx[i].data[2] == 0x10);
    }
    /* A sample every 5 ms, on time, across the wrap of the clock. */
    CHECK(bd.samples >= 200u && bd.samples <= 202u);
    CHECK_EQ(bd.max_gap, CO_FILTER_PERIOD_US);
    CHECK_EQ(bd.min_gap, CO_FILTER_PERIOD_US);
    CHECK(bd.max_sleep <= CO_FILTER_PERIOD_US);
    /* Pre-operational: the green LED blinks, red stays off. */
    CHECK(bd.green_seen[0] && bd.green_seen[1]);
    CHECK_EQ(bd.red_only, 0);
    CHECK_EQ(sent_on(0x1FF, 0, start), 0); /* no PDO before NMT start */
    CHECK_EQ(bd.slept_queued, 0);          /* what a pass queued left before the core slept */
}

/* A board that filters (BOARD_RX_FILTER) gets the node's receive list after
 * every pass of the loop, before it sleeps: the DST X730 at node 0x7F
 * consumes NMT, SYNC and its SDO request, nothing else. */
static void test_main_loop_receive_list(void)
{
    bd_reset(true, true, 100000u);
    memset(nvm, 0xFF, sizeof(nvm));
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_any();
    }
    CHECK(bd.filter_calls >= bd.sleeps && bd.filter_calls > 0u);
    CHECK_EQ(bd.sleeps_at_filter + 1u, bd.sleeps); /* the last pass's list came before its sleep */
    CHECK_EQ(bd.nfilter, 3);
    CHECK(in_filter(0x000, false) && in_filter(0x080, false) && in_filter(0x67F, false));
}

/* The node answers 1018h:04 with the board's serial number (the LSS
 * address's last part, CiA 305): the main loop asks the board once per
 * node before the start. */
static void test_main_loop_serial_from_board(void)
{
    bd_reset(true, true, 200000u);
    memset(nvm, 0xFF, sizeof(nvm));
    uint32_t start = bd.now;
    deliver((co_frame_t){.id = 0x67F, .dlc = 8, .data = {0x40, 0x18, 0x10, 0x04}}, start + 100000u);
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_any();
    }
    CHECK_EQ(bd.serial_calls, 1);
    unsigned i = 0;
    while (i < bd.ntx && bd.tx[i].id != 0x5FF) {
        i++;
    }
    CHECK(i < bd.ntx);
    if (i < bd.ntx) {
        CHECK(bd.tx[i].data[0] == 0x43 && bd.tx[i].data[1] == 0x18 && bd.tx[i].data[3] == 0x04);
        CHECK_EQ(co_get_u32(&bd.tx[i].data[4]), board_serial(0));
        CHECK(co_get_u32(&bd.tx[i].data[4]) != 0u);
    }
}

/* The serial number from a chip's folded ID: never 0, the node in bit 1
 * (the two nodes of a device differ), bit 0 set, the ID's low 30 bits in
 * bits 31..2 (IDs that differ there differ). */
static void test_uid_serial(void)
{
    CHECK_EQ(board_uid_serial(0, 0), 1);
    CHECK_EQ(board_uid_serial(0, 1), 3);
    CHECK_EQ(board_uid_serial(0xC0000000u, 0), 1); /* bits 31, 30 dropped: still not 0 */
    CHECK_EQ(board_uid_serial(0x12345678u, 0), 0x48D159E1u);
    CHECK_EQ(board_uid_serial(0x12345678u, 1), 0x48D159E3u);
    for (unsigned bit = 0; bit < 30u; bit++) {
        if (board_uid_serial(1u << bit, 0) == board_uid_serial(0, 0)) {
            FAIL("one bit of the ID changed, the serial number did not");
        }
    }
}

/* NMT start through the loop: TPDO1 follows (X730 default event timer). */
static void test_main_loop_nmt_start(void)
{
    bd_reset(true, true, 1000000u);
    memset(nvm, 0xFF, sizeof(nvm));
    uint32_t start = bd.now;
    deliver((co_frame_t){.id = 0x000, .dlc = 2, .data = {0x01, 0x7F}}, start + 100000u);
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_any();
    }
    CHECK(sent_on(0x1FF, 100000u, start) >= 5u);
    CHECK_EQ(bd.slept_queued, 0); /* each TPDO left in the pass that made it */
    CHECK_EQ(sent_on(0x1FF, 0, start), sent_on(0x1FF, 100000u, start));
}

/* The node brings the controller to the product's bit rate at start (the
 * DST's default code 3: 250 kbit/s), once. A controller that refuses it
 * stays where it was; the node runs all the same. */
static void test_main_loop_bitrate_refused(void)
{
    bd_reset(true, true, 100000u);
    memset(nvm, 0xFF, sizeof(nvm));
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_any();
    }
    CHECK_EQ(bd.nkbps, 1);
    CHECK_EQ(bd.kbps[0], 250);
    bd_reset(true, false, 100000u);
    memset(nvm, 0xFF, sizeof(nvm));
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_any();
    }
    CHECK_EQ(bd.nkbps, 1);
    CHECK(bd.ntx >= 1u && bd.tx[0].id == 0x77F);
}

/* The port function: an unusable code (0 kbit/s) gets the common default. */
static void test_port_bitrate_default(void)
{
    bd_reset(true, true, 0);
    CHECK(co_port_can_bitrate(NULL, 500));
    CHECK(co_port_can_bitrate(NULL, 0));
    CHECK_EQ(bd.nkbps, 2);
    CHECK_EQ(bd.kbps[0], 500);
    CHECK_EQ(bd.kbps[1], 250);
}

/* A board that fails to start, or an image built with another product's
 * fixed config: red LED for ever, nothing sent, the sensor never read. */
static void test_main_loop_refuses_to_run(void)
{
    bd_reset(false, true, 1000000u);
    bd.red_limit = 3;
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_any();
    }
    CHECK_EQ(bd.red_only, 3);
    CHECK_EQ(bd.leds, 3);
    CHECK_EQ(bd.ntx, 0);
    CHECK_EQ(bd.samples, 0);
    bd_reset(true, true, 1000000u);
    bd.red_limit = 3;
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_fixed();
    }
    CHECK_EQ(bd.red_only, 3);
    CHECK_EQ(bd.leds, 3);
    CHECK_EQ(bd.ntx, 0);
    CHECK_EQ(bd.samples, 0);
    CHECK_EQ(bd.nkbps, 0);
    bd_reset(true, true, 1000000u);
    bd.red_limit = 3;
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_two_fixed();
    }
    CHECK_EQ(bd.red_only, 3);
    CHECK_EQ(bd.ntx, 0);
    CHECK_EQ(bd.samples, 0);
    CHECK_EQ(bd.nkbps, 0);
    /* Built with its own config, the image runs. */
    bd_reset(true, true, 100000u);
    memset(nvm, 0xFF, sizeof(nvm));
    bd.red_limit = 1;
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_paired();
    }
    CHECK(bd.ntx >= 1u && bd.tx[0].id == 0x77F);
    CHECK_EQ(bd.red_only, 0);
    CHECK(bd.samples >= 20u);
}

/* The first frame on id sent at or after time t (relative to the start),
 * its index in bd.tx; bd.ntx when there is none. */
static unsigned first_on(uint16_t id, uint32_t t, uint32_t start)
{
    unsigned i = 0;
    while (i < bd.ntx && (bd.tx[i].id != id || bd.tx_at[i] - start < t)) {
        i++;
    }
    return i;
}

/* Frames received together are served one by one, each to its end: a
 * reset node (NMT) is done before the next frame is served, so that an SDO
 * request to the new node-ID right behind it is answered (DST manual: the
 * node-ID setting is active after the next reset). The boot-up under the
 * new node-ID leaves with the filter passing its SDO requests (boards
 * whose controller sends from board_can_state, as rv32-virt's SJA1000). */
static void test_main_loop_frames_of_one_pass(void)
{
    bd_reset(true, true, 400000u);
    memset(nvm, 0xFF, sizeof(nvm));
    uint32_t start = bd.now;
    deliver((co_frame_t){.id = 0x67F, .dlc = 8, .data = {0x2F, 0xF0, 0x20, 0x00, 0x06}},
            start + 100000u);
    deliver((co_frame_t){.id = 0x67F, .dlc = 8, .data = {0x2F, 0xF1, 0x20, 0x00, 0x06}},
            start + 100000u);
    deliver((co_frame_t){.id = 0x000, .dlc = 2, .data = {0x81, 0x7F}}, start + 200000u);
    deliver((co_frame_t){.id = 0x606, .dlc = 8, .data = {0x40, 0x00, 0x10, 0x00}}, start + 200000u);
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_any();
    }
    unsigned boot = first_on(0x706, 0, start);
    unsigned answer = first_on(0x586, 0, start);
    CHECK(boot < answer && answer < bd.ntx);
    if (boot < answer && answer < bd.ntx) {
        CHECK_EQ(bd.tx_at[boot] - start, 200000);
        CHECK_EQ(bd.tx_at[answer] - start, 200000);
        CHECK(bd.tx[answer].data[0] == 0x43 && bd.tx[answer].data[1] == 0x00 &&
              bd.tx[answer].data[2] == 0x10);
    }
    CHECK(bd.state_calls > 0u);
    CHECK_EQ(bd.unfiltered_bootups, 0);
    CHECK(in_filter(0x606, false) && !in_filter(0x67F, false));
}

/* The controller's error state reaches the node in the loop: from 0.1 s
 * on error passive, and the red LED shows it (CiA 303-3: off while the
 * controller is error active). */
static void test_main_loop_can_state(void)
{
    bd_reset(true, true, 300000u);
    memset(nvm, 0xFF, sizeof(nvm));
    bd.passive_from = 100000u;
    bd.passive_until = 300000u;
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_any();
    }
    CHECK(bd.red_seen);
    CHECK(bd.red_first - bd.start >= 100000u && bd.red_first - bd.start < 110000u);
}

/* A product with two nodes (the redundant GSH-A, nodes 0x13 and 0x14):
 * each boots, has its own serial number from the board (node 0 and 1),
 * gets the frames, is polled (TPDOs after NMT start) and is in the
 * receive list; the sleep waits for the earlier of their deadlines. */
static void test_main_loop_two_nodes(void)
{
    bd_reset(true, true, 1000000u);
    memset(nvm, 0xFF, sizeof(nvm));
    uint32_t start = bd.now;
    deliver((co_frame_t){.id = 0x613, .dlc = 8, .data = {0x40, 0x18, 0x10, 0x04}}, start + 100000u);
    deliver((co_frame_t){.id = 0x614, .dlc = 8, .data = {0x40, 0x18, 0x10, 0x04}}, start + 100000u);
    deliver((co_frame_t){.id = 0x000, .dlc = 2, .data = {0x01, 0x00}}, start + 200000u);
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_two();
    }
    CHECK_EQ(bd.serial_calls, 2);
    CHECK(bd.ntx >= 2u && bd.tx[0].id == 0x713 && bd.tx[1].id == 0x714);
    CHECK(bd.tx_at[0] == start && bd.tx_at[1] == start);
    for (unsigned k = 0; k < 2u; k++) {
        unsigned i = first_on((uint16_t)(0x593u + k), 0, start);
        CHECK(i < bd.ntx);
        if (i < bd.ntx) {
            CHECK_EQ(bd.tx_at[i] - start, 100000);
            CHECK_EQ(co_get_u32(&bd.tx[i].data[4]), board_serial(k));
        }
        CHECK(in_filter((uint16_t)(0x613u + k), false));
        CHECK(sent_on((uint16_t)(0x193u + k), 200000u, start) >= 5u);
    }
    CHECK(bd.max_sleep <= CO_FILTER_PERIOD_US);
    CHECK_EQ(bd.slept_queued, 0);
}

/* Each frame is served to its end before the next: the JD2xxx's "save
 * with reset" (2300h) confirms, then resets the node (JD manual, 9.17), and
 * an SDO request right behind it in the same pass is answered by the
 * node after its reset, behind the boot-up. */
static void test_main_loop_reset_between_frames(void)
{
    bd_reset(true, true, 300000u);
    memset(nvm, 0xFF, sizeof(nvm));
    uint32_t start = bd.now;
    deliver((co_frame_t){.id = 0x60A,
                         .dlc = 8,
                         .data = {0x23, 0x00, 0x23, 0x00, 0x55, 0xAA, 0xAA, 0x55}},
            start + 100000u);
    deliver((co_frame_t){.id = 0x60A, .dlc = 8, .data = {0x40, 0x00, 0x10, 0x00}}, start + 100000u);
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_jd();
    }
    unsigned confirm = first_on(0x58A, 100000u, start);
    unsigned boot = first_on(0x70A, 100000u, start);
    CHECK(confirm < boot && boot < bd.ntx);
    if (confirm < boot && boot < bd.ntx) {
        CHECK(bd.tx[confirm].data[0] == 0x60 && bd.tx[confirm].data[1] == 0x00 &&
              bd.tx[confirm].data[2] == 0x23);
        CHECK_EQ(bd.tx_at[boot] - start, 100000);
        unsigned answer = boot + 1u;
        while (answer < bd.ntx && bd.tx[answer].id != 0x58A) {
            answer++;
        }
        CHECK(answer < bd.ntx && bd.tx[answer].data[0] == 0x43 &&
              bd.tx_at[answer] == bd.tx_at[boot]);
    }
}

/* The node's inclination follows the sensor: sampled once before the
 * start (0x6010 answers 12.5 deg, in 0.05 deg, before the first period
 * ends), then every period (the sensor at 20 deg from 0.1 s on: at 0.3 s
 * the filtered output is on its way there). */
static void test_main_loop_feeds_samples(void)
{
    bd_reset(true, true, 400000u);
    memset(nvm, 0xFF, sizeof(nvm));
    uint32_t start = bd.now;
    bd.x_change_at = 100000u;
    deliver((co_frame_t){.id = 0x67F, .dlc = 8, .data = {0x40, 0x10, 0x60, 0x00}}, start + 1000u);
    deliver((co_frame_t){.id = 0x67F, .dlc = 8, .data = {0x40, 0x10, 0x60, 0x00}}, start + 300000u);
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_any();
    }
    unsigned first = first_on(0x5FF, 0, start);
    unsigned later = first_on(0x5FF, 300000u, start);
    CHECK(first < later && later < bd.ntx);
    if (first < later && later < bd.ntx) {
        CHECK_EQ(bd.tx_at[first] - start, 1000);
        CHECK_EQ(co_get_u16(&bd.tx[first].data[4]), 250);
        uint16_t x = co_get_u16(&bd.tx[later].data[4]); /* on its way, through the filter */
        CHECK(x > 250u && x <= 400u);
    }
}

/* A stop (1F51h:1 = 0, the application side of program download) asks
 * for the hand-over (co_port_prog_handover): the loop makes it after the
 * answer of that frame went out, with the node's node-ID and bit rate in a
 * block the bootloader takes (boot_handover_valid), then resets. */
static void test_main_loop_hands_over(void)
{
    bd_reset(true, true, 1000000u);
    memset(nvm, 0xFF, sizeof(nvm));
    memset(&boot_handover_block, 0, sizeof boot_handover_block);
    resets = 0;
    uint32_t start = bd.now;
    deliver((co_frame_t){.id = 0x67F, .dlc = 8, .data = {0x40, 0x00, 0x10, 0x00}}, start + 300000u);
    handover_on_answer = true;
    if (setjmp(bd.out) == 0) {
        (void)mcu_main_any();
    }
    handover_on_answer = false;
    CHECK_EQ(resets, 1);
    CHECK(tx_at_reset >= 2u);
    if (tx_at_reset >= 2u) { /* the answer first, at once */
        CHECK_EQ(bd.tx[tx_at_reset - 1u].id, 0x5FF);
        CHECK_EQ(bd.tx_at[tx_at_reset - 1u] - start, 300000);
    }
    CHECK(boot_handover_valid(&boot_handover_block));
    CHECK_EQ(boot_handover_block.node_id, 0x7F);
    CHECK_EQ(boot_handover_block.kbps, 250);
    /* Another magic, no node-ID, no bit rate: the bootloader takes no block. */
    boot_handover_block.magic ^= 1u;
    CHECK(!boot_handover_valid(&boot_handover_block));
    boot_handover_block.magic ^= 1u;
    boot_handover_block.node_id = 0;
    CHECK(!boot_handover_valid(&boot_handover_block));
    boot_handover_block.node_id = 0x7F;
    boot_handover_block.kbps = 0;
    CHECK(!boot_handover_valid(&boot_handover_block));
}

int main(void)
{
    RUN(test_libc_min);
    RUN(test_main_loop_runs_the_product);
    RUN(test_main_loop_nmt_start);
    RUN(test_main_loop_serial_from_board);
    RUN(test_main_loop_receive_list);
    RUN(test_uid_serial);
    RUN(test_main_loop_bitrate_refused);
    RUN(test_port_bitrate_default);
    RUN(test_main_loop_refuses_to_run);
    RUN(test_main_loop_frames_of_one_pass);
    RUN(test_main_loop_can_state);
    RUN(test_main_loop_two_nodes);
    RUN(test_main_loop_reset_between_frames);
    RUN(test_main_loop_feeds_samples);
    RUN(test_main_loop_hands_over);
    return h_finish();
}
