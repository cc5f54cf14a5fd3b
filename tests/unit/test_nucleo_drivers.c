/*
 * test_nucleo_drivers.c - the Nucleo-F042K6 board's drivers
 * (boards/nucleo-f042k6/board.c: clock, bxCAN, flash, SysTick, LEDs) on
 * the host, against the register-level models of tests/models written
 * from the STM32F0 reference manual RM0091. board.c is built with
 * STM32F042_MODEL: its every register access is a call into the models,
 * which answer as the chip does and record a violation whenever the
 * driver does what the manual forbids in that state. The test plays the
 * CAN bus (frames in, frames taken, errors, idle time) and the interrupt
 * controller (it calls can_irq_handler() while the model requests it).
 *
 * First the models themselves: each forbidden action, done on purpose,
 * is recorded (so that "no violation" below means something). Then the
 * drivers: start-up, bit timing for every rate the products use against
 * the manual's formula, a second bit-rate change on the bus, the transmit
 * mailboxes, the receive FIFO and queue, error states and bus-off
 * recovery, the flash driver and the EEPROM emulation, a parameter save
 * and restore of a DST X730 through the board's port, time and LEDs.
 */
#include "board.h"
#include "co_port.h"
#include "dst.h"
#include "flash_ee.h"
#include "harness.h"
#include "stm32f042.h"
#include "uid_serial.h"

/* The board's interrupt handlers (vectors of startup.c). */
void can_irq_handler(void);
void systick_handler(void);

/* Every rate of the products' bit-rate tables (od/bitrates.c) and CiA 301's 10 kbit/s. */
static const uint16_t product_rates[] = {10, 20, 50, 100, 125, 250, 500, 800, 1000};

#define EE_BASE 0x08006000u

/* ---- helpers ------------------------------------------------------------ */

/* No violation of the manual since the last one (the model prints any). */
#define CLEAN() CHECK_EQ(stm_violations_report(), 0)

/* The CAN interrupt, as the NVIC delivers it: the handler runs while the
 * controller requests; after it returns the request must be gone (an
 * interrupt that stays pending would lock the core in its handler). */
static unsigned irq(void)
{
    unsigned runs = 0;
    while (stm_can_irq() && runs < 4u) {
        can_irq_handler();
        runs++;
    }
    CHECK(!stm_can_irq());
    return runs;
}

static void drain_queue(void)
{
    co_frame_t f;
    while (board_can_receive(&f)) {
    }
}

/* A new chip, board_init(), and (kbps != 0) the controller on the bus. */
static void boot(uint16_t kbps)
{
    stm_chip_new();
    drain_queue();
    CHECK(board_init());
    if (kbps != 0u) {
        CHECK(board_can_bitrate(kbps));
        stm_can_bus_idle(1); /* 11 recessive bits: the controller joins */
        CHECK_EQ(stm_can_mode(), STM_CAN_NORMAL);
    }
}

static stm_can_frame_t frame(uint32_t id, uint8_t dlc, uint8_t seed)
{
    stm_can_frame_t f = {.id = id, .dlc = dlc};
    for (unsigned i = 0; i < 8u; i++) {
        f.data[i] = (uint8_t)(seed + 17u * i);
    }
    return f;
}

/* One frame from the bus through the FIFO, the interrupt and the queue. */
static bool receive_one(const stm_can_frame_t *in, co_frame_t *out)
{
    if (stm_can_bus_send(in) != STM_CAN_FIFO0) {
        return false;
    }
    CHECK_EQ(irq(), 1);
    return board_can_receive(out);
}

static bool same_frame(const co_frame_t *a, const stm_can_frame_t *b)
{
    unsigned n = b->dlc > 8u ? 8u : b->dlc;
    return a->id == b->id && a->rtr == b->rtr && a->dlc == n &&
           (b->rtr || memcmp(a->data, b->data, n) == 0);
}

static co_frame_t co_frame(uint16_t id, uint8_t dlc, uint8_t seed)
{
    co_frame_t f = {.id = id, .dlc = dlc};
    for (unsigned i = 0; i < 8u; i++) {
        f.data[i] = (uint8_t)(seed * 3u + i);
    }
    return f;
}

/* Bit rate of the bit timing in CAN_BTR at the APB clock (RM0091: bit time
 * = tq x (1 + TS1 + TS2), tq = (BRP + 1) / f_APB); 0 when not exact. */
static uint32_t btr_rate(uint32_t btr, uint32_t *sample_permille)
{
    uint32_t brp = (btr & 0x3FFu) + 1u;
    uint32_t ts1 = ((btr >> 16) & 0xFu) + 1u;
    uint32_t ts2 = ((btr >> 20) & 7u) + 1u;
    uint32_t quanta = 1u + ts1 + ts2;
    *sample_permille = 1000u * (1u + ts1) / quanta;
    uint32_t apb = stm_apb_hz();
    return apb % (brp * quanta) == 0u ? apb / (brp * quanta) : 0u;
}

/* The bxCAN registers a bit-rate change may touch, as a debugger sees them. */
static void can_snapshot(uint32_t regs[12])
{
    const uint32_t addr[12] = {CAN_MCR,  CAN_IER,  CAN_FMR,  CAN_FM1R, CAN_FS1R, CAN_FFA1R,
                               CAN_FA1R, CAN_F0R1, CAN_F0R2, CAN_BTR,  CAN_TSR,  CAN_RF0R};
    for (unsigned i = 0; i < 12u; i++) {
        regs[i] = stm_peek32(addr[i]);
    }
}

/* ---- the models catch what the manual forbids ---------------------------- */

static void spin_on_inak(void *arg)
{
    (void)arg;
    while ((stm_rd32(CAN_MSR) & CAN_MSR_INAK) == 0u) {
    }
}

