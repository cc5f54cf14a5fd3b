/*
 * flash_model.c - the STM32F042's embedded flash memory (32 pages of 1 KB)
 * and its program/erase interface (RM0091 section 3, "Embedded flash
 * memory"), at register level, for the host tests (stm32f042_model.h).
 *
 * As the manual describes it:
 * - FLASH_CR is locked after reset (LOCK). Writing KEY1 then KEY2 to
 *   FLASH_KEYR unlocks it; any other sequence is a bus error (HardFault)
 *   and keeps FLASH_CR locked until the next reset. A write to FLASH_CR
 *   while locked is ignored (a violation here); writing LOCK locks it.
 *   A key written while unlocked is taken for a wrong sequence.
 * - Page erase: PER set, the page's address in FLASH_AR, STRT set: BSY
 *   while it runs (here: a few reads of FLASH_SR), then the page reads
 *   0xFF and EOP is set.
 * - Programming: PG set, then one half-word write to the flash memory:
 *   BSY, then EOP. The interface reads the location first: a half-word
 *   that is not 0xFFFF is left as it is and PGERR is set (a violation
 *   here), except that writing 0x0000 is always accepted (the manual's
 *   one exception). A write to the flash memory without PG, or not by a
 *   half-word, is a bus error.
 * - A page in a write-protected 4-KB sector (FLASH_WRPR) is neither erased
 *   nor programmed: WRPRTERR.
 * - EOP, PGERR and WRPRTERR are cleared by writing 1; BSY is read-only.
 * - Nothing starts while BSY is set: the procedures wait for BSY to clear
 *   before they touch FLASH_CR or FLASH_AR again or start the next
 *   operation (a violation here); FLASH_AR is write-blocked while BSY.
 *   A read of the flash memory during an operation stalls the bus until it
 *   ends (here: the read completes the operation first). BSY shows at
 *   once after STRT (the manual asks for a cycle before the first check,
 *   which the Cortex-M0 always leaves: its store ends before the next load).
 */
#include <string.h>

#include "stm32f042_parts.h"

#define KEY1 0x45670123u
#define KEY2 0xCDEF89ABu

#define SR_BSY (1u << 0)
#define SR_PGERR (1u << 2)
#define SR_WRPRTERR (1u << 4)
#define SR_EOP (1u << 5)

#define CR_PG (1u << 0)
#define CR_PER (1u << 1)
#define CR_MER (1u << 2)
#define CR_STRT (1u << 6)
#define CR_LOCK (1u << 7)
#define CR_WRITABLE 0x00003677u /* OBL_LAUNCH, EOPIE, ERRIE, OPTWRE, STRT..PG but LOCK */

#define IMAGE_SIZE (24u * 1024u) /* the image's part; the EEPROM emulation above */

typedef enum { OP_NONE, OP_ERASE, OP_PROGRAM } op_t;

static struct {
    uint8_t mem[STM_FLASH_SIZE];
    uint32_t cr, sr, ar;
    uint32_t wrpr;     /* bit s clear: sector s protected */
    unsigned key_step; /* 1: KEY1 seen */
    bool locked_out;   /* a wrong key sequence: until reset */
    op_t op;
    uint32_t op_addr;
    uint16_t op_value;
    unsigned busy_left; /* FLASH_SR reads until the operation ends */
    unsigned busy_reads;
    unsigned erases, programs;
    uint32_t worn; /* offset + 1 of a worn-out half-word; 0: none */
} fl;

static uint8_t image_byte(uint32_t off)
{
    return (uint8_t)(off * 131u + (off >> 8) + 7u);
}

void flash_reset(bool new_chip)
{
    if (new_chip) {
        for (uint32_t i = 0; i < IMAGE_SIZE; i++) {
            fl.mem[i] = image_byte(i);
        }
        memset(&fl.mem[IMAGE_SIZE], 0xFF, STM_FLASH_SIZE - IMAGE_SIZE);
        fl.wrpr = 0xFFFFFFFFu;
        fl.busy_reads = 3u;
        fl.erases = 0;
        fl.programs = 0;
        fl.worn = 0;
    }
    /* A reset in the middle of an operation: the memory stays as it is. */
    fl.cr = CR_LOCK;
    fl.sr = 0;
    fl.ar = 0;
    fl.key_step = 0;
    fl.locked_out = false;
    fl.op = OP_NONE;
    fl.busy_left = 0;
}

