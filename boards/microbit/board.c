/*
 * board.c - BBC micro:bit (nRF51822, Cortex-M0 at 16 MHz), bare metal, as
 * qemu-system-arm's "microbit" machine emulates it: the Cortex-M0 board
 * that runs in an emulator, with the same product images as the Nucleo
 * (boards/CMakeLists.txt). The chip has no CAN controller: frames travel as
 * SLCAN text lines on the UART (boards/common/serial_link.h, which also
 * takes the simulated sensor input); time is TIMER0 counting microseconds;
 * the EEPROM emulation lives in the last 8 flash pages, programmed through
 * the NVMC (boards/common/flash_ee.c, as on the Nucleo).
 *
 * Interrupts: the UART receive interrupt only copies bytes into a ring
 * that the main loop drains; TIMER0's compare interrupt only wakes the
 * core from board_sleep. The ring and the serial line's state are the
 * board's state: file-level variables, because interrupt handlers take no
 * context (the stack itself has none).
 */
#include "board.h"

#include "boot.h"
#include "co_port.h"
#include "co_progdl.h"
#include "flash_ee.h"
#include "nrf51.h"
#include "serial_link.h"
#include "uid_serial.h"

/* ---- identity ------------------------------------------------------------- */

/* The serial number from the 64-bit device identifier FICR DEVICEID[0..1]
 * (nRF51 reference manual, FICR), folded (uid_serial.h). */
uint32_t board_serial(unsigned node)
{
    return board_uid_serial(REG(FICR_DEVICEID0) ^ REG(FICR_DEVICEID1), node);
}

/* ---- time ---------------------------------------------------------------- */

/* TIMER0 runs from the 16 MHz clock divided by 2^4: one count a
 * microsecond, 32 bits wide, so it wraps like board_now_us must. Reading it
 * takes a capture task (the nRF51 timer has no counter register): channel
 * 3 captures, channel 0 is board_sleep's alarm. */
#define TIME_CC 3u
#define ALARM_CC 0u

uint32_t board_now_us(void)
{
    TIMER0_TASKS_CAPTURE(TIME_CC) = 1u;
    return TIMER0_CC(TIME_CC);
}

void timer0_handler(void);
void timer0_handler(void)
{
    TIMER0_EVENTS_COMPARE(ALARM_CC) = 0u; /* the alarm only wakes the core */
    /* Read back: the write reaches the peripheral before the handler
     * returns, else its interrupt fires once more (nRF51 reference manual,
     * peripheral interface). */
    (void)TIMER0_EVENTS_COMPARE(ALARM_CC);
}

/* ---- UART: the serial line --------------------------------------------- */

#ifndef BOARD_BOOT
/* Received bytes between two main-loop passes. When the ring is full the
 * interrupt stops taking bytes (the UART's FIFO then holds them, and
 * qemu's holds the rest back on the socket) until the main loop has taken
 * some: nothing is lost in the emulator. On silicon, a 6-byte FIFO at
 * 115200 baud, bytes would be lost after 520 us more. */
#define RX_RING 64u /* a power of two: the free-running indices wrap cleanly */
static volatile uint8_t rx_ring[RX_RING];
static volatile uint32_t rx_head, rx_tail; /* the ISR writes head, main tail */

void uart0_handler(void);
void uart0_handler(void)
{
    while (UART_EVENTS_RXDRDY != 0u) {
        if (rx_head - rx_tail == RX_RING) {
            UART_INTENCLR = UART_INT_RXDRDY; /* full: board_can_receive resumes */
            return;
        }
        /* Event first, then RXD: reading RXD raises the event again when
         * the FIFO holds more. */
        UART_EVENTS_RXDRDY = 0u;
        rx_ring[rx_head % RX_RING] = (uint8_t)UART_RXD;
        rx_head++;
    }
}
#endif

/* One byte out; waits until the UART took it: at once in qemu. Deviation
 * from co_port.h's "must not block", as on rv32-virt: on silicon, 87 us a
 * byte at 115200 baud, a frame's line (up to 22 bytes) would hold the main
 * loop 2 ms; a real port would send from a ring by the TXDRDY interrupt. */
static void put(char c)
{
    UART_TXD = (uint8_t)c;
    while (UART_EVENTS_TXDRDY == 0u) {
    }
    UART_EVENTS_TXDRDY = 0u;
}

/* The serial line: SLCAN frames and simulated-input lines (serial_link.h). */
static serial_link_t link;