static void test_models_catch_violations(void)
{
    /* A peripheral whose clock is off. */
    stm_chip_new();
    stm_wr32(CAN_MCR, CAN_MCR_INRQ);
    CHECK_EQ(stm_take_violations("clock off"), 1);
    /* The flash needs a wait state before the clock goes to 48 MHz. */
    stm_wr32(RCC_CR2, RCC_CR2_HSI48ON);
    while ((stm_rd32(RCC_CR2) & RCC_CR2_HSI48RDY) == 0u) {
    }
    stm_wr32(RCC_CFGR, RCC_CFGR_SW_HSI48);
    while (((stm_rd32(RCC_CFGR) >> 2) & 3u) != RCC_CFGR_SW_HSI48) {
    }
    CHECK_EQ(stm_take_violations("zero wait states"), 1);
    CHECK_EQ(stm_apb_hz(), 48000000u);

    /* bxCAN: the INAK handshake takes time: BTR written at once is too early. */
    boot(0);
    stm_wr32(CAN_MCR, CAN_MCR_INRQ);
    stm_wr32(CAN_BTR, 0x001C0005u);
    CHECK_EQ(stm_take_violations("CAN_BTR written outside initialization mode"), 1);
    CHECK_EQ(stm_peek32(CAN_BTR), 0x01230000u); /* the reset value stayed */
    /* INRQ and SLEEP together: no transition, a poll for INAK hangs. */
    stm_wr32(CAN_MCR, CAN_MCR_INRQ | CAN_MCR_SLEEP);
    CHECK(!stm_run(spin_on_inak, NULL));
    CHECK_EQ(stm_take_violations("hang"), 1);

    /* On the bus: BTR, filter configuration and active banks are locked. */
    boot(250);
    uint32_t btr = stm_peek32(CAN_BTR);
    stm_wr32(CAN_BTR, 0x001C0005u);
    CHECK_EQ(stm_take_violations("CAN_BTR written outside"), 1);
    CHECK_EQ(stm_peek32(CAN_BTR), btr);
    (void)stm_rd32(CAN_BTR);
    CHECK_EQ(stm_take_violations("CAN_BTR read outside"), 1);
    stm_wr32(CAN_FM1R, 0);
    CHECK_EQ(stm_take_violations("CAN_FM1R written while FINIT is clear"), 1);
    stm_wr32(CAN_F0R1, 0x12345678u);
    CHECK_EQ(stm_take_violations("CAN_F0R1 written while bank 0 is active"), 1);
    CHECK_EQ(stm_peek32(CAN_F0R1), 0);
    stm_wr32(CAN_FMR, 1u);
    CHECK_EQ(stm_take_violations("CAN_FMR: reserved bits"), 1);
    stm_wr32(CAN_FMR, stm_peek32(CAN_FMR) | 1u);
    stm_wr32(CAN_FS1R, 0);
    CHECK_EQ(stm_take_violations("reconfigured while active"), 1);
    stm_wr32(CAN_F0R1, 0); /* with FINIT set: allowed */
    stm_wr32(CAN_FMR, stm_peek32(CAN_FMR) & ~1u);
    CLEAN();

    /* Mailboxes: written only while empty; the receive side is read-only. */
    co_frame_t f = co_frame(0x123, 8, 1);
    CHECK(co_port_can_send(NULL, &f));
    stm_wr32(CAN_TDLR(0), 0);
    CHECK_EQ(stm_take_violations("mailbox 0 register 2 written while not empty"), 1);
    (void)stm_rd32(CAN_RI0R);
    CHECK_EQ(stm_take_violations("while it is empty"), 1);
    stm_wr32(CAN_RDL0R, 0);
    CHECK_EQ(stm_take_violations("read-only"), 1);

    /* Bus-off without ABOM: no recovery until init is entered and left. */
    stm_wr32(CAN_MCR, stm_peek32(CAN_MCR) & ~CAN_MCR_ABOM);
    for (unsigned i = 0; i < 32u; i++) {
        stm_can_bus_tx_error(false);
    }
    CHECK_EQ(stm_peek32(CAN_ESR) & CAN_ESR_BOFF, CAN_ESR_BOFF);
    stm_can_bus_idle(200);
    CHECK_EQ(stm_peek32(CAN_ESR) & CAN_ESR_BOFF, CAN_ESR_BOFF);
    stm_wr32(CAN_MCR, stm_peek32(CAN_MCR) | CAN_MCR_INRQ);
    spin_on_inak(NULL);
    stm_wr32(CAN_MCR, stm_peek32(CAN_MCR) & ~CAN_MCR_INRQ);
    stm_can_bus_idle(1); /* joins the bus: the recovery starts */
    stm_can_bus_idle(127);
    CHECK_EQ(stm_peek32(CAN_ESR) & CAN_ESR_BOFF, CAN_ESR_BOFF);
    stm_can_bus_idle(1);
    CHECK_EQ(stm_peek32(CAN_ESR) & CAN_ESR_BOFF, 0);
    CLEAN();

    /* Flash: FLASH_CR locked after reset; a wrong key locks until reset. */
    boot(0);
    stm_wr32(FLASH_CR, FLASH_CR_PG);
    CHECK_EQ(stm_take_violations("FLASH_CR written while locked"), 1);
    stm_wr32(FLASH_KEYR, 0x45670123u);
    stm_wr32(FLASH_KEYR, 0x11111111u);
    CHECK_EQ(stm_take_violations("wrong key sequence"), 1);
    stm_wr32(FLASH_KEYR, 0x45670123u);
    stm_wr32(FLASH_KEYR, 0xCDEF89ABu);
    CHECK_EQ(stm_take_violations("after a wrong key sequence"), 2);
    CHECK_EQ(stm_peek32(FLASH_CR) & FLASH_CR_LOCK, FLASH_CR_LOCK);
    stm_reset();
    stm_wr32(FLASH_KEYR, 0x45670123u);
    stm_wr32(FLASH_KEYR, 0xCDEF89ABu);
    CHECK_EQ(stm_peek32(FLASH_CR) & FLASH_CR_LOCK, 0);
    CLEAN();
    /* Programming: only with PG, by half-words, over erased half-words
     * (0x0000 excepted), one operation at a time. */
    stm_wr16(EE_BASE, 0x1234);
    CHECK_EQ(stm_take_violations("without PG"), 1);
    stm_wr32(FLASH_CR, FLASH_CR_PG);
    stm_wr32(EE_BASE, 0x12345678u);
    CHECK_EQ(stm_take_violations("programming is by aligned half-words"), 1);
    stm_wr16(EE_BASE, 0x1234);
    stm_wr16(EE_BASE + 2u, 0x5678);
    CHECK_EQ(stm_take_violations("programming started while BSY"), 1);
    while ((stm_rd32(FLASH_SR) & FLASH_SR_BSY) != 0u) {
    }
    CHECK_EQ(stm_rd16(EE_BASE), 0x1234);
    stm_wr32(FLASH_SR, FLASH_SR_EOP);
    stm_wr16(EE_BASE, 0x5678);
    CHECK_EQ(stm_take_violations("not erased"), 1);
    CHECK_EQ(stm_peek32(FLASH_SR) & FLASH_SR_PGERR, FLASH_SR_PGERR);
    CHECK_EQ(stm_rd16(EE_BASE), 0x1234); /* left as it was */
    stm_wr32(FLASH_SR, FLASH_SR_PGERR);
    stm_wr16(EE_BASE, 0x0000); /* the manual's exception */
    CHECK_EQ(stm_rd16(EE_BASE), 0x0000);
    CHECK_EQ(stm_peek32(FLASH_SR) & FLASH_SR_PGERR, 0);
    CLEAN();
    /* An erase started while another runs. */
    stm_wr32(FLASH_CR, FLASH_CR_PER);
    stm_wr32(FLASH_AR, EE_BASE);
    stm_wr32(FLASH_CR, FLASH_CR_PER | FLASH_CR_STRT);
    stm_wr32(FLASH_CR, FLASH_CR_PER | FLASH_CR_STRT);
    CHECK_EQ(stm_take_violations("BSY"), 2); /* CR written while BSY, STRT while BSY */
    stm_wr32(FLASH_AR, EE_BASE + 1024u);
    CHECK_EQ(stm_take_violations("FLASH_AR written while BSY"), 1);
    CHECK_EQ(stm_rd16(EE_BASE), 0xFFFF); /* the read waited for the erase */
    CLEAN();
}

