/*
 * board.c - a RISC-V (rv32imac) port for QEMU's "virt" machine, the second
 * architecture the stack builds for. CAN goes one of two ways, found at
 * start:
 *  - an SJA1000 CAN controller on a PCI card (QEMU's kvaser_pci,
 *    pcm3680_pci or mioe3680_pci; see "CAN controller" below), driven by
 *    boards/common/sja1000.c: the image is then a node on whatever bus
 *    QEMU connects the card to (a host SocketCAN interface), and the UART
 *    carries the simulated sensor's input lines only;
 *  - without a card, frames travel as SLCAN text lines ("t1FF8...",
 *    Lawicel's serial-line CAN protocol) on the 16550 UART, beside the
 *    input lines ("set x=10", "fault sensor on"; serial_link.h).
 * Time comes from the CLINT's mtime (10 MHz); the EEPROM is emulated in the
 * machine's CFI flash (cfi_flash.c, see the end of this file). The serial
 * line's state, the controller's and the flash's description are the
 * board's state.
 */
#include "board.h"

#include "boot.h"
#include "cfi_flash.h"
#include "co_port.h"
#include "co_progdl.h"
#include "flash_ee.h"
#include "serial_link.h"
#include "sja1000.h"
#include "uid_serial.h"

#define UART 0x10000000u
#define UART_THR (*(volatile uint8_t *)(UART + 0u))
#define UART_RBR (*(volatile uint8_t *)(UART + 0u))
#define UART_LSR (*(volatile uint8_t *)(UART + 5u))
#define MTIME_LO (*(volatile uint32_t *)0x0200BFF8u)
#define MTIME_HI (*(volatile uint32_t *)0x0200BFFCu)

/* The serial line: SLCAN frames and simulated-input lines (serial_link.h). */
static serial_link_t link;
static void put(char c);
static void wake_sources_init(void);
static bool can_probe(void);
static bool have_card(void);
static bool can_ready(void);
static bool can_bitrate(uint16_t kbps);
static bool can_rx_waiting(void);

/* The controller (can.io set when a card was found at start). */
static sja1000_t can;

int main(void);
void reset_c(void) __attribute__((used)); /* called from the assembly above: LTO must keep it */

__attribute__((naked, section(".text.start"))) void _start(void);
void _start(void)
{
    __asm__ volatile("la sp, _estack\n"
                     "call reset_c\n"
                     "1: j 1b\n");
}

void reset_c(void)
{
    extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss;
    const uint32_t *src = &_sidata;
    for (uint32_t *p = &_sdata; p < &_edata;) {
        *p++ = *src++;
    }
    for (uint32_t *p = &_sbss; p < &_ebss;) {
        *p++ = 0;
    }
    (void)main();
}

/* QEMU's virt machine has no unique ID to read: the serial number is the
 * fold of a constant ("rv32", uid_serial.h), the node in bit 0. Every
 * rv32-virt image has the same ones: two of them on one bus need their
 * LSS addresses told apart by their node-IDs (a real board reads its
 * chip's ID here). */
uint32_t board_serial(unsigned node)
{
    return board_uid_serial(0x72763332u, node);
}

bool board_init(void)
{
    (void)can_probe();
    wake_sources_init();
    return true;
}

/* The controller's bit timing, or, without one, told on the line the way
 * an SLCAN adapter is ("S6": 500 kbit/s). */
bool board_can_bitrate(uint16_t kbps)
{
    if (have_card()) {
        link.kbps = kbps; /* the simulated bus-off's recovery time */
        return can_bitrate(kbps);
    }
    return serial_link_bitrate(&link, kbps, put);
}

/* The CLINT's 64-bit mtime (10 MHz), read as two words: again if the high
 * word moved in between. */
static uint64_t mtime(void)
{
    uint32_t hi;
    uint32_t lo;
    do {
        hi = MTIME_HI;
        lo = MTIME_LO;
    } while (hi != MTIME_HI);
    return ((uint64_t)hi << 32) | lo;
}

/* mtime in microseconds, its low 32 bits: wrapping at 2^32 us as board.h
 * wants (the low word of mtime alone, divided, jumped back to 0 every
 * 429.5 s, and the stack took time for running backwards). */
uint32_t board_now_us(void)
{
    return (uint32_t)(mtime() / 10u);
}

/*
 * Sleep in WFI until the CLINT's timer reaches the deadline or the UART has
 * a byte: the core idles (QEMU then uses no host CPU) instead of spinning.
 * No trap handler: with mstatus.MIE clear, WFI still wakes on an interrupt
 * that mie enables and that is pending (RISC-V privileged spec, WFI), so
 * the timer (MTIE) and the PLIC's external line (MEIE, the UART's source
 * claimed and completed here) only wake the core.
 */