#ifdef BOARD_BOOT
/* The bootloader reads the UART from its loop, which never sleeps
 * (board_sleep): no interrupt, no ring, 200 bytes less of its 4 KiB. The
 * UART's FIFO (and qemu's, which holds bytes back on the socket) keeps
 * what comes while the flash is written, and the client waits for the
 * answer then anyway. */
bool board_can_receive(co_frame_t *f)
{
    bool got = false;
    while (!got && UART_EVENTS_RXDRDY != 0u) {
        UART_EVENTS_RXDRDY = 0u;
        got = serial_link_rx(&link, (char)UART_RXD, f, put);
    }
    return got;
}
#else
bool board_can_receive(co_frame_t *f)
{
    bool got = false;
    while (!got && rx_tail != rx_head) {
        char c = (char)rx_ring[rx_tail % RX_RING];
        rx_tail++;
        got = serial_link_rx(&link, c, f, put);
    }
    UART_INTENSET = UART_INT_RXDRDY; /* room in the ring (again) */
    return got;
}
#endif

bool co_port_can_send(void *port, const co_frame_t *f)
{
    (void)port;
    serial_link_tx(f, put);
    return true;
}

/* Told on the line the way an SLCAN adapter is ("S6": 500 kbit/s). */
bool board_can_bitrate(uint16_t kbps)
{
    return serial_link_bitrate(&link, kbps, put);
}

uint8_t board_can_state(void)
{
    return (uint8_t)serial_link_can_state(&link, board_now_us());
}

#ifdef BOARD_BOOT
void board_sleep(uint32_t us)
{
    (void)us; /* the bootloader polls (board_can_receive) */
}
#else
void board_sleep(uint32_t us)
{
    if (us == 0u) {
        return;
    }
    /* At most a second: the alarm's deadline stays well inside the half
     * range the wrap-safe comparison needs. */
    uint32_t deadline = board_now_us() + co_min_u32(us, 1000000u);
    TIMER0_CC(ALARM_CC) = deadline;
    TIMER0_EVENTS_COMPARE(ALARM_CC) = 0u;
    /* With interrupts masked, a byte or the alarm arriving after the checks
     * below stays pending, and a pending interrupt ends WFI: no wake-up is
     * missed. The handlers run once they are unmasked. */
    __asm__ volatile("cpsid i" ::: "memory");
    if (rx_tail == rx_head && co_time_before(board_now_us(), deadline)) {
        __asm__ volatile("wfi");
    }
    __asm__ volatile("cpsie i" ::: "memory");
}
#endif

/* ---- LEDs ------------------------------------------------------------------ */

void board_leds(bool green, bool red)
{
    /* The micro:bit's LEDs are a 5 x 5 matrix that must be scanned row by
     * row, and the emulator runs without a display: not driven. The LED
     * states remain visible to a master through the products' objects. */
    (void)green;
    (void)red;
}

/* ---- the sensor: the serial line's simulated inputs ------------------------ */

/* The true inputs as the serial line set them (serial_link_sample). */
void board_sensor(const product_t *p, int32_t values[], uint32_t *faults)
{
    serial_link_sample(&link, p, values, faults);
}

/* ---- flash EEPROM on the NVMC ---------------------------------------------- */

/* The last 8 pages of flash (link.ld: _eeprom_start, _eeprom_end): one page
 * per store slot, 4 per node, for up to two nodes, as on the Nucleo. */
#define EEPROM_BASE 0x3E000u
#define EEPROM_PAGES 8u

static void nvmc_config(uint32_t mode)
{
    NVMC_CONFIG = mode;
    while (NVMC_READY == 0u) {
    }
}

static bool nrf51_erase(void *ctx, uint32_t page)
{
    (void)ctx;
    nvmc_config(NVMC_CONFIG_EEN);
    NVMC_ERASEPAGE = page;
    while (NVMC_READY == 0u) {
    }
    nvmc_config(NVMC_CONFIG_REN);
    const volatile uint32_t *w = (const volatile uint32_t *)page;
    for (uint32_t i = 0; i < NRF51_PAGE_SIZE / 4u; i++) {
        if (w[i] != 0xFFFFFFFFu) {
            return false; /* the page did not erase */
        }
    }
    return true;
}

/* The NVMC programs whole 32-bit words (a half-word store to flash is a bus
 * fault in qemu's model); programming only clears bits, so the other half
 * of the word is written as 0xFFFF, which leaves it as it is. A word is
 * thus written at most twice between erases, the nRF51's limit (n_WRITE,
 * product specification). */