/* ---- start-up ------------------------------------------------------------- */

static void test_board_init(void)
{
    stm_chip_new();
    CHECK(board_init());
    CLEAN();
    CHECK_EQ(stm_peek32(FLASH_ACR) & 7u, 1);       /* one wait state ... */
    CHECK_EQ((stm_peek32(RCC_CFGR) >> 2) & 3u, 3); /* ... before HSI48 is SYSCLK */
    CHECK_EQ(stm_apb_hz(), 48000000u);             /* bxCAN's clock */
    CHECK_EQ(stm_peek32(RCC_APB1ENR) & RCC_APB1ENR_CAN, RCC_APB1ENR_CAN);
    uint32_t moder_a = stm_peek32(GPIO_MODER(GPIOA_BASE));
    CHECK_EQ((moder_a >> 22) & 0xFu, 0xA);      /* PA11, PA12 alternate */
    CHECK_EQ(moder_a >> 26, 0x28000000u >> 26); /* SWD pins PA13, PA14 kept */
    CHECK_EQ((stm_peek32(GPIO_AFRH(GPIOA_BASE)) >> 12) & 0xFFu, 0x44); /* AF4: CAN */
    CHECK_EQ((stm_peek32(GPIO_MODER(GPIOB_BASE)) >> 6) & 0xFu, 0x5);   /* PB3, PB4 out */
    CHECK_EQ(stm_peek32(SYST_RVR), 47999);                             /* 1 ms at 48 MHz */
    CHECK_EQ(stm_peek32(SYST_CSR) & 7u, 7);
    CHECK_EQ(stm_peek32(NVIC_ISER), 1u << 30); /* CEC_CAN */
    CHECK_EQ(stm_can_mode(), STM_CAN_SLEEP);   /* bxCAN left for the bit rate */
}

/* ---- bit timing ------------------------------------------------------------ */

static void test_bit_timing_every_product_rate(void)
{
    for (unsigned i = 0; i < sizeof(product_rates) / sizeof(product_rates[0]); i++) {
        uint16_t kbps = product_rates[i];
        boot(kbps);
        CLEAN();
        uint32_t btr = stm_peek32(CAN_BTR);
        uint32_t sp;
        CHECK_EQ(btr_rate(btr, &sp), kbps * 1000u);
        CHECK(sp >= 750u && sp <= 900u);
        CHECK_EQ(btr & 0xC0000000u, 0);                /* no silent or loop-back mode */
        CHECK((btr >> 24 & 3u) <= ((btr >> 20) & 7u)); /* SJW <= TS2 */
        CHECK_EQ(stm_peek32(CAN_MCR) & CAN_MCR_ABOM, CAN_MCR_ABOM);
        CHECK_EQ(stm_peek32(CAN_IER), CAN_IER_FMPIE0);
        if (sp < 750u || sp > 900u || btr_rate(btr, &sp) != kbps * 1000u) {
            printf("     %u kbit/s: CAN_BTR 0x%08X\n", kbps, (unsigned)btr);
        }
    }
}

/* Every value of the argument: accepted exactly when the controller can
 * run that rate (at most 1 Mbit/s, RM0091 "bit rates up to 1 Mbit/s"),
 * and then exactly that rate; refused without touching the controller. */