const uint8_t *stm_flash_mem(void)
{
    return fl.mem;
}

void stm_flash_write_protect(unsigned sector, bool on)
{
    if (on) {
        fl.wrpr &= ~(1u << sector);
    } else {
        fl.wrpr |= 1u << sector;
    }
}

void stm_flash_wear_out(uint32_t addr)
{
    fl.worn = addr - STM_FLASH_BASE + 1u;
}

void stm_flash_busy_reads(unsigned n)
{
    fl.busy_reads = n == 0u ? 1u : n;
}

unsigned stm_flash_erases(void)
{
    return fl.erases;
}

unsigned stm_flash_programs(void)
{
    return fl.programs;
}

bool stm_flash_image_intact(void)
{
    for (uint32_t i = 0; i < IMAGE_SIZE; i++) {
        if (fl.mem[i] != image_byte(i)) {
            return false;
        }
    }
    return true;
}

static bool write_protected(uint32_t off)
{
    return ((fl.wrpr >> (off / 4096u)) & 1u) == 0u;
}

/* The running operation ends. */
static void finish(void)
{
    if (fl.op == OP_ERASE) {
        memset(&fl.mem[fl.op_addr], 0xFF, STM_FLASH_PAGE);
        fl.erases++;
    } else if (fl.op == OP_PROGRAM && fl.op_addr + 1u == fl.worn) {
        fl.programs++; /* a worn-out cell: the bits do not move */
    } else if (fl.op == OP_PROGRAM) {
        fl.mem[fl.op_addr] &= (uint8_t)fl.op_value;
        fl.mem[fl.op_addr + 1u] &= (uint8_t)(fl.op_value >> 8);
        fl.programs++;
    }
    if (fl.op != OP_NONE) {
        fl.sr = (fl.sr & ~SR_BSY) | SR_EOP;
        fl.op = OP_NONE;
        stm_progress();
    }
}

static void start(op_t op, uint32_t addr, uint16_t v)
{
    fl.op = op;
    fl.op_addr = addr;
    fl.op_value = v;
    fl.busy_left = fl.busy_reads;
    fl.sr |= SR_BSY;
}

uint32_t flash_reg_read(uint32_t off, bool peek)
{
    switch (off) {
    case 0x0Cu:
        if (!peek && fl.op != OP_NONE && --fl.busy_left == 0u) {
            finish();
        }
        return fl.sr;
    case 0x10u:
        return fl.cr;
    case 0x1Cu:
        return 0x03FFFF02u; /* FLASH_OBR: level 0 read protection, default user options */
    case 0x20u:
        return fl.wrpr;
    default:
        if (!peek) {
            stm_violation("FLASH: read of write-only or unmodelled register at offset 0x%02X",
                          (unsigned)off);
        }
        return 0;
    }
}

static void write_cr(uint32_t v)
{
    if ((fl.cr & CR_LOCK) != 0u) {
        stm_violation("FLASH_CR written while locked (0x%08X)", (unsigned)v);
        return;
    }
    if ((fl.sr & SR_BSY) != 0u) {
        stm_violation("FLASH_CR written while BSY (0x%08X): the procedure waits for BSY to clear",
                      (unsigned)v);
    }
    if ((v & CR_PG) != 0u && (v & (CR_PER | CR_MER)) != 0u) {
        stm_violation("FLASH_CR: programming and erase selected together (0x%08X)", (unsigned)v);
    }
    fl.cr = (v & CR_WRITABLE & ~CR_STRT) | (v & CR_LOCK);
    if ((v & CR_STRT) == 0u) {
        return;
    }
    if ((fl.sr & SR_BSY) != 0u) {
        stm_violation("FLASH_CR: STRT while an operation runs (BSY)");
        return;
    }
    if ((v & CR_PER) != 0u) {
        if (fl.ar < STM_FLASH_BASE || fl.ar - STM_FLASH_BASE >= STM_FLASH_SIZE) {
            stm_violation("FLASH: page erase of 0x%08X, outside the flash memory", (unsigned)fl.ar);
            return;
        }
        uint32_t page = (fl.ar - STM_FLASH_BASE) & ~(STM_FLASH_PAGE - 1u);
        if (write_protected(page)) {
            fl.sr |= SR_WRPRTERR;
            return;
        }
        start(OP_ERASE, page, 0);
    } else if ((v & CR_MER) != 0u) {
        stm_violation("FLASH: mass erase (it would erase the image itself)");
    } else {
        stm_violation("FLASH_CR: STRT without PER or MER");
    }
}

