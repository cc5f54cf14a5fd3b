/*
 * cfi_flash.c - see cfi_flash.h.
 *
 * The command set (Intel/Sharp, CFI ID 0x0001), as QEMU's pflash_cfi01
 * implements it and as the chips' data sheets describe it:
 *   0xFF read array, 0x98 CFI query, 0x70 read status, 0x50 clear status,
 *   0x20 + 0xD0 block erase (setup, confirm), 0x40 + data word program.
 * Status register bits: 7 ready (write state machine idle), 5 erase
 * error, 4 program error, 3 programming voltage low, 1 block locked; they
 * stay set until a clear status command.
 * After erase or program the flash answers reads with its status until it
 * is put back into read-array mode, which every function here does before
 * it returns.
 */
#include "cfi_flash.h"

/* A command to both x16 chips: the byte in each half-word. */
/* clang-format off */
#define CMD(c) ((uint32_t)(c) * 0x00010001u)
/* clang-format on */
#define CMD_READ_ARRAY CMD(0xFFu)
#define CMD_QUERY CMD(0x98u)
#define CMD_CLEAR_STATUS CMD(0x50u)
#define CMD_ERASE_SETUP CMD(0x20u)
#define CMD_ERASE_CONFIRM CMD(0xD0u)
#define CMD_PROGRAM CMD(0x40u)

#define SR_READY CMD(0x80u)
#define SR_ERRORS CMD(0x3Au) /* erase, program, voltage, locked */

/* Status polls before giving up: a real chip erases a block in about a
 * second at worst, far less than this many bus reads; QEMU's model is done
 * at once. A flash that never gets ready is a hardware fault, not a hang. */
#define POLL_MAX 0x01000000u

static volatile uint32_t *word_at(uint32_t addr)
{
    return (volatile uint32_t *)(uintptr_t)(addr & ~3u);
}

/* Wait for both chips to be ready, put the bank back into read-array mode
 * and say whether the operation succeeded. */
static bool finish(volatile uint32_t *w)
{
    uint32_t sr = 0;
    for (uint32_t n = 0; n < POLL_MAX && (sr & SR_READY) != SR_READY; n++) {
        sr = *w;
    }
    *w = CMD_READ_ARRAY;
    return (sr & SR_READY) == SR_READY && (sr & SR_ERRORS) == 0u;
}

bool cfi_flash_probe(cfi_flash_t *f, uint32_t base)
{
    volatile uint32_t *w = word_at(base);
    f->base = base;
    f->size = 0;
    f->block_size = 0;
    *w = CMD_QUERY;
    /* In query mode each 32-bit word at index i holds byte i of the CFI
     * table in both halves (one per chip). */
    uint8_t q[0x31];
    bool ok = true;
    for (unsigned i = 0x10u; i < sizeof(q); i++) {
        uint32_t v = w[i];
        ok = ok && (v >> 16) == (v & 0xFFFFu) && (v & 0xFF00u) == 0u;
        q[i] = (uint8_t)v;
    }
    *w = CMD_READ_ARRAY;
    ok = ok && q[0x10] == 'Q' && q[0x11] == 'R' && q[0x12] == 'Y';
    ok = ok && q[0x13] == 0x01u && q[0x14] == 0x00u; /* Intel/Sharp command set */
    ok = ok && q[0x2C] == 1u;                        /* one uniform block region */
    /* Byte 0x27: log2 of one chip's size; bytes 0x2F-0x30: one chip's
     * block size / 256. The bank is twice each (two chips side by side). */
    uint32_t chip_block = ((uint32_t)q[0x2F] | (uint32_t)q[0x30] << 8) * 256u;
    ok = ok && q[0x27] < 31u && chip_block != 0u && chip_block < (1u << q[0x27]);
    if (ok) {
        f->size = 2u << q[0x27];
        f->block_size = 2u * chip_block;
    }
    return ok;
}

/* Erase the block holding addr: clear status, erase setup + confirm, wait.
 * QEMU erases at the setup command, and writes the block to its file. */
static bool cfi_erase(void *ctx, uint32_t addr)
{
    const cfi_flash_t *f = ctx;
    volatile uint32_t *w = word_at(addr & ~(f->block_size - 1u));
    *w = CMD_CLEAR_STATUS;
    *w = CMD_ERASE_SETUP;
    *w = CMD_ERASE_CONFIRM;
    return finish(w);
}

/*
 * Half-word programming on a 32-bit bank of two x16 chips: the half-word
 * belongs to one chip, but a command must reach both (a chip left waiting
 * for its data word would take the next bus write as data). So the whole
 * word is programmed, the other half with the value it already holds.
 * On real NOR flash programming a bit already at its value changes
 * nothing; QEMU's model simply stores the word. Not writing 0xFFFF into
 * the other half matters there: QEMU stores what it is given, so 0xFFFF
 * would undo the other chip's programmed bits (real flash cannot set a bit
 * without an erase; QEMU can). For the same reason a half-word that is not
 * erased is refused, as on the Nucleo: QEMU would overwrite it, a real chip
 * would AND the values.
 */
static bool cfi_program16(void *ctx, uint32_t addr, uint16_t v)
{
    (void)ctx;
    if ((addr & 1u) != 0u) {
        return false;
    }
    volatile uint32_t *w = word_at(addr);
    uint32_t shift = (addr & 2u) * 8u;
    uint32_t old = *w;
    if (((old >> shift) & 0xFFFFu) != 0xFFFFu) {
        return false; /* erase before write */
    }
    if (v == 0xFFFFu) {
        return true; /* programming ones changes nothing */
    }
    uint32_t val = (old & ~(0xFFFFu << shift)) | ((uint32_t)v << shift);
    *w = CMD_CLEAR_STATUS;
    *w = CMD_PROGRAM;
    *w = val;
    return finish(w) && *w == val;
}

/* Plain byte reads: the bank is always left in read-array mode. */
static void cfi_read(void *ctx, uint32_t addr, void *buf, uint32_t len)
{
    (void)ctx;
    const volatile uint8_t *p = (const volatile uint8_t *)(uintptr_t)addr;
    uint8_t *b = buf;
    for (uint32_t i = 0; i < len; i++) {
        b[i] = p[i];
    }
}

const flash_ops_t cfi_flash_ops = {
    .erase = cfi_erase, .program16 = cfi_program16, .read = cfi_read};
