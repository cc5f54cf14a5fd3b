/*
 * board.c - Nucleo-F042K6 (STM32F042K6, Cortex-M0 at 48 MHz from HSI48),
 * bare metal: clock, SysTick time base, bxCAN on PA11/PA12, status LEDs on
 * PB3 (green: the Nucleo's LD3) and PB4 (red: external, pin D12), the
 * EEPROM emulation on the last flash pages, and a sensor that is a fixed
 * test pattern (no sensor driver exists for this board: see board_sensor).
 *
 * Interrupts: SysTick counts milliseconds; the CAN receive interrupt only
 * copies frames into a ring buffer that the main loop drains. Those two
 * and the transmit queue are the board's state: file-level variables,
 * because interrupt handlers take no context (the stack itself has none).
 */
#include "board.h"

#include "boot.h"
#include "co_port.h"
#include "co_progdl.h"
#include "flash_ee.h"
#include "stm32f042.h"
#include "uid_serial.h"

/* ---- identity ----------------------------------------------------------- */

/* The serial number from the 96-bit unique device ID (RM0091 33.1, at
 * 0x1FFFF7AC, read as three words), folded (uid_serial.h). */
uint32_t board_serial(unsigned node)
{
    return board_uid_serial(RD32(UID_BASE) ^ RD32(UID_BASE + 4u) ^ RD32(UID_BASE + 8u), node);
}

/* ---- time -------------------------------------------------------------- */

static volatile uint32_t ms_ticks;

void systick_handler(void);
void systick_handler(void)
{
    ms_ticks++;
}

uint32_t board_now_us(void)
{
    uint32_t ms;
    uint32_t cvr;
    do {
        ms = ms_ticks;
        cvr = RD32(SYST_CVR);
    } while (ms != ms_ticks); /* a tick between the two reads: read again */
    uint32_t load = RD32(SYST_RVR);
    return ms * 1000u + (load - cvr) / (SYSCLK_HZ / 1000000u);
}

void board_sleep(uint32_t us)
{
    (void)us;
#ifndef BOARD_BOOT
    WFI(); /* SysTick wakes the core every millisecond anyway */
#endif
}

/* ---- CAN ----------------------------------------------------------------- */

#ifdef BOARD_BOOT
/* The bootloader reads the controller's FIFO 0 (3 frames) from its loop,
 * which never sleeps (board_sleep above): no interrupt, no queue, 250
 * bytes less of its 4 KiB. It keeps up: a pass that takes a frame is a
 * few microseconds, and the flash is written only while the client waits
 * for the answer (a segment's, a block's acknowledge), so that no frame of
 * the download comes meanwhile; another node's frame lost then is not the
 * bootloader's. */
bool board_can_receive(co_frame_t *f)
{
    while ((RD32(CAN_RF0R) & CAN_RF0R_FMP0) != 0u) {
        uint32_t ri = RD32(CAN_RI0R);
        f->id = (uint16_t)(ri >> 21);
        f->rtr = (ri & CAN_RI0R_RTR) != 0u;
        f->dlc = (uint8_t)(RD32(CAN_RDT0R) & 0x0Fu);
        f->dlc = f->dlc > 8u ? 8u : f->dlc;
        co_put_u32(&f->data[0], RD32(CAN_RDL0R));
        co_put_u32(&f->data[4], RD32(CAN_RDH0R));
        WR32(CAN_RF0R, CAN_RF0R_RFOM0); /* release the FIFO entry */
        if ((ri & CAN_RI0R_IDE) == 0u) {
            return true;
        }
    }
    WR32(CAN_RF0R, CAN_RF0R_FOVR0);
    return false;
}
#else
/* Frames between two main-loop passes: the controller's FIFO holds 3 more,
 * and a pass takes far less than the 8 frame times (>= 376 us at 1 Mbit/s)
 * this queue covers. A frame that finds it full is lost, as one that finds
 * the controller's FIFO full. No count is kept: nothing read it (reporting
 * it, as the JD's CiA 301 EMCY 8110h "CAN overrun", would need a port
 * function the stack does not have). */
