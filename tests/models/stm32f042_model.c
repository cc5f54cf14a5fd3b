/*
 * stm32f042_model.c - the bus of the STM32F042 model (see
 * stm32f042_model.h): each access goes to the model that owns its address;
 * the violation log and the hang detector; and the small parts the board
 * touches besides bxCAN and flash, from RM0091: RCC (HSI48 start-up, the
 * system clock switch, peripheral clock enables), the flash wait states
 * (FLASH_ACR), GPIO ports A and B, and the Cortex-M0 SysTick and NVIC.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "stm32f042_parts.h"

/* ---- violations and hangs ---------------------------------------------- */

#define LOG_MAX 64u
#define LOG_TEXT 200u

static char vlog[LOG_MAX][LOG_TEXT];
static unsigned vcount;   /* entries in vlog */
static unsigned vdropped; /* recorded beyond LOG_MAX (never taken) */

void stm_violation(const char *fmt, ...)
{
    char text[LOG_TEXT];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof(text), fmt, ap);
    va_end(ap);
    if (vcount < LOG_MAX) {
        memcpy(vlog[vcount++], text, sizeof(text));
    } else {
        vdropped++;
    }
}

unsigned stm_violations_left(void)
{
    return vcount + vdropped;
}

unsigned stm_take_violations(const char *what)
{
    unsigned taken = 0;
    unsigned kept = 0;
    for (unsigned i = 0; i < vcount; i++) {
        if (strstr(vlog[i], what) != NULL) {
            taken++;
        } else {
            memmove(vlog[kept++], vlog[i], LOG_TEXT);
        }
    }
    vcount = kept;
    return taken;
}

unsigned stm_violations_report(void)
{
    unsigned n = stm_violations_left();
    for (unsigned i = 0; i < vcount; i++) {
        fprintf(stderr, "model: violation: %s\n", vlog[i]);
    }
    if (vdropped > 0u) {
        fprintf(stderr, "model: and %u more\n", vdropped);
    }
    stm_violations_clear();
    return n;
}

void stm_violations_clear(void)
{
    vcount = 0;
    vdropped = 0;
}

static unsigned spin_count; /* reads since the last write or change */
static jmp_buf *hang_exit;

void stm_progress(void)
{
    spin_count = 0;
}

/* One more read (of addr, returning v) with nothing written and nothing
 * changed since the last one: a loop of such reads, of one register or of
 * several, can never end. */
static void spin_check(uint32_t addr, uint32_t v)
{
    if (++spin_count < STM_SPIN_LIMIT) {
        return;
    }
    stm_violation(
        "hang: %u register reads and nothing written or changed (the last: 0x%08X = 0x%08X)",
        STM_SPIN_LIMIT, (unsigned)addr, (unsigned)v);
    spin_count = 0;
    if (hang_exit != NULL) {
        longjmp(*hang_exit, 1);
    }
    (void)stm_violations_report();
    fprintf(stderr, "model: the code under test hangs (outside stm_run)\n");
    abort();
}

bool stm_run(void (*fn)(void *arg), void *arg)
{
    jmp_buf here;
    jmp_buf *outer = hang_exit;
    if (setjmp(here) != 0) {
        hang_exit = outer;
        return false;
    }
    hang_exit = &here;
    fn(arg);
    hang_exit = outer;
    return true;
}

/* ---- RCC and flash wait states (RM0091 sections 6 and 3.5) ------------- */

#define RCC_BASE 0x40021000u
#define HSI48_ON (1u << 16)
#define HSI48_RDY (1u << 17)
#define CAN_EN (1u << 25)
#define IOPA_EN (1u << 17)
#define IOPB_EN (1u << 18)

static struct {
    uint32_t cr, cfgr, ahbenr, apb2enr, apb1enr, cr2;
    unsigned hsi48_wait; /* CR2 reads until HSI48RDY (0: not starting) */
    unsigned sw_wait;    /* CFGR reads until SWS follows SW */
    uint32_t acr;        /* FLASH_ACR */
} rcc;