static void test_bit_rate_accepted_or_refused(void)
{
    boot(250);
    uint32_t before[12];
    uint32_t after[12];
    unsigned accepted = 0;
    for (uint32_t k = 0; k <= 3100u; k++) {
        can_snapshot(before);
        if (board_can_bitrate((uint16_t)k)) {
            accepted++;
            stm_can_bus_idle(1);
            uint32_t sp;
            uint32_t rate = btr_rate(stm_peek32(CAN_BTR), &sp);
            if (rate != k * 1000u || k > 1000u || sp < 750u || sp > 900u) {
                printf("     %u kbit/s accepted: %u bit/s, sample point %u/1000\n", (unsigned)k,
                       (unsigned)rate, (unsigned)sp);
                FAIL("an accepted bit rate that the controller cannot run exactly");
            }
            CHECK_EQ(stm_can_mode(), STM_CAN_NORMAL);
        } else {
            can_snapshot(after);
            CHECK(memcmp(before, after, sizeof(before)) == 0);
            CHECK_EQ(stm_can_mode(), STM_CAN_NORMAL);
        }
    }
    CHECK(!board_can_bitrate(65535));
    CLEAN();
    /* Every product rate is among them; and rates such as 33 or 801 are not. */
    CHECK(accepted >= sizeof(product_rates) / sizeof(product_rates[0]));
    printf("     %u of 0..3100 kbit/s accepted\n", accepted);
    /* Refused before the first bit rate: the controller stays asleep. */
    boot(0);
    CHECK(!board_can_bitrate(0));
    CHECK(!board_can_bitrate(33));
    CHECK(!board_can_bitrate(2000));
    CHECK_EQ(stm_can_mode(), STM_CAN_SLEEP);
    CLEAN();
}

/* co_port_can_bitrate() calls board_can_bitrate() at run time (LSS
 * activate bit timing, the bit-rate object): again while on the bus, with
 * frames in every stage. */
static void test_bit_rate_change_on_the_bus(void)
{
    boot(250);
    stm_can_frame_t in1 = frame(0x181, 8, 1);
    stm_can_frame_t in2 = frame(0x182, 2, 2);
    CHECK_EQ(stm_can_bus_send(&in1), STM_CAN_FIFO0);
    CHECK_EQ(irq(), 1);                              /* in the board's queue */
    CHECK_EQ(stm_can_bus_send(&in2), STM_CAN_FIFO0); /* in the FIFO, no interrupt yet */
    co_frame_t out = co_frame(0x701, 1, 5);
    CHECK(co_port_can_send(NULL, &out)); /* pending in a mailbox */
    const uint16_t next[] = {500, 125, 1000, 10, 250};
    for (unsigned i = 0; i < sizeof(next) / sizeof(next[0]); i++) {
        CHECK(board_can_bitrate(next[i]));
        CLEAN();
        stm_can_bus_idle(1);
        CHECK_EQ(stm_can_mode(), STM_CAN_NORMAL);
        uint32_t sp;
        CHECK_EQ(btr_rate(stm_peek32(CAN_BTR), &sp), next[i] * 1000u);
    }
    /* Nothing lost: the queued frame, the FIFO's, the pending mailbox. */
    CHECK_EQ(irq(), 1);
    co_frame_t f;
    CHECK(board_can_receive(&f) && same_frame(&f, &in1));
    CHECK(board_can_receive(&f) && same_frame(&f, &in2));
    CHECK(!board_can_receive(&f));
    stm_can_frame_t b;
    CHECK(stm_can_bus_take(&b) && b.id == 0x701 && b.dlc == 1 && b.data[0] == out.data[0]);
    /* The filter is the same: standard frames in, extended ones out. */
    stm_can_frame_t ext = frame(0x181, 8, 3);
    ext.ide = true;
    CHECK_EQ(stm_can_bus_send(&ext), STM_CAN_FILTERED);
    CHECK(receive_one(&in2, &f) && same_frame(&f, &in2));
    CLEAN();
}

/* The bus held dominant (a shorted line, a transceiver fault): the
 * controller cannot join it, and a bit-rate change must not wait for that
 * forever (at start-up the node would never run; at run time it would
 * stop). It joins by itself once the bus is free. */
static uint16_t hang_kbps;
static bool hang_result;

static void call_bitrate(void *arg)
{
    (void)arg;
    hang_result = board_can_bitrate(hang_kbps);
}

static void test_bus_held_dominant(void)
{
    boot(0);
    stm_can_bus_stuck_dominant(true);
    hang_kbps = 250;
    CHECK(stm_run(call_bitrate, NULL));
    CHECK(hang_result);
    CLEAN();
    co_frame_t out = co_frame(0x700, 1, 0);
    CHECK(co_port_can_send(NULL, &out)); /* waits in its mailbox */
    stm_can_frame_t b;
    CHECK(!stm_can_bus_take(&b));
    stm_can_bus_stuck_dominant(false);
    stm_can_bus_idle(1);
    CHECK_EQ(stm_can_mode(), STM_CAN_NORMAL);
    CHECK(stm_can_bus_take(&b) && b.id == 0x700);
    /* Again at run time, on the bus. */
    stm_can_bus_stuck_dominant(true);
    hang_kbps = 500;
    CHECK(stm_run(call_bitrate, NULL));
    CHECK(hang_result);
    stm_can_bus_stuck_dominant(false);
    stm_can_bus_idle(1);
    CHECK_EQ(stm_can_mode(), STM_CAN_NORMAL);
    CLEAN();
}

/* ---- transmission ---------------------------------------------------------- */