#define RXQ 8u
static co_frame_t rxq[RXQ];
static volatile uint32_t rx_head, rx_tail; /* ISR writes head, main reads tail */

void can_irq_handler(void);
void can_irq_handler(void)
{
    while ((RD32(CAN_RF0R) & CAN_RF0R_FMP0) != 0u) {
        uint32_t ri = RD32(CAN_RI0R);
        uint32_t next = (rx_head + 1u) % RXQ;
        if (next != rx_tail && (ri & CAN_RI0R_IDE) == 0u) {
            co_frame_t *f = &rxq[rx_head];
            f->id = (uint16_t)(ri >> 21);
            f->rtr = (ri & CAN_RI0R_RTR) != 0u;
            f->dlc = (uint8_t)(RD32(CAN_RDT0R) & 0x0Fu);
            f->dlc = f->dlc > 8u ? 8u : f->dlc;
            co_put_u32(&f->data[0], RD32(CAN_RDL0R));
            co_put_u32(&f->data[4], RD32(CAN_RDH0R));
            rx_head = next;
        } /* else the queue is full (the frame is lost) or it is 29-bit */
        WR32(CAN_RF0R, CAN_RF0R_RFOM0); /* release the FIFO entry */
    }
    if ((RD32(CAN_RF0R) & CAN_RF0R_FOVR0) != 0u) {
        WR32(CAN_RF0R, CAN_RF0R_FOVR0);
    }
}

bool board_can_receive(co_frame_t *f)
{
    if (rx_tail == rx_head) {
        return false;
    }
    *f = rxq[rx_tail];
    rx_tail = (rx_tail + 1u) % RXQ;
    return true;
}
#endif

/* Bit timing at 48 MHz, SJW 1: 16 time quanta a bit (1 + 13 + 2: sample
 * point 87.5 %) with a prescaler of 3000 / kbit/s, for every rate that
 * divides 3000 from 3 kbit/s (the 10-bit prescaler) to 1 Mbit/s (bxCAN's
 * and ISO 11898's top rate): all of CiA 301's but 800 k; 800 k: 15 quanta
 * (1 + 12 + 2: 86.7 %), prescaler 4. Computed rather than tabled: 60 bytes
 * less flash. Any other rate is refused before the controller is touched.
 * 1500 and 3000 kbit/s were accepted and programmed (found by the model
 * test, tests/unit/test_nucleo_drivers.c): now refused by the prescaler's
 * lower bound; the remainder by multiplication, one division call fewer. */
bool board_can_bitrate(uint16_t kbps)
{
    uint32_t ts1 = 13u;
    uint32_t brp = 4u;
    if (kbps == 800u) {
        ts1 = 12u;
    } else {
        if (kbps < 3u) {
            return false;
        }
        brp = 3000u / kbps;
        if (brp < 3u || brp * kbps != 3000u) { /* above 1 Mbit/s, or not exact */
            return false;
        }
    }
    WR32(CAN_MCR, CAN_MCR_INRQ | CAN_MCR_ABOM | CAN_MCR_TXFP); /* init; auto bus-off recovery */
    while ((RD32(CAN_MSR) & CAN_MSR_INAK) == 0u) {
    }
    WR32(CAN_BTR, (brp - 1u) | ((ts1 - 1u) << 16) | ((2u - 1u) << 20));
    /* Filter 0, 32-bit mask mode to FIFO 0: every standard-ID frame (the
     * IDE bit must be 0); the stack sorts them out. */
    WR32(CAN_FMR, RD32(CAN_FMR) | 1u);
    WR32(CAN_FA1R, RD32(CAN_FA1R) & ~1u);
    WR32(CAN_FS1R, RD32(CAN_FS1R) | 1u);
    WR32(CAN_FM1R, RD32(CAN_FM1R) & ~1u);
    WR32(CAN_FFA1R, RD32(CAN_FFA1R) & ~1u);
    WR32(CAN_F0R1, 0);
    WR32(CAN_F0R2, CAN_RI0R_IDE);
    WR32(CAN_FA1R, RD32(CAN_FA1R) | 1u);
    WR32(CAN_FMR, RD32(CAN_FMR) & ~1u);
#ifndef BOARD_BOOT
    WR32(CAN_IER, CAN_IER_FMPIE0);
#endif
    /* Leave init mode. The controller joins the bus by itself once it has
     * seen 11 recessive bits (RM0091); not waited for: on a bus held
     * dominant that wait never ended, and the node hung at start-up or on a
     * bit-rate change at run time (found by the register model,
     * tests/unit/test_nucleo_drivers.c). Frames queued meanwhile wait in
     * their mailboxes. */
    WR32(CAN_MCR, RD32(CAN_MCR) & ~CAN_MCR_INRQ);
    return true;
}