static uint32_t sysclk_hz(void)
{
    switch ((rcc.cfgr >> 2) & 3u) {
    case 0u:
        return 8000000u; /* HSI */
    case 3u:
        return 48000000u; /* HSI48 */
    default:
        return 0u; /* HSE and PLL: never selected by this model (not ready) */
    }
}

uint32_t stm_apb_hz(void)
{
    uint32_t hz = sysclk_hz();
    uint32_t hpre = (rcc.cfgr >> 4) & 0xFu;
    uint32_t ppre = (rcc.cfgr >> 8) & 7u;
    static const uint8_t hshift[8] = {1, 2, 3, 4, 6, 7, 8, 9}; /* /2 .. /512 */
    if (hpre >= 8u) {
        hz >>= hshift[hpre - 8u];
    }
    if (ppre >= 4u) {
        hz >>= ppre - 3u; /* /2 .. /16 */
    }
    return hz;
}

/* RM0091 3.5.1: zero wait states up to 24 MHz, one above. */
static void check_wait_states(void)
{
    if (sysclk_hz() > 24000000u && (rcc.acr & 7u) == 0u) {
        stm_violation(
            "FLASH_ACR: zero wait states with SYSCLK at %u Hz (one is needed above 24 MHz)",
            (unsigned)sysclk_hz());
    }
}

static uint32_t rcc_read(uint32_t off, bool peek)
{
    switch (off) {
    case 0x00u:
        return rcc.cr;
    case 0x04u:
        if (!peek && rcc.sw_wait > 0u && --rcc.sw_wait == 0u) {
            uint32_t sw = rcc.cfgr & 3u;
            bool ready = sw == 0u || (sw == 3u && (rcc.cr2 & HSI48_RDY) != 0u);
            if (ready) {
                rcc.cfgr = (rcc.cfgr & ~0xCu) | (sw << 2);
                check_wait_states();
            }
        }
        return rcc.cfgr;
    case 0x14u:
        return rcc.ahbenr;
    case 0x18u:
        return rcc.apb2enr;
    case 0x1Cu:
        return rcc.apb1enr;
    case 0x34u:
        if (!peek && rcc.hsi48_wait > 0u && --rcc.hsi48_wait == 0u) {
            rcc.cr2 |= HSI48_RDY;
        }
        return rcc.cr2;
    default:
        if (!peek) {
            stm_violation("RCC: read of an unmodelled register at offset 0x%02X", (unsigned)off);
        }
        return 0;
    }
}

static void rcc_write(uint32_t off, uint32_t v)
{
    switch (off) {
    case 0x04u:
        /* SWS (3:2) is read-only; the switch happens once the source is ready. */
        rcc.cfgr = (v & ~0xCu) | (rcc.cfgr & 0xCu);
        rcc.sw_wait = 2u;
        break;
    case 0x14u:
        rcc.ahbenr = v;
        break;
    case 0x18u:
        rcc.apb2enr = v;
        break;
    case 0x1Cu:
        rcc.apb1enr = v;
        break;
    case 0x34u:
        if ((v & HSI48_ON) != 0u && (rcc.cr2 & HSI48_ON) == 0u) {
            rcc.hsi48_wait = 2u;
        }
        if ((v & HSI48_ON) == 0u) {
            if ((rcc.cfgr & 0xCu) == 0xCu) {
                stm_violation("RCC_CR2: HSI48 switched off while it is the system clock");
            }
            rcc.cr2 &= ~HSI48_RDY;
        }
        rcc.cr2 = (v & ~HSI48_RDY) | (rcc.cr2 & HSI48_RDY);
        break;
    default:
        stm_violation("RCC: write of an unmodelled register at offset 0x%02X", (unsigned)off);
        break;
    }
}

/* ---- GPIO (RM0091 section 8) ---------------------------------------------- */