#define MTIMECMP_LO (*(volatile uint32_t *)0x02004000u)
#define MTIMECMP_HI (*(volatile uint32_t *)0x02004004u)
#define UART_IER (*(volatile uint8_t *)(UART + 1u))
#define PLIC_PRIORITY(src) (*(volatile uint32_t *)(0x0C000000u + 4u * (src)))
#define PLIC_ENABLE0 (*(volatile uint32_t *)0x0C002000u) /* hart 0, M-mode */
#define PLIC_THRESHOLD0 (*(volatile uint32_t *)0x0C200000u)
#define PLIC_CLAIM0 (*(volatile uint32_t *)0x0C200004u)
#define UART_IRQ 10u /* the virt machine's UART0 at the PLIC */
#define MIE_MTIE (1u << 7)
#define MIE_MEIE (1u << 11)

/* Claims and completes what the PLIC has pending: the UART's and the CAN
 * card's sources, once each at most. A source whose line is still high
 * (the SJA1000's until its interrupt register is read) is pending again at
 * once, and the WFI after this returns at once: the main loop's next pass
 * reads it (sja1000_service). */
static void plic_done(void)
{
    for (unsigned i = 0; i < 2u; i++) {
        uint32_t claimed = PLIC_CLAIM0;
        if (claimed == 0u) {
            return;
        }
        PLIC_CLAIM0 = claimed;
    }
}

static void wake_sources_init(void)
{
    UART_IER = 1u; /* received data available */
    PLIC_PRIORITY(UART_IRQ) = 1u;
    PLIC_ENABLE0 = 1u << UART_IRQ;
    PLIC_THRESHOLD0 = 0u;
    /* Zicsr for this one instruction: -march stays rv32imac, whose
     * multilib libgcc the images link. */
    __asm__ volatile(".option push\n.option arch, +zicsr\ncsrs mie, %0\n.option pop"
                     :
                     : "r"(MIE_MTIE | MIE_MEIE));
}

void board_sleep(uint32_t us)
{
    /* The deadline in mtime ticks (10 MHz), 64 bits: at most 1 s ahead. */
    uint32_t ticks = (us < 1000000u ? us : 1000000u) * 10u;
    uint64_t deadline = mtime() + ticks;
    MTIMECMP_LO = 0xFFFFFFFFu; /* no moment with a deadline in the past */
    MTIMECMP_HI = (uint32_t)(deadline >> 32);
    MTIMECMP_LO = (uint32_t)deadline;
    plic_done(); /* interrupts seen before: done */
    if ((UART_LSR & 1u) == 0u && !can_rx_waiting()) {
        __asm__ volatile("wfi");
    }
    plic_done();
}

static void put(char c)
{
    while ((UART_LSR & 0x20u) == 0u) {
    }
    UART_THR = (uint8_t)c;
}

bool co_port_can_send(void *port, const co_frame_t *f)
{
    (void)port;
    if (have_card()) { /* false: queue full or bus-off, the stack counts it */
        return can_ready() && sja1000_send(&can, f);
    }
    serial_link_tx(f, put);
    return true;
}

/* Once, on the serial line: the controller's receive FIFO went out of step
 * (sja1000_receive: QEMU's model after a remote frame with a DLC above 0),
 * and the node hears no frame from the bus any more; docs/emulator.md. */
static void tell_out_of_step(void)
{
    static bool told;
    if (can.out_of_step && !told) {
        told = true;
        for (const char *s = "error: CAN receive FIFO out of step: no more frames\r"; *s != '\0';
             s++) {
            put(*s);
        }
    }
}

/* The serial line's input lines first; then a frame from the controller,
 * or, without one, a frame line from the serial line. With a controller an
 * SLCAN frame line on the UART is ignored: the bus is the controller's. A
 * simulated bus-off (`can bus-off` on the line) loses what arrives meanwhile. */
bool board_can_receive(co_frame_t *f)
{
    while ((UART_LSR & 1u) != 0u) {
        if (serial_link_rx(&link, (char)UART_RBR, f, put) && !have_card()) {
            return true;
        }
    }
    while (can_ready() && sja1000_receive(&can, f)) {
        if (link.can_state != (uint8_t)CO_CAN_BUSOFF) {
            return true;
        }
    }
    tell_out_of_step();
    return false;
}