bool co_port_can_send(void *port, const co_frame_t *frame)
{
    (void)port;
    uint32_t tsr = RD32(CAN_TSR);
    for (unsigned n = 0; n < 3u; n++) {
        if ((tsr & (CAN_TSR_TME0 << n)) != 0u) {
            WR32(CAN_TDTR(n), frame->dlc);
            WR32(CAN_TDLR(n), co_get_u32(&frame->data[0]));
            WR32(CAN_TDHR(n), co_get_u32(&frame->data[4]));
            WR32(CAN_TIR(n),
                 ((uint32_t)frame->id << 21) | (frame->rtr ? CAN_TIR_RTR : 0u) | CAN_TIR_TXRQ);
            return true;
        }
    }
    return false; /* three mailboxes busy: the stack counts the loss */
}

uint8_t board_can_state(void)
{
    uint32_t esr = RD32(CAN_ESR);
    if ((esr & CAN_ESR_BOFF) != 0u) {
        return CO_CAN_BUSOFF;
    }
    if ((esr & CAN_ESR_EPVF) != 0u) {
        return CO_CAN_PASSIVE;
    }
    return (esr & CAN_ESR_EWGF) != 0u ? CO_CAN_WARNING : CO_CAN_ACTIVE;
}

/* ---- LEDs -------------------------------------------------------------- */

void board_leds(bool green, bool red)
{
    WR32(GPIO_BSRR(GPIOB_BASE), (green ? (1u << 3) : (1u << 19)) | (red ? (1u << 4) : (1u << 20)));
}

/* ---- flash EEPROM ---------------------------------------------------------- */

extern uint32_t _eeprom_start;

static bool flash_wait(void)
{
    while ((RD32(FLASH_SR) & FLASH_SR_BSY) != 0u) {
    }
    uint32_t sr = RD32(FLASH_SR);
    WR32(FLASH_SR, FLASH_SR_EOP | FLASH_SR_PGERR | FLASH_SR_WRPRTERR);
    return (sr & (FLASH_SR_PGERR | FLASH_SR_WRPRTERR)) == 0u;
}

static void flash_unlock(void)
{
    if ((RD32(FLASH_CR) & FLASH_CR_LOCK) != 0u) {
        WR32(FLASH_KEYR, 0x45670123u);
        WR32(FLASH_KEYR, 0xCDEF89ABu);
    }
}

/* Known and left: the code runs from the flash it erases, so the core
 * stalls for the page erase (tens of ms, datasheet); interrupts wait, the
 * bxCAN FIFO (3 frames) can overrun on a busy bus and SysTick loses all
 * but one of the milliseconds (time is late, never backwards). A save is a
 * master's explicit request; running the erase from RAM with the vectors
 * there would cost flash the X730 does not have. */