typedef struct gpio {
    uint32_t moder, otyper, ospeedr, pupdr, odr, lckr, afrl, afrh;
} gpio_t;

static gpio_t gpio[2];

uint32_t stm_gpio_odr(char port)
{
    return gpio[port == 'B' ? 1 : 0].odr;
}

static uint32_t gpio_read(gpio_t *g, uint32_t off, bool peek)
{
    switch (off) {
    case 0x00u:
        return g->moder;
    case 0x04u:
        return g->otyper;
    case 0x08u:
        return g->ospeedr;
    case 0x0Cu:
        return g->pupdr;
    case 0x10u:
        return g->odr; /* IDR: the pins driven as outputs read back; nothing drives the others */
    case 0x14u:
        return g->odr;
    case 0x1Cu:
        return g->lckr;
    case 0x20u:
        return g->afrl;
    case 0x24u:
        return g->afrh;
    default:
        if (!peek) {
            stm_violation("GPIO: read of offset 0x%02X (write-only or unmodelled)", (unsigned)off);
        }
        return 0;
    }
}

static void gpio_write(gpio_t *g, uint32_t off, uint32_t v)
{
    switch (off) {
    case 0x00u:
        g->moder = v;
        break;
    case 0x04u:
        g->otyper = v & 0xFFFFu;
        break;
    case 0x08u:
        g->ospeedr = v;
        break;
    case 0x0Cu:
        g->pupdr = v;
        break;
    case 0x14u:
        g->odr = v & 0xFFFFu;
        break;
    case 0x18u:
        /* BSRR: the set half wins over the reset half. */
        g->odr = (g->odr & ~(v >> 16)) | (v & 0xFFFFu);
        break;
    case 0x20u:
        g->afrl = v;
        break;
    case 0x24u:
        g->afrh = v;
        break;
    case 0x28u:
        g->odr &= ~(v & 0xFFFFu); /* BRR */
        break;
    default:
        stm_violation("GPIO: write of offset 0x%02X (read-only or unmodelled)", (unsigned)off);
        break;
    }
}

/* ---- SysTick and NVIC (Cortex-M0) ------------------------------------ */

static struct {
    uint32_t csr, rvr, cvr;
    unsigned wrap_in; /* CVR reads until the armed reload (0: none) */
    void (*handler)(void);
    uint32_t nvic_enabled;
    unsigned wfi;
} core;

void stm_systick_set(uint32_t cvr)
{
    core.cvr = cvr & 0xFFFFFFu;
}

void stm_systick_wrap_at_read(unsigned nth, void (*handler)(void))
{
    core.wrap_in = nth;
    core.handler = handler;
}

void stm_wfi(void)
{
    core.wfi++;
}

unsigned stm_wfi_count(void)
{
    return core.wfi;
}

static uint32_t core_read(uint32_t addr, bool peek)
{
    switch (addr) {
    case 0xE000E010u: {
        uint32_t v = core.csr;
        if (!peek) {
            core.csr &= ~(1u << 16); /* COUNTFLAG clears on read */
        }
        return v;
    }
    case 0xE000E014u:
        return core.rvr;
    case 0xE000E018u:
        if (!peek && core.wrap_in > 0u && --core.wrap_in == 0u) {
            core.cvr = core.rvr;
            core.csr |= 1u << 16;
            if (core.handler != NULL) {
                core.handler();
            }
        }
        return core.cvr;
    case 0xE000E01Cu:
        return 0x40000000u | (48000000u / 8u / 100u - 1u); /* CALIB: no exact 10 ms */
    case 0xE000E100u:
    case 0xE000E180u:
        return core.nvic_enabled;
    default:
        if (!peek) {
            stm_violation("core: read of unmodelled address 0x%08X", (unsigned)addr);
        }
        return 0;
    }
}