static void test_transmit_mailboxes(void)
{
    boot(500);
    /* Three mailboxes: the fourth frame is refused, not overwritten. */
    co_frame_t a = co_frame(0x700, 1, 1);
    co_frame_t b = co_frame(0x080, 8, 2);
    co_frame_t c = co_frame(0x7FF, 0, 3);
    co_frame_t d = co_frame(0x000, 8, 4);
    c.rtr = true;
    CHECK(co_port_can_send(NULL, &a));
    CHECK(co_port_can_send(NULL, &b));
    CHECK(co_port_can_send(NULL, &c));
    CHECK_EQ(stm_peek32(CAN_TSR) & (7u << 26), 0); /* no TME left */
    CHECK(!co_port_can_send(NULL, &d));
    CHECK_EQ(stm_can_tx_pending(), 3);
    CLEAN();
    /* In the order requested (TXFP), whatever the identifiers: a CANopen
     * transfer's frames go out as the stack sent them. */
    stm_can_frame_t got;
    CHECK(stm_can_bus_take(&got));
    CHECK(got.id == 0x700 && !got.ide && !got.rtr && got.dlc == 1 && got.data[0] == a.data[0]);
    CHECK(co_port_can_send(NULL, &d)); /* a mailbox is free again */
    CHECK(stm_can_bus_take(&got));
    CHECK(got.id == 0x080 && got.dlc == 8 && memcmp(got.data, b.data, 8) == 0);
    CHECK(stm_can_bus_take(&got));
    CHECK(got.id == 0x7FF && got.rtr && got.dlc == 0);
    CHECK(stm_can_bus_take(&got));
    CHECK(got.id == 0x000 && got.dlc == 8 && memcmp(got.data, d.data, 8) == 0);
    CHECK(!stm_can_bus_take(&got));
    CHECK_EQ(stm_peek32(CAN_TSR) & (7u << 26), 7u << 26);
    CHECK(!stm_can_irq()); /* transmission raises no interrupt (TMEIE off) */
    CLEAN();
}

/* ---- reception ------------------------------------------------------------ */

static void test_receive_fifo_and_queue(void)
{
    boot(1000);
    co_frame_t f;
    /* Every standard identifier passes the filter, data and remote. */
    unsigned ok = 0;
    for (uint32_t id = 0; id < 0x800u; id++) {
        stm_can_frame_t in = frame(id, (uint8_t)(id % 9u), (uint8_t)id);
        in.rtr = id % 5u == 0u;
        ok += receive_one(&in, &f) && same_frame(&f, &in);
    }
    CHECK_EQ(ok, 0x800);
    /* Extended frames never reach the FIFO. */
    for (uint32_t id = 0; id < 0x20000000u; id += 0x10001u) {
        stm_can_frame_t in = frame(id, 8, 1);
        in.ide = true;
        CHECK_EQ(stm_can_bus_send(&in), STM_CAN_FILTERED);
    }
    CHECK(!stm_can_irq());
    /* A DLC above 8 (allowed on the bus) means 8 bytes. */
    stm_can_frame_t long_dlc = frame(0x123, 15, 9);
    CHECK(receive_one(&long_dlc, &f) && f.dlc == 8 && memcmp(f.data, long_dlc.data, 8) == 0);
    /* Three frames before the interrupt runs: one run takes them all. */
    stm_can_frame_t in[4];
    for (unsigned i = 0; i < 3u; i++) {
        in[i] = frame(0x200u + i, 8, (uint8_t)i);
        CHECK_EQ(stm_can_bus_send(&in[i]), STM_CAN_FIFO0);
    }
    CHECK_EQ(stm_can_fmp0(), 3);
    CHECK_EQ(irq(), 1);
    CHECK_EQ(stm_can_fmp0(), 0);
    for (unsigned i = 0; i < 3u; i++) {
        CHECK(board_can_receive(&f) && same_frame(&f, &in[i]));
    }
    /* A fourth one overruns the FIFO (the third is overwritten, RFLM clear);
     * the interrupt clears FOVR. */
    for (unsigned i = 0; i < 4u; i++) {
        in[i] = frame(0x300u + i, 4, (uint8_t)i);
        CHECK_EQ(stm_can_bus_send(&in[i]), STM_CAN_FIFO0);
    }
    CHECK_EQ(stm_peek32(CAN_RF0R) & CAN_RF0R_FOVR0, CAN_RF0R_FOVR0);
    CHECK_EQ(irq(), 1);
    CHECK_EQ(stm_peek32(CAN_RF0R) & CAN_RF0R_FOVR0, 0);
    CHECK(board_can_receive(&f) && same_frame(&f, &in[0]));
    CHECK(board_can_receive(&f) && same_frame(&f, &in[1]));
    CHECK(board_can_receive(&f) && same_frame(&f, &in[3]));
    CHECK(!board_can_receive(&f));
    /* The board's queue holds 7 frames; more are dropped, the first kept. */
    for (unsigned i = 0; i < 10u; i++) {
        stm_can_frame_t x = frame(0x400u + i, 1, (uint8_t)i);
        CHECK_EQ(stm_can_bus_send(&x), STM_CAN_FIFO0);
        CHECK_EQ(irq(), 1);
    }
    for (unsigned i = 0; i < 7u; i++) {
        CHECK(board_can_receive(&f) && f.id == 0x400u + i);
    }
    CHECK(!board_can_receive(&f));
    /* Were an extended frame ever to pass (a filter that takes them, set
     * here legally by someone else), the interrupt drops it and goes on. */
    stm_wr32(CAN_FMR, stm_peek32(CAN_FMR) | 1u);
    stm_wr32(CAN_FA1R, 0);
    stm_wr32(CAN_F0R2, 0); /* mask nothing: every frame */
    stm_wr32(CAN_FA1R, 1);
    stm_wr32(CAN_FMR, stm_peek32(CAN_FMR) & ~1u);
    stm_can_frame_t ext = frame(0x1ABCDEF, 8, 1);
    stm_can_frame_t std = frame(0x0AB, 8, 2);
    ext.ide = true;
    CHECK_EQ(stm_can_bus_send(&ext), STM_CAN_FIFO0);
    CHECK_EQ(stm_can_bus_send(&std), STM_CAN_FIFO0);
    CHECK_EQ(irq(), 1);
    CHECK_EQ(stm_can_fmp0(), 0);
    CHECK(board_can_receive(&f) && same_frame(&f, &std));
    CHECK(!board_can_receive(&f));
    CLEAN();
}