void flash_reg_write(uint32_t off, uint32_t v)
{
    switch (off) {
    case 0x04u:
        if (fl.locked_out) {
            stm_violation("FLASH_KEYR written after a wrong key sequence: bus error (HardFault), "
                          "locked until reset");
            return;
        }
        if ((fl.cr & CR_LOCK) == 0u) {
            stm_violation(
                "FLASH_KEYR written while unlocked: a wrong sequence, bus error (HardFault)");
            fl.locked_out = true;
            fl.cr |= CR_LOCK;
            return;
        }
        if (fl.key_step == 0u && v == KEY1) {
            fl.key_step = 1;
        } else if (fl.key_step == 1u && v == KEY2) {
            fl.key_step = 0;
            fl.cr &= ~CR_LOCK;
        } else {
            stm_violation("FLASH_KEYR: wrong key sequence (0x%08X): bus error (HardFault), locked "
                          "until reset",
                          (unsigned)v);
            fl.key_step = 0;
            fl.locked_out = true;
        }
        break;
    case 0x0Cu:
        fl.sr &= ~(v & (SR_EOP | SR_PGERR | SR_WRPRTERR)); /* write 1 to clear; BSY read-only */
        break;
    case 0x10u:
        write_cr(v);
        break;
    case 0x14u:
        if ((fl.sr & SR_BSY) != 0u) {
            stm_violation("FLASH_AR written while BSY (write-blocked)");
            return;
        }
        fl.ar = v;
        break;
    default:
        stm_violation("FLASH: write of read-only or unmodelled register at offset 0x%02X",
                      (unsigned)off);
        break;
    }
}

uint32_t flash_mem_read(uint32_t off, unsigned size)
{
    if (fl.op != OP_NONE) {
        finish(); /* the bus stalls until the operation ends */
    }
    if ((off & (size - 1u)) != 0u) {
        stm_violation("FLASH: unaligned %u-byte read at offset 0x%05X", size, (unsigned)off);
        return 0;
    }
    uint32_t v = 0;
    for (unsigned i = 0; i < size; i++) {
        v |= (uint32_t)fl.mem[off + i] << (8u * i);
    }
    return v;
}

void flash_mem_write(uint32_t off, uint32_t v, unsigned size)
{
    if ((fl.cr & CR_PG) == 0u) {
        stm_violation("FLASH: write to flash memory at offset 0x%05X without PG: bus error",
                      (unsigned)off);
        return;
    }
    if (size != 2u || (off & 1u) != 0u) {
        stm_violation("FLASH: %u-byte write at offset 0x%05X: programming is by aligned half-words",
                      size, (unsigned)off);
        return;
    }
    if ((fl.sr & SR_BSY) != 0u) {
        stm_violation("FLASH: programming started while BSY");
        return;
    }
    if (write_protected(off)) {
        fl.sr |= SR_WRPRTERR;
        return;
    }
    uint16_t now = (uint16_t)(fl.mem[off] | (fl.mem[off + 1u] << 8));
    if (now != 0xFFFFu && v != 0u) {
        stm_violation("FLASH: programming 0x%04X over a half-word that is not erased (0x%04X) at "
                      "offset 0x%05X",
                      (unsigned)v, now, (unsigned)off);
        fl.sr |= SR_PGERR;
        return;
    }
    start(OP_PROGRAM, off, (uint16_t)v);
}