static void core_write(uint32_t addr, uint32_t v)
{
    switch (addr) {
    case 0xE000E010u:
        core.csr = (core.csr & (1u << 16)) | (v & 7u);
        break;
    case 0xE000E014u:
        core.rvr = v & 0xFFFFFFu;
        break;
    case 0xE000E018u:
        core.cvr = 0; /* any write clears the counter and COUNTFLAG */
        core.csr &= ~(1u << 16);
        break;
    case 0xE000E100u:
        core.nvic_enabled |= v; /* ISER: write 1 to enable */
        break;
    case 0xE000E180u:
        core.nvic_enabled &= ~v; /* ICER: write 1 to disable */
        break;
    default:
        stm_violation("core: write of unmodelled address 0x%08X", (unsigned)addr);
        break;
    }
}

bool stm_can_irq(void)
{
    return (core.nvic_enabled & (1u << 30)) != 0u && bxcan_irq_line();
}

/* ---- the chip ------------------------------------------------------------ */

static void reset_all(bool new_chip)
{
    memset(&rcc, 0, sizeof(rcc));
    rcc.cr = 0x00000083u;     /* HSION, HSIRDY, HSITRIM 16 */
    rcc.ahbenr = 0x00000014u; /* SRAM and flash interface clocks */
    rcc.cr2 = 0x00000080u;    /* HSI14TRIM 16; HSI48 off */
    rcc.acr = 0x00000030u;    /* prefetch on, zero wait states */
    memset(gpio, 0, sizeof(gpio));
    gpio[0].moder = 0x28000000u; /* PA13, PA14: SWD (alternate function) */
    gpio[0].ospeedr = 0x0C000000u;
    gpio[0].pupdr = 0x24000000u;
    unsigned wfi = core.wfi;
    memset(&core, 0, sizeof(core));
    core.wfi = new_chip ? 0u : wfi;
    bxcan_reset();
    flash_reset(new_chip);
    spin_count = 0;
}

/* The 96-bit unique device ID (RM0091 33.1): factory-programmed, read-only. */
static uint32_t uid[3] = {0x00470021u, 0x31385107u, 0x20363650u};

void stm_uid_set(const uint32_t id[3])
{
    uid[0] = id[0];
    uid[1] = id[1];
    uid[2] = id[2];
}

void stm_chip_new(void)
{
    reset_all(true);
    stm_violations_clear();
}

void stm_reset(void)
{
    reset_all(false);
}

/* ---- the bus --------------------------------------------------------------- */

#define IN(a, base, size) ((a) >= (base) && (a) - (base) < (size))

/* Peripheral clock gates (RM0091 6.4.6, 6.4.8): a disabled peripheral
 * ignores writes and reads as 0. */
static bool clocked(uint32_t addr, bool peek)
{
    uint32_t need = 0;
    uint32_t have = 0;
    const char *name = "";
    if (IN(addr, 0x40006400u, 0x400u)) {
        need = CAN_EN;
        have = rcc.apb1enr;
        name = "CAN (RCC_APB1ENR.CANEN)";
    } else if (IN(addr, 0x48000000u, 0x400u)) {
        need = IOPA_EN;
        have = rcc.ahbenr;
        name = "GPIOA (RCC_AHBENR.IOPAEN)";
    } else if (IN(addr, 0x48000400u, 0x400u)) {
        need = IOPB_EN;
        have = rcc.ahbenr;
        name = "GPIOB (RCC_AHBENR.IOPBEN)";
    }
    if ((have & need) != need) {
        if (!peek) {
            stm_violation("access to %s with its clock off, at 0x%08X", name, (unsigned)addr);
        }
        return false;
    }
    return true;
}