/* The worse of the controller's state and the one the serial line
 * simulates (`can passive`, `can bus-off`: a bench's fault injection on
 * top of the real controller). */
uint8_t board_can_state(void)
{
    co_can_state_t s = serial_link_can_state(&link, board_now_us());
    if (can_ready()) {
        co_can_state_t hw = sja1000_service(&can);
        s = hw > s ? hw : s;
    }
    return (uint8_t)s;
}

void board_can_filter(const co_rx_id_t *ids, unsigned n)
{
    if (can_ready()) {
        sja1000_set_filter(&can, ids, n);
    }
}

void board_leds(bool green, bool red)
{
    (void)green;
    (void)red; /* no LEDs on the virt machine */
}

/* The true inputs as the serial line set them (serial_link_sample). */
void board_sensor(const product_t *p, int32_t values[], uint32_t *faults)
{
    serial_link_sample(&link, p, values, faults);
}

/* ---- flash EEPROM ---------------------------------------------------------- */

/*
 * The EEPROM emulation (boards/common/flash_ee.c, as on the Nucleo) in the
 * virt machine's second CFI flash bank (QEMU: -drive if=pflash,unit=1,
 * format=raw,file=F, a 32 MiB file; tools/emu makes it). Each
 * parameter-store slot gets an erase block of its own: 8 slots (two nodes
 * x two classes x two copies) in the first 8 blocks of 256 KiB.
 *
 * Without a drive QEMU still maps the bank, but as zero-filled RAM that
 * takes every command and forgets it at exit: it reads 0x00 where an
 * erased flash reads 0xFF. The last word of the bank, which nothing here
 * ever programs, tells the two apart: 0x00000000 means no flash file, and
 * the board then has no EEPROM at all. Every access fails, so the node runs
 * on its defaults and reports the stored set as unreadable, as on a board
 * whose EEPROM is missing (CO_STORE_HW: EMCY 6300h, or the product's own
 * report such as the DST's 0x4001); a save answers SDO abort 0x06060000.
 * A flash file whose last word someone zeroed is taken as missing too.
 */
#define FLASH_BANK1 0x22000000u
#define EEPROM_SLOTS 8u

static cfi_flash_t flash;
static flash_ee_t eeprom;
static bool eeprom_probed;

/* The EEPROM, probed at its first use (the first store access, at node
 * creation); NULL when there is none. */
static const flash_ee_t *nvm(void)
{
    if (!eeprom_probed) {
        eeprom_probed = true;
        if (cfi_flash_probe(&flash, FLASH_BANK1) &&
            flash.block_size * (EEPROM_SLOTS + 1u) <= flash.size &&
            *(const volatile uint32_t *)(uintptr_t)(flash.base + flash.size - 4u) != 0u) {
            eeprom = (flash_ee_t){.ops = &cfi_flash_ops,
                                  .ctx = &flash,
                                  .base = flash.base,
                                  .page_size = flash.block_size,
                                  .pages = EEPROM_SLOTS};
        }
    }
    return eeprom.ops != NULL ? &eeprom : NULL;
}

bool co_port_nvm_read(void *port, uint32_t addr, void *buf, uint32_t len)
{
    (void)port;
    const flash_ee_t *fe = nvm();
    return fe != NULL && flash_ee_read(fe, addr, buf, len);
}

bool co_port_nvm_write(void *port, uint32_t addr, const void *buf, uint32_t len)
{
    (void)port;
    const flash_ee_t *fe = nvm();
    return fe != NULL && flash_ee_write(fe, addr, buf, len);
}

void co_port_nvm_prepare(void *port, uint32_t addr, uint32_t len)
{
    (void)port;
    (void)len;
    const flash_ee_t *fe = nvm();
    if (fe != NULL) {
        flash_ee_prepare(fe, addr);
    }
}

/* ---- CAN controller -------------------------------------------------------- */

/*
 * QEMU's virt machine has a PCIe host bridge (ECAM at 0x30000000, the I/O
 * window at 0x03000000, INTA..INTD of slot s on PLIC sources 32 + (s +
 * pin) mod 4). Nothing configures it before this image (no firmware runs
 * first: the image is the -bios), so the image scans bus 0, gives the
 * card's I/O BARs their addresses itself, and turns I/O decoding on.
 * Cards known, all with one SJA1000 at 16 MHz (their data sheets; the
 * first channel where a card has two):
 *   Kvaser PCIcan (10e8:8406): BAR1, registers 1 byte apart; its PCI
 *     bridge (S5920, BAR0) passes the controller's interrupt on only with
 *     INTCSR's add-on interrupt enable bit set;
 *   Advantech PCM-3680I (13fe:c002): BAR0, 1 byte apart;
 *   Advantech MIOe-3680 (13fe:c302): BAR0, 4 bytes apart.
 */