/* ---- error states ------------------------------------------------------------ */

static void test_error_states_and_bus_off(void)
{
    boot(125);
    CHECK_EQ(board_can_state(), CO_CAN_ACTIVE);
    co_frame_t out = co_frame(0x181, 8, 7);
    CHECK(co_port_can_send(NULL, &out));
    for (unsigned i = 0; i < 11u; i++) {
        stm_can_bus_tx_error(false);
    }
    CHECK_EQ(stm_can_tec(), 88);
    CHECK_EQ(board_can_state(), CO_CAN_ACTIVE);
    stm_can_bus_tx_error(false);
    CHECK_EQ(board_can_state(), CO_CAN_WARNING); /* 96 */
    for (unsigned i = 0; i < 4u; i++) {
        stm_can_bus_tx_error(false);
    }
    CHECK_EQ(stm_can_tec(), 128);
    CHECK_EQ(board_can_state(), CO_CAN_PASSIVE);
    /* Alone on the bus (no acknowledgement): passive, never bus-off. */
    for (unsigned i = 0; i < 50u; i++) {
        stm_can_bus_tx_error(true);
    }
    CHECK_EQ(stm_can_tec(), 128);
    CHECK_EQ(board_can_state(), CO_CAN_PASSIVE);
    for (unsigned i = 0; i < 16u; i++) {
        stm_can_bus_tx_error(false);
    }
    CHECK_EQ(board_can_state(), CO_CAN_BUSOFF); /* TEC 256 */
    stm_can_frame_t got;
    CHECK(!stm_can_bus_take(&got));
    stm_can_frame_t in = frame(0x080, 0, 0);
    CHECK_EQ(stm_can_bus_send(&in), STM_CAN_OFF_BUS);
    /* Automatic recovery (ABOM): 128 x 11 recessive bits, the frame above
     * (its end) counted as one. */
    stm_can_bus_idle(126);
    CHECK_EQ(board_can_state(), CO_CAN_BUSOFF);
    stm_can_bus_idle(1);
    CHECK_EQ(board_can_state(), CO_CAN_ACTIVE);
    CHECK_EQ(stm_can_tec(), 0);
    CHECK(stm_can_bus_take(&got) && got.id == 0x181); /* then the frame goes out */
    /* Receive errors: warning and passive, back by correct receptions. */
    stm_can_bus_rx_error(96);
    CHECK_EQ(board_can_state(), CO_CAN_WARNING);
    stm_can_bus_rx_error(32);
    CHECK_EQ(board_can_state(), CO_CAN_PASSIVE);
    co_frame_t f;
    CHECK(receive_one(&in, &f));
    CHECK_EQ(stm_can_rec(), 127);
    CHECK_EQ(board_can_state(), CO_CAN_WARNING);
    CLEAN();
}

/* ---- flash and the EEPROM emulation ---------------------------------------- */

