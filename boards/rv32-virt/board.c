/*
 * board.c - a RISC-V (rv32imac) port for QEMU's "virt" machine, the second
 * architecture the stack builds for. The machine has no CAN controller, so
 * frames travel as SLCAN text lines ("t1FF8...", Lawicel's serial-line CAN
 * protocol) on the 16550 UART, and the simulated sensor's input lines
 * ("set x=10", "fault sensor on") on the same line (serial_link.h); time
 * comes from the CLINT's mtime (10 MHz); the EEPROM is emulated in the
 * machine's CFI flash (cfi_flash.c, see the end of this file).
 * The serial line's state and the flash's description are the board's state.
 */
#include "board.h"

#include "cfi_flash.h"
#include "co_port.h"
#include "flash_ee.h"
#include "serial_link.h"
#include "uid_serial.h"

#define UART 0x10000000u
#define UART_THR (*(volatile uint8_t *)(UART + 0u))
#define UART_RBR (*(volatile uint8_t *)(UART + 0u))
#define UART_LSR (*(volatile uint8_t *)(UART + 5u))
#define MTIME_LO (*(volatile uint32_t *)0x0200BFF8u)

/* The serial line: SLCAN frames and simulated-input lines (serial_link.h). */
static serial_link_t link;
static void put(char c);
static void wake_sources_init(void);

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
    wake_sources_init();
    return true;
}

/* Told on the line the way an SLCAN adapter is ("S6": 500 kbit/s). */
bool board_can_bitrate(uint16_t kbps)
{
    return serial_link_bitrate(&link, kbps, put);
}

uint32_t board_now_us(void)
{
    return MTIME_LO / 10u; /* 10 MHz */
}

/*
 * Sleep in WFI until the CLINT's timer reaches the deadline or the UART has
 * a byte: the core idles (QEMU then uses no host CPU) instead of spinning.
 * No trap handler: with mstatus.MIE clear, WFI still wakes on an interrupt
 * that mie enables and that is pending (RISC-V privileged spec, WFI), so
 * the timer (MTIE) and the PLIC's external line (MEIE, the UART's source
 * claimed and completed here) only wake the core.
 */
#define MTIME_HI (*(volatile uint32_t *)0x0200BFFCu)
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
    uint32_t hi;
    uint32_t lo;
    do {
        hi = MTIME_HI;
        lo = MTIME_LO;
    } while (hi != MTIME_HI);
    uint32_t dlo = lo + ticks;
    uint32_t dhi = hi + (dlo < lo ? 1u : 0u);
    MTIMECMP_LO = 0xFFFFFFFFu; /* no moment with a deadline in the past */
    MTIMECMP_HI = dhi;
    MTIMECMP_LO = dlo;
    uint32_t claimed = PLIC_CLAIM0; /* a UART interrupt seen before: done */
    if (claimed != 0u) {
        PLIC_CLAIM0 = claimed;
    }
    if ((UART_LSR & 1u) == 0u) {
        __asm__ volatile("wfi");
    }
    claimed = PLIC_CLAIM0;
    if (claimed != 0u) {
        PLIC_CLAIM0 = claimed;
    }
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
    serial_link_tx(f, put);
    return true;
}

bool board_can_receive(co_frame_t *f)
{
    while ((UART_LSR & 1u) != 0u) {
        if (serial_link_rx(&link, (char)UART_RBR, f, put)) {
            return true;
        }
    }
    return false;
}

uint8_t board_can_state(void)
{
    return (uint8_t)serial_link_can_state(&link, board_now_us());
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
            eeprom = (flash_ee_t){.ops = &cfi_flash_ops, .ctx = &flash, .base = flash.base,
                                  .page_size = flash.block_size, .pages = EEPROM_SLOTS};
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