#define ECAM 0x30000000u
#define PCI_IO_WINDOW 0x03000000u
#define PCI_IO_FIRST 0x1000u /* port addresses handed out from here up */
#define PCI_IRQ_BASE 32u
#define PLIC_ENABLE1 (*(volatile uint32_t *)0x0C002004u) /* sources 32..63 */
#define SJA_CLOCK_HZ 16000000u
#define S5920_INTCSR 0x38u
#define S5920_ADDON_INT_ENABLE 0x2000u

typedef struct can_card {
    uint32_t vendor_device; /* vendor in the low half, as config space word 0 reads */
    uint8_t bar;            /* the SJA1000's BAR */
    uint8_t shift;          /* log2 of the register spacing */
    bool s5920;             /* a Kvaser PCIcan: interrupt enable in BAR0 */
} can_card_t;

static const can_card_t cards[] = {
    {0x840610E8u, 1u, 0u, true},
    {0xC00213FEu, 0u, 0u, false},
    {0xC30213FEu, 0u, 2u, false},
};

/* Where the controller's registers are: base (CPU address) and spacing. */
typedef struct sja_port {
    uint32_t base;
    uint8_t shift;
} sja_port_t;

static sja_port_t sja_port;
static uint32_t can_irq; /* its PLIC source, 0: none */

static uint8_t sja_read(void *ctx, uint8_t reg)
{
    const sja_port_t *p = ctx;
    return *(volatile uint8_t *)(uintptr_t)(p->base + ((uint32_t)reg << p->shift));
}

static void sja_write(void *ctx, uint8_t reg, uint8_t value)
{
    const sja_port_t *p = ctx;
    *(volatile uint8_t *)(uintptr_t)(p->base + ((uint32_t)reg << p->shift)) = value;
}

static const sja1000_io_t sja_io = {sja_read, sja_write};

static volatile uint32_t *cfg(uint32_t dev, uint32_t off)
{
    return (volatile uint32_t *)(uintptr_t)(ECAM + (dev << 15) + off);
}

/* Sizes and places the device's I/O BARs (memory BARs are left off: the
 * cards here have none); returns the CPU address of BAR want (0: none). */
static uint32_t assign_io_bars(uint32_t dev, unsigned want)
{
    static uint32_t next = PCI_IO_FIRST;
    uint32_t found = 0;
    for (unsigned b = 0; b < 6u; b++) {
        volatile uint32_t *bar = cfg(dev, 0x10u + 4u * b);
        *bar = 0xFFFFFFFFu;
        uint32_t v = *bar;
        if ((v & 1u) == 0u || (v & 0xFFFCu) == 0u) {
            *bar = 0u;
            continue; /* a memory BAR or none */
        }
        uint32_t size = (~(v & 0xFFFCu) + 1u) & 0xFFFFu;
        next = (next + size - 1u) & ~(size - 1u);
        *bar = next;
        if (b == want) {
            found = PCI_IO_WINDOW + next;
        }
        next += size;
    }
    *cfg(dev, 0x04u) |= 1u; /* command: I/O space decoding on */
    return found;
}

/* The first known card on bus 0: its controller's registers and its PLIC
 * source. */
static bool can_probe(void)
{
    for (uint32_t dev = 0; dev < 32u; dev++) {
        uint32_t id = *cfg(dev, 0u);
        for (unsigned k = 0; k < sizeof cards / sizeof cards[0]; k++) {
            if (id != cards[k].vendor_device) {
                continue;
            }
            uint32_t base = assign_io_bars(dev, cards[k].bar);
            if (base == 0u) {
                return false;
            }
            if (cards[k].s5920) {
                volatile uint32_t *intcsr =
                    (volatile uint32_t *)(uintptr_t)(PCI_IO_WINDOW + (*cfg(dev, 0x10u) & 0xFFFCu) +
                                                     S5920_INTCSR);
                *intcsr = *intcsr | S5920_ADDON_INT_ENABLE;
            }
            uint32_t pin = (*cfg(dev, 0x3Cu) >> 8) & 0xFFu; /* 1: INTA */
            can_irq = pin != 0u ? PCI_IRQ_BASE + (dev + pin - 1u) % 4u : 0u;
            sja_port = (sja_port_t){.base = base, .shift = cards[k].shift};
            return true;
        }
    }
    return false;
}

static bool have_card(void)
{
    return sja_port.base != 0u;
}