static void test_flash_driver(void)
{
    boot(0);
    uint8_t rec[64];
    uint8_t back[64];
    for (unsigned i = 0; i < sizeof(rec); i++) {
        rec[i] = (uint8_t)(i * 7u + 3u);
    }
    /* The EEPROM is 8 slots (co_port.h: no size query, a byte beyond is refused). */
    CHECK(co_port_nvm_read(NULL, 8u * CO_STORE_SLOT - 1u, back, 1));
    CHECK(!co_port_nvm_read(NULL, 8u * CO_STORE_SLOT, back, 1));
    /* A record from the start of a blank slot: half-words only. */
    CHECK(co_port_nvm_write(NULL, 0, rec, sizeof(rec)));
    CHECK_EQ(stm_flash_erases(), 0);
    CHECK_EQ(stm_flash_programs(), sizeof(rec) / 2u);
    /* From the start of a slot that holds one: its page erased first. */
    CHECK(co_port_nvm_write(NULL, 0, rec, sizeof(rec)));
    CHECK_EQ(stm_flash_erases(), 1);
    CHECK_EQ(stm_flash_programs(), sizeof(rec));
    CHECK(memcmp(stm_flash_mem() + (EE_BASE - STM_FLASH_BASE), rec, sizeof(rec)) == 0);
    CHECK(co_port_nvm_read(NULL, 0, back, sizeof(back)));
    CHECK(memcmp(back, rec, sizeof(rec)) == 0);
    CHECK_EQ(stm_peek32(FLASH_CR), FLASH_CR_LOCK); /* locked again, nothing selected */
    CHECK_EQ(stm_peek32(FLASH_SR), 0);             /* flags cleared */
    CLEAN();
    /* Erased ahead (the store, when no answer is due): the slot's page,
     * once; a blank slot or an address inside a slot is left alone. */
    CHECK(co_port_nvm_write(NULL, 2u * CO_STORE_SLOT, rec, 8));
    co_port_nvm_prepare(NULL, 2u * CO_STORE_SLOT, CO_STORE_SLOT);
    CHECK_EQ(stm_flash_erases(), 2);
    CHECK(co_port_nvm_read(NULL, 2u * CO_STORE_SLOT, back, 8));
    CHECK(back[0] == 0xFF && back[7] == 0xFF);
    co_port_nvm_prepare(NULL, 2u * CO_STORE_SLOT, CO_STORE_SLOT);
    co_port_nvm_prepare(NULL, 10, CO_STORE_SLOT);
    co_port_nvm_prepare(NULL, 8u * CO_STORE_SLOT, CO_STORE_SLOT);
    CHECK_EQ(stm_flash_erases(), 2);
    CHECK(co_port_nvm_read(NULL, 0, back, sizeof(back)) && memcmp(back, rec, sizeof(rec)) == 0);
    CHECK(co_port_nvm_write(NULL, 2u * CO_STORE_SLOT, rec, 8)); /* no erase on its path */
    CHECK_EQ(stm_flash_erases(), 2);
    CLEAN();
    /* A record continued at an offset: programs only. */
    CHECK(co_port_nvm_write(NULL, 64, rec, 4));
    CHECK_EQ(stm_flash_erases(), 2);
    /* A half-word written twice: refused by the driver before the flash
     * sees it (no PGERR, no violation), the flash unchanged. */
    CHECK(!co_port_nvm_write(NULL, 64, back + 10, 2));
    CHECK(co_port_nvm_read(NULL, 64, back, 4) && memcmp(back, rec, 4) == 0);
    CLEAN();
    /* Each slot in its own page; the last one is the flash's last page. */
    CHECK(co_port_nvm_write(NULL, 7u * CO_STORE_SLOT, rec, 8));
    CHECK(memcmp(stm_flash_mem() + 0x7C00u, rec, 8) == 0);
    CHECK(!co_port_nvm_write(NULL, 8u * CO_STORE_SLOT, rec, 2));
    CHECK_EQ(stm_flash_erases(), 2); /* slot 7 was blank */
    /* Write protection: erase refused (WRPRTERR), reported, flags cleared. */
    stm_flash_write_protect(6, true); /* 0x08006000..0x08006FFF */
    CHECK(!co_port_nvm_write(NULL, 0, rec, sizeof(rec)));
    CHECK_EQ(stm_peek32(FLASH_SR), 0);
    CHECK_EQ(stm_peek32(FLASH_CR), FLASH_CR_LOCK);
    CHECK(co_port_nvm_read(NULL, 0, back, sizeof(back)) && memcmp(back, rec, sizeof(rec)) == 0);
    CHECK(co_port_nvm_write(NULL, 4u * CO_STORE_SLOT, rec, 8)); /* 0x08007000: sector 7 */
    CHECK(!co_port_nvm_write(NULL, 100, rec, 2)); /* an erased half-word: programming refused too */
    CHECK_EQ(stm_flash_mem()[EE_BASE - STM_FLASH_BASE + 100u], 0xFF);
    CHECK_EQ(stm_peek32(FLASH_SR), 0);
    stm_flash_write_protect(6, false);
    /* A worn-out cell: the program ends (EOP) but the read-back differs. */
    stm_flash_wear_out(EE_BASE + STM_FLASH_PAGE + 6u); /* slot 1: the second page */
    CHECK(!co_port_nvm_write(NULL, CO_STORE_SLOT, rec, 8));
    CHECK_EQ(stm_peek32(FLASH_CR), FLASH_CR_LOCK);
    CHECK_EQ(stm_peek32(FLASH_SR), 0);
    /* Someone else left the flash unlocked: no key written again (a key
     * while unlocked would be a bus error). */
    stm_wr32(FLASH_KEYR, 0x45670123u);
    stm_wr32(FLASH_KEYR, 0xCDEF89ABu);
    CHECK(co_port_nvm_write(NULL, 2u * CO_STORE_SLOT, rec, 8));
    CLEAN();
    /* A slow flash (BSY for long) changes nothing. */
    stm_flash_busy_reads(5000);
    CHECK(co_port_nvm_write(NULL, 0, rec, sizeof(rec)));
    CHECK(co_port_nvm_read(NULL, 0, back, sizeof(back)) && memcmp(back, rec, sizeof(rec)) == 0);
    CHECK(stm_flash_image_intact()); /* never a byte outside the EEPROM pages */
    CLEAN();
}

/* ---- a parameter set saved and restored through the board's port ---------- */

static _Alignas(8) unsigned char dst_mem[sizeof(dst_dev_t)];

/* The image's port function (boards/common/mcu_main.c, which has the
 * image's main and is not linked here), word for word: the node's bit-rate
 * requests reach the driver under test. */
bool co_port_can_bitrate(void *port, uint16_t kbps)
{
    (void)port;
    return board_can_bitrate(kbps != 0u ? kbps : 250u);
}

/* Power on a DST X730 as mcu_main.c does, on the modelled chip; returns its node. */
static co_node_t *power_on(void)
{
    void *ports[2] = {NULL, NULL};
    co_node_t *nodes[2];
    drain_queue();
    CHECK(board_init());
    dst_x730_xy10.create(&dst_x730_xy10, dst_mem, ports, nodes);
    co_node_start(nodes[0], 0); /* brings bxCAN to the DST's 250 kbit/s */
    uint32_t sp;
    CHECK_EQ(btr_rate(stm_peek32(CAN_BTR), &sp), 250000u);
    CHECK_EQ(stm_violations_left(), 0);
    stm_can_bus_idle(1);
    stm_can_frame_t boot_up;
    CHECK(stm_can_bus_take(&boot_up));
    CHECK(boot_up.id == 0x700u + nodes[0]->node_id && boot_up.dlc == 1 && boot_up.data[0] == 0);
    return nodes[0];
}

/* An SDO request over the bus; returns the response's first byte, *v its value. */
static uint8_t sdo_over_bus(co_node_t *node, const char *req, uint32_t *v)
{
    stm_can_frame_t in = {.id = 0x600u + node->node_id, .dlc = 8};
    h_hex(req, in.data, 8);
    co_frame_t f;
    CHECK(receive_one(&in, &f));
    co_node_receive(node, &f, board_now_us());
    stm_can_frame_t out;
    if (!stm_can_bus_take(&out) || out.id != 0x580u + node->node_id) {
        FAIL("no SDO response on the bus");
        return 0;
    }
    *v = co_get_u32(&out.data[4]);
    return out.data[0];
}