static bool f042_erase(void *ctx, uint32_t page)
{
    (void)ctx;
    flash_unlock();
    WR32(FLASH_CR, FLASH_CR_PER);
    WR32(FLASH_AR, page);
    WR32(FLASH_CR, FLASH_CR_PER | FLASH_CR_STRT);
    bool ok = flash_wait();
    WR32(FLASH_CR, FLASH_CR_LOCK);
    return ok;
}

static bool f042_program16(void *ctx, uint32_t addr, uint16_t v)
{
    (void)ctx;
    if (RD16(addr) != 0xFFFFu) {
        return false; /* erase before write */
    }
    flash_unlock();
    WR32(FLASH_CR, FLASH_CR_PG);
    WR16(addr, v);
    bool ok = flash_wait() && RD16(addr) == v;
    WR32(FLASH_CR, FLASH_CR_LOCK);
    return ok;
}

static void f042_read(void *ctx, uint32_t addr, void *buf, uint32_t len)
{
    (void)ctx;
    uint8_t *b = buf;
    for (uint32_t i = 0; i < len; i++) {
        b[i] = RD8(addr + i);
    }
}

static const flash_ops_t f042_flash = {
    .erase = f042_erase, .program16 = f042_program16, .read = f042_read};
static const flash_ee_t eeprom = {
    .ops = &f042_flash, .ctx = 0, .base = 0x08006000u, .page_size = 1024u, .pages = 8u};

bool co_port_nvm_read(void *port, uint32_t addr, void *buf, uint32_t len)
{
    (void)port;
    return flash_ee_read(&eeprom, addr, buf, len);
}

bool co_port_nvm_write(void *port, uint32_t addr, const void *buf, uint32_t len)
{
    (void)port;
    return flash_ee_write(&eeprom, addr, buf, len);
}

void co_port_nvm_prepare(void *port, uint32_t addr, uint32_t len)
{
    (void)port;
    (void)len;
    flash_ee_prepare(&eeprom, addr);
}

/* ---- the sensor: a fixed test pattern ----------------------------------- */

/* No sensor driver exists for this board: every input sweeps a triangle of
 * +-10 % of its range around its initial value, one period in 20 s, so the
 * outputs move and every code path of the product runs. */
void board_sensor(const product_t *p, int32_t values[], uint32_t *faults)
{
    uint32_t t = ms_ticks % 20000u;
    uint32_t tri = t < 10000u ? t : 20000u - t; /* 0..10000 */
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && p->inputs[i].name != 0; i++) {
        const product_input_t *in = &p->inputs[i];
        /* initial + (tri - 5000) x limit x 1000 x 10 % / 5000, in unsigned
         * arithmetic (no signed division helper in the image): tri x limit
         * <= 10000 x 100000 fits 32 bits. */
        uint32_t lim = (uint32_t)in->limit;
        values[i] = in->initial + (int32_t)(tri * lim / 50u) - (int32_t)(100u * lim);
    }
    *faults = 0;
}

/* ---- start-up ------------------------------------------------------------- */