static uint32_t read32(uint32_t addr, bool peek)
{
    if (!clocked(addr, peek)) {
        return 0;
    }
    if (IN(addr, 0x40006400u, 0x400u)) {
        return bxcan_read(addr - 0x40006400u, peek);
    }
    if (IN(addr, RCC_BASE, 0x400u)) {
        return rcc_read(addr - RCC_BASE, peek);
    }
    if (addr == 0x40022000u) {
        return rcc.acr | ((rcc.acr & 0x10u) << 1); /* PRFTBS follows PRFTBE */
    }
    if (IN(addr, 0x40022000u, 0x400u)) {
        return flash_reg_read(addr - 0x40022000u, peek);
    }
    if (IN(addr, 0x48000000u, 0x800u)) {
        return gpio_read(&gpio[(addr >> 10) & 1u], addr & 0x3FFu, peek);
    }
    if (IN(addr, 0xE000E000u, 0x1000u)) {
        return core_read(addr, peek);
    }
    if (IN(addr, STM_FLASH_BASE, STM_FLASH_SIZE)) {
        return peek ? 0u : flash_mem_read(addr - STM_FLASH_BASE, 4);
    }
    if (IN(addr, 0x1FFFF7ACu, 12u)) {
        return uid[(addr - 0x1FFFF7ACu) / 4u]; /* the system memory's ID words */
    }
    if (!peek) {
        stm_violation("read of unmodelled address 0x%08X", (unsigned)addr);
    }
    return 0;
}

uint32_t stm_peek32(uint32_t addr)
{
    return read32(addr, true);
}

uint32_t stm_rd32(uint32_t addr)
{
    if ((addr & 3u) != 0u) {
        stm_violation("unaligned word read at 0x%08X", (unsigned)addr);
    }
    uint32_t v = read32(addr, false);
    spin_check(addr, v);
    return v;
}

void stm_wr32(uint32_t addr, uint32_t v)
{
    stm_progress();
    if ((addr & 3u) != 0u) {
        stm_violation("unaligned word write at 0x%08X", (unsigned)addr);
    }
    if (!clocked(addr, false)) {
        return;
    }
    if (IN(addr, 0x40006400u, 0x400u)) {
        bxcan_write(addr - 0x40006400u, v);
    } else if (IN(addr, RCC_BASE, 0x400u)) {
        rcc_write(addr - RCC_BASE, v);
    } else if (addr == 0x40022000u) {
        rcc.acr = v & 0x17u;
        check_wait_states();
    } else if (IN(addr, 0x40022000u, 0x400u)) {
        flash_reg_write(addr - 0x40022000u, v);
    } else if (IN(addr, 0x48000000u, 0x800u)) {
        gpio_write(&gpio[(addr >> 10) & 1u], addr & 0x3FFu, v);
    } else if (IN(addr, 0xE000E000u, 0x1000u)) {
        core_write(addr, v);
    } else if (IN(addr, STM_FLASH_BASE, STM_FLASH_SIZE)) {
        flash_mem_write(addr - STM_FLASH_BASE, v, 4);
    } else {
        stm_violation("write of unmodelled address 0x%08X", (unsigned)addr);
    }
}

/* Half-word and byte accesses: only the flash memory is accessed so. */
uint16_t stm_rd16(uint32_t addr)
{
    if (!IN(addr, STM_FLASH_BASE, STM_FLASH_SIZE) || (addr & 1u) != 0u) {
        stm_violation("half-word read at 0x%08X: not (aligned) flash memory", (unsigned)addr);
        return 0;
    }
    uint16_t v = (uint16_t)flash_mem_read(addr - STM_FLASH_BASE, 2);
    spin_check(addr, v);
    return v;
}

void stm_wr16(uint32_t addr, uint16_t v)
{
    stm_progress();
    if (!IN(addr, STM_FLASH_BASE, STM_FLASH_SIZE)) {
        stm_violation("half-word write at 0x%08X: not flash memory", (unsigned)addr);
        return;
    }
    flash_mem_write(addr - STM_FLASH_BASE, v, 2);
}

uint8_t stm_rd8(uint32_t addr)
{
    if (!IN(addr, STM_FLASH_BASE, STM_FLASH_SIZE)) {
        stm_violation("byte read at 0x%08X: not flash memory", (unsigned)addr);
        return 0;
    }
    return (uint8_t)flash_mem_read(addr - STM_FLASH_BASE, 1);
}