static bool nrf51_program16(void *ctx, uint32_t addr, uint16_t v)
{
    (void)ctx;
    const volatile uint16_t *h = (const volatile uint16_t *)addr;
    if (*h != 0xFFFFu) {
        return false; /* erase before write */
    }
    uint32_t shift = (addr & 2u) * 8u;
    nvmc_config(NVMC_CONFIG_WEN);
    *(volatile uint32_t *)(addr & ~3u) = ~(0xFFFFu << shift) | ((uint32_t)v << shift);
    while (NVMC_READY == 0u) {
    }
    nvmc_config(NVMC_CONFIG_REN);
    return *h == v;
}

static void nrf51_read(void *ctx, uint32_t addr, void *buf, uint32_t len)
{
    (void)ctx;
    const volatile uint8_t *p = (const volatile uint8_t *)addr;
    uint8_t *b = buf;
    for (uint32_t i = 0; i < len; i++) {
        b[i] = p[i];
    }
}

static const flash_ops_t nrf51_flash = {
    .erase = nrf51_erase, .program16 = nrf51_program16, .read = nrf51_read};
static const flash_ee_t eeprom = {.ops = &nrf51_flash,
                                  .ctx = 0,
                                  .base = EEPROM_BASE,
                                  .page_size = NRF51_PAGE_SIZE,
                                  .pages = EEPROM_PAGES};

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

/* ---- start-up ------------------------------------------------------------- */

bool board_init(void)
{
    /* The linker script's EEPROM pages are the ones this file programs. */
    extern uint32_t _eeprom_start, _eeprom_end;
    if ((uintptr_t)&_eeprom_start != EEPROM_BASE ||
        (uintptr_t)&_eeprom_end != EEPROM_BASE + EEPROM_PAGES * NRF51_PAGE_SIZE) {
        return false;
    }
    /* The 16 MHz crystal: the UART's baud rate and the timer's microsecond
     * need it (the internal RC oscillator is off by up to 2 %). */
    CLOCK_TASKS_HFCLKSTART = 1u;
    while (CLOCK_EVENTS_HFCLKSTARTED == 0u) {
    }
    TIMER0_MODE = 0u; /* timer */
    TIMER0_BITMODE = TIMER_BITMODE_32;
    TIMER0_PRESCALER = 4u; /* 16 MHz / 2^4 */
#ifndef BOARD_BOOT
    TIMER0_INTENSET = TIMER_INT_COMPARE(ALARM_CC);
#endif
    TIMER0_TASKS_CLEAR = 1u;
    TIMER0_TASKS_START = 1u;
    /* The micro:bit's USB serial line: P0.24 TX, P0.25 RX, 115200 8N1. */
    UART_PSELTXD = 24u;
    UART_PSELRXD = 25u;
    UART_BAUDRATE = UART_BAUD_115200;
    UART_ENABLE = UART_ENABLE_ON;
    UART_TASKS_STARTTX = 1u;
    UART_TASKS_STARTRX = 1u;
#ifndef BOARD_BOOT
    UART_INTENSET = UART_INT_RXDRDY;
    NVIC_ISER = (1u << UART_IRQ) | (1u << TIMER0_IRQ);
#endif
    return true;
}

/* A system reset (ARMv6-M SYSRESETREQ). The UART sends each byte before
 * the next is written (put), so the answer to a stop has left. */
void board_reset(void)
{
    SCB_AIRCR = 0x05FA0004u; /* the key, and a system reset */
    for (;;) {
    }
}

/* ---- bootloader ------------------------------------------------------------ */

/* The layout (layout.ld; docs/program-download.md): the application area
 * and the boot-info page in 1 KiB pages like the EEPROM's, written
 * through the same driver. */
extern const uint8_t _app_area[], _app_area_end[], _app_vectors[], _boot_info[];
extern volatile uint32_t _app_running;
#define BOOT_APP_RUNNING 0x4E555241u /* startup.c's */

const flash_ee_t *board_boot_area(void)
{
    static const flash_ee_t area = {.ops = &nrf51_flash,
                                    .ctx = 0,
                                    .base = (uint32_t)(uintptr_t)_app_area,
                                    .page_size = NRF51_PAGE_SIZE,
                                    .pages = 243u}; /* layout.ld's area: 0x1400 .. 0x3E000 */
    return &area;
}

const flash_ee_t *board_boot_info(void)
{
    static const flash_ee_t info = {.ops = &nrf51_flash,
                                    .ctx = 0,
                                    .base = (uint32_t)(uintptr_t)_boot_info,
                                    .page_size = NRF51_PAGE_SIZE,
                                    .pages = 1u};
    return &info;
}

uint8_t board_boot_check(const co_image_hdr_t *h)
{
    if (h->board != CO_IMAGE_BOARD_MICROBIT) {
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