static void test_parameters_saved_and_restored(void)
{
    stm_chip_new();
    co_node_t *node = power_on();
    uint32_t v;
    CHECK_EQ(sdo_over_bus(node, "2B 17 10 00 64 00 00 00", &v), 0x60); /* 0x1017 = 100 ms */
    CHECK_EQ(sdo_over_bus(node, "2B 00 18 05 0A 00 00 00", &v), 0x60); /* 0x1800:5 = 10 ms */
    CHECK_EQ(sdo_over_bus(node, "23 10 10 01 73 61 76 65", &v), 0x60); /* save */
    CHECK_EQ(stm_flash_erases(), 0); /* into a blank slot: programmed only */
    CHECK(stm_flash_programs() > 0u);
    CLEAN();
    /* Reset the chip (the flash keeps its content) and start again. */
    stm_reset();
    node = power_on();
    CHECK_EQ(sdo_over_bus(node, "40 17 10 00 00 00 00 00", &v), 0x4B);
    CHECK_EQ(v, 100);
    CHECK_EQ(sdo_over_bus(node, "40 00 18 05 00 00 00 00", &v), 0x4B);
    CHECK_EQ(v, 10);
    /* Save twice more and restore: the newest set wins. */
    CHECK_EQ(sdo_over_bus(node, "2B 17 10 00 2C 01 00 00", &v), 0x60); /* 300 ms */
    CHECK_EQ(sdo_over_bus(node, "23 10 10 01 73 61 76 65", &v), 0x60);
    CHECK_EQ(sdo_over_bus(node, "2B 17 10 00 90 01 00 00", &v), 0x60); /* 400 ms */
    CHECK_EQ(sdo_over_bus(node, "23 10 10 01 73 61 76 65", &v), 0x60);
    stm_reset();
    node = power_on();
    CHECK_EQ(sdo_over_bus(node, "40 17 10 00 00 00 00 00", &v), 0x4B);
    CHECK_EQ(v, 400);
    CHECK(stm_flash_image_intact());
    CLEAN();
}

/* ---- time, sleep, LEDs, the test-pattern sensor ------------------------------ */

static void test_time_sleep_leds(void)
{
    boot(0);
    stm_systick_set(47999u); /* the start of a millisecond */
    uint32_t t0 = board_now_us();
    systick_handler();
    systick_handler();
    stm_systick_set(47999u - 480u); /* 10 us into the millisecond */
    CHECK_EQ(board_now_us() - t0, 2010);
    /* The counter reloads, and its interrupt runs, between the two reads
     * of the time: the time read again, not 1 ms behind. */
    stm_systick_set(5);
    uint32_t before = board_now_us();
    stm_systick_wrap_at_read(1, systick_handler);
    uint32_t after = board_now_us();
    CHECK(after > before && after - before < 1000u);
    CHECK_EQ(after % 1000u, 0);
    /* Sleep is a WFI (SysTick wakes the core every millisecond). */
    unsigned w = stm_wfi_count();
    board_sleep(5000);
    CHECK_EQ(stm_wfi_count(), w + 1u);
    /* LEDs: PB3 green, PB4 red. */
    board_leds(true, false);
    CHECK_EQ(stm_gpio_odr('B') & 0x18u, 0x08);
    board_leds(false, true);
    CHECK_EQ(stm_gpio_odr('B') & 0x18u, 0x10);
    board_leds(false, false);
    CHECK_EQ(stm_gpio_odr('B') & 0x18u, 0);
    /* The test pattern stays within +-10 % of each input's range, every product. */
    for (unsigned n = 0; product_list[n] != NULL; n++) {
        const product_t *p = product_list[n];
        int32_t values[PRODUCT_MAX_INPUTS];
        uint32_t faults = 1;
        bool moved = false;
        for (unsigned ms = 0; ms < 20000u; ms += 250u) {
            board_sensor(p, values, &faults);
            CHECK_EQ(faults, 0);
            for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && p->inputs[i].name != NULL; i++) {
                int64_t d = (int64_t)values[i] - p->inputs[i].initial;
                CHECK(d >= -100 * (int64_t)p->inputs[i].limit &&
                      d <= 100 * (int64_t)p->inputs[i].limit);
                moved = moved || d != 0;
            }
            for (unsigned k = 0; k < 250u; k++) {
                systick_handler();
            }
        }
        CHECK(moved);
    }
    CLEAN();
}

/* The serial number (0x1018 sub 4) from the chip's 96-bit unique ID, read
 * where RM0091 33.1 puts it (the model records any other read), its
 * three words folded (uid_serial.h), one per node, another for another chip. */
static void test_serial_from_uid(void)
{
    stm_chip_new();
    static const uint32_t a[3] = {0x00470021u, 0x31385107u, 0x20363650u};
    static const uint32_t b[3] = {0x00470021u, 0x31385107u, 0x20363651u};
    stm_uid_set(a);
    uint32_t s0 = board_serial(0);
    uint32_t s1 = board_serial(1);
    CHECK_EQ(s0, board_uid_serial(a[0] ^ a[1] ^ a[2], 0));
    CHECK_EQ(s1, board_uid_serial(a[0] ^ a[1] ^ a[2], 1));
    CHECK(s0 != 0u && s1 != 0u && s0 != s1);
    CHECK_EQ(board_serial(0), s0); /* stable */
    stm_uid_set(b);
    CHECK(board_serial(0) != s0);
    CHECK_EQ(board_serial(0), board_uid_serial(b[0] ^ b[1] ^ b[2], 0));
    stm_uid_set(a);
    CLEAN();
}

int main(void)
{
    RUN(test_models_catch_violations);
    RUN(test_board_init);
    RUN(test_bit_timing_every_product_rate);
    RUN(test_bit_rate_accepted_or_refused);
    RUN(test_bit_rate_change_on_the_bus);
    RUN(test_bus_held_dominant);
    RUN(test_transmit_mailboxes);
    RUN(test_receive_fifo_and_queue);
    RUN(test_error_states_and_bus_off);
    RUN(test_flash_driver);
    RUN(test_parameters_saved_and_restored);
    RUN(test_time_sleep_leds);
    RUN(test_serial_from_uid);
    return h_finish();
}