bool board_init(void)
{
    /* 48 MHz from the internal HSI48; one flash wait state, prefetch on. */
    WR32(FLASH_ACR, 0x11u);
    WR32(RCC_CR2, RD32(RCC_CR2) | RCC_CR2_HSI48ON);
    while ((RD32(RCC_CR2) & RCC_CR2_HSI48RDY) == 0u) {
    }
    WR32(RCC_CFGR, (RD32(RCC_CFGR) & ~3u) | RCC_CFGR_SW_HSI48);
    while (((RD32(RCC_CFGR) >> 2) & 3u) != RCC_CFGR_SW_HSI48) {
    }
    WR32(RCC_AHBENR, RD32(RCC_AHBENR) | RCC_AHBENR_IOPA | RCC_AHBENR_IOPB);
    WR32(RCC_APB1ENR, RD32(RCC_APB1ENR) | RCC_APB1ENR_CAN);
    /* PA11 CAN_RX, PA12 CAN_TX: alternate function 4. */
    WR32(GPIO_MODER(GPIOA_BASE), (RD32(GPIO_MODER(GPIOA_BASE)) & ~(0xFu << 22)) | (0xAu << 22));
    WR32(GPIO_AFRH(GPIOA_BASE), (RD32(GPIO_AFRH(GPIOA_BASE)) & ~(0xFFu << 12)) | (0x44u << 12));
    /* PB3, PB4: outputs. */
    WR32(GPIO_MODER(GPIOB_BASE), (RD32(GPIO_MODER(GPIOB_BASE)) & ~(0xFu << 6)) | (0x5u << 6));
    WR32(SYST_RVR, SYSCLK_HZ / 1000u - 1u);
    WR32(SYST_CVR, 0);
    WR32(SYST_CSR, 7u); /* processor clock, interrupt, enable */
    WR32(NVIC_ISER, 1u << CAN_IRQ);
    return true;
}

/* A system reset (ARMv6-M SYSRESETREQ). The answer to a stop, still in
 * its transmit mailbox, may be lost with it: CiA 302-3 lets a stop go
 * unanswered when the device resets into its bootloader (tools/update
 * and Lely's master carry on). Decision: waiting for the mailboxes would
 * cost the DST X730 28 B of flash it does not have (its 10 496 B). */
void board_reset(void)
{
    WR32(SCB_AIRCR, SCB_AIRCR_SYSRESETREQ);
    for (;;) {
    }
}

/* ---- bootloader ------------------------------------------------------------ */

/* Not in the host build against the chip's models (STM32F042_MODEL,
 * tests/unit/test_nucleo_drivers.c): these name the link script's
 * addresses and enter code through the Cortex-M's stack pointer. */
#ifndef STM32F042_MODEL

/* The layout (layout.ld; docs/program-download.md): the application area
 * and the boot-info page in the same 1 KiB pages as the EEPROM, written
 * through the same driver. */
extern const uint8_t _app_area[], _app_area_end[], _app_vectors[], _boot_info[];
extern volatile uint32_t _app_running;
#define BOOT_APP_RUNNING 0x4E555241u /* startup.c's */

const flash_ee_t *board_boot_area(void)
{
    static const flash_ee_t area = {.ops = &f042_flash,
                                    .ctx = 0,
                                    .base = (uint32_t)(uintptr_t)_app_area,
                                    .page_size = 1024u,
                                    .pages = 19u}; /* layout.ld's area: 0x08001400 .. 0x08006000 */
    return &area;
}

const flash_ee_t *board_boot_info(void)
{
    static const flash_ee_t info = {.ops = &f042_flash,
                                    .ctx = 0,
                                    .base = (uint32_t)(uintptr_t)_boot_info,
                                    .page_size = 1024u,
                                    .pages = 1u};
    return &info;
}

uint8_t board_boot_check(const co_image_hdr_t *h)
{
    if (h->board != CO_IMAGE_BOARD_NUCLEO_F042K6) {
        return CO_PROGDL_FORMAT;
    }
    if (h->load_addr != (uint32_t)(uintptr_t)_app_vectors ||
        h->length > (uint32_t)(_app_area_end - _app_area)) {
        return CO_PROGDL_ADDRESS;
    }
    return CO_PROGDL_OK;
}

/* Enter the application as a reset would: its stack pointer and reset
 * handler from its table, the bootloader's vectors forwarding to it. */
void board_boot_app(const co_image_hdr_t *h)
{
    const uint32_t *v = (const uint32_t *)(uintptr_t)h->load_addr;
    _app_running = BOOT_APP_RUNNING;
    __asm__ volatile("msr msp, %0\n"
                     "bx %1\n"
                     :
                     : "r"(v[0]), "r"(v[1]));
    for (;;) {
    }
}
#endif /* STM32F042_MODEL */