/* The controller is up (its first bit rate taken). */
static bool can_ready(void)
{
    return can.io != NULL;
}

/* The first bit rate brings the controller up; later ones retime it. A
 * card that does not answer as an SJA1000 leaves the board without CAN. */
static bool can_bitrate(uint16_t kbps)
{
    if (can.io == NULL) {
        sja1000_t fresh;
        if (!sja1000_init(&fresh, &sja_io, &sja_port, SJA_CLOCK_HZ, kbps)) {
            return false;
        }
        can = fresh;
        if (can_irq != 0u) {
            PLIC_PRIORITY(can_irq) = 1u;
            PLIC_ENABLE1 |= 1u << (can_irq - 32u);
        }
        return true;
    }
    return sja1000_set_bitrate(&can, kbps);
}

static bool can_rx_waiting(void)
{
    return can_ready() && (sja_read(&sja_port, SJA_SR) & SJA_SR_RBS) != 0u;
}

/* ---- bootloader ------------------------------------------------------------ */

/*
 * Bank 1 beyond the EEPROM (docs/program-download.md, "Bootloaders and
 * flash layouts"): erase block EEPROM_SLOTS holds the boot-info record,
 * the APP_BLOCKS blocks after it the application area (an image: header,
 * then the payload, which the bootloader copies to the load address in
 * RAM and runs there: code cannot run from a flash bank that answers
 * status reads while the EEPROM beside it is written). No flash file: no
 * area (NULL), as no EEPROM.
 */
#define APP_BLOCKS 4u
#define SIFIVE_TEST (*(volatile uint32_t *)0x00100000u) /* QEMU's reset and power device */
#define SIFIVE_TEST_RESET 0x7777u

extern uint8_t _app_load[], _app_max[]; /* layout.ld */

static flash_ee_t boot_flash(uint32_t block, uint32_t blocks)
{
    const flash_ee_t *fe = nvm();
    if (fe == NULL || flash.block_size * (EEPROM_SLOTS + 1u + APP_BLOCKS) > flash.size) {
        return (flash_ee_t){0};
    }
    return (flash_ee_t){.ops = &cfi_flash_ops,
                        .ctx = &flash,
                        .base = flash.base + block * flash.block_size,
                        .page_size = flash.block_size,
                        .pages = blocks};
}

const flash_ee_t *board_boot_area(void)
{
    static flash_ee_t area;
    area = boot_flash(EEPROM_SLOTS + 1u, APP_BLOCKS);
    return area.ops != NULL ? &area : NULL;
}

const flash_ee_t *board_boot_info(void)
{
    static flash_ee_t info;
    info = boot_flash(EEPROM_SLOTS, 1u);
    return info.ops != NULL ? &info : NULL;
}

uint8_t board_boot_check(const co_image_hdr_t *h)
{
    if (h->board != CO_IMAGE_BOARD_RV32_VIRT) {
        return CO_PROGDL_FORMAT;
    }
    const flash_ee_t *a = board_boot_area();
    if (a == NULL || h->load_addr != (uint32_t)(uintptr_t)_app_load ||
        h->length > a->pages * a->page_size ||
        h->length - CO_IMAGE_HDR_SIZE > (uint32_t)(uintptr_t)_app_max) {
        return CO_PROGDL_ADDRESS;
    }
    return CO_PROGDL_OK;
}

void board_boot_app(const co_image_hdr_t *h)
{
    const flash_ee_t *a = board_boot_area();
    a->ops->read(a->ctx, a->base + CO_IMAGE_HDR_SIZE, _app_load, h->length - CO_IMAGE_HDR_SIZE);
    /* The instructions just stored are fetched next (Zifencei for this one
     * instruction, as Zicsr above). */
    __asm__ volatile(".option push\n.option arch, +zifencei\nfence.i\n.option pop" ::: "memory");
    ((void (*)(void))(uintptr_t)_app_load)();
    for (;;) {
    }
}

/* The frames queued (the answer to a stop) leave first: the controller is
 * serviced until its queue is empty and its transmit buffer released,
 * within a bound (a bus that acknowledges nothing does not hold the
 * reset). The serial line sends each character before the next. */
void board_reset(void)
{
    for (uint32_t n = 0; n < 100000u && can_ready() &&
                         (can.tx_len != 0u || (sja_read(&sja_port, SJA_SR) & SJA_SR_TBS) == 0u);
         n++) {
        (void)sja1000_service(&can);
    }
    SIFIVE_TEST = SIFIVE_TEST_RESET;
    for (;;) {
    }
}
