/*
 * flash_ee.c - see flash_ee.h.
 */
#include "flash_ee.h"

#include "co_store.h"

uint32_t flash_ee_size(const flash_ee_t *fe)
{
    /* A page must hold a whole slot, and slots must start at even
     * addresses (half-word programming): otherwise slots would spill into
     * each other's pages and past the last one. Such a geometry gives no
     * EEPROM at all (every access fails, the store reports a hardware
     * error) rather than one that half works (found by fuzz_flash_ee.c). */
    if (fe->page_size < CO_STORE_SLOT || ((fe->page_size | fe->base) & 1u) != 0u) {
        return 0;
    }
    return fe->pages * CO_STORE_SLOT;
}

/* Offset of logical EEPROM byte addr in its slot; *page receives the
 * slot's page address. By subtraction, not division: a few passes (one per
 * slot) instead of a call into the division helper and its stack, on the
 * deepest call chain of the image (a save from an SDO hook). */
static uint32_t split(const flash_ee_t *fe, uint32_t addr, uint32_t *page)
{
    uint32_t p = fe->base;
    while (addr >= CO_STORE_SLOT) {
        addr -= CO_STORE_SLOT;
        p += fe->page_size;
    }
    *page = p;
    return addr;
}

bool flash_ee_read(const flash_ee_t *fe, uint32_t addr, void *buf, uint32_t len)
{
    uint8_t *b = buf;
    while (len > 0u) {
        /* Slot by slot: each lives in its own page. */
        if (addr >= flash_ee_size(fe)) {
            return false;
        }
        uint32_t page;
        uint32_t off = split(fe, addr, &page);
        uint32_t n = CO_STORE_SLOT - off;
        n = n < len ? n : len;
        fe->ops->read(fe->ctx, page + off, b, n);
        addr += n;
        b += n;
        len -= n;
    }
    return true;
}

/* The slot of the page at page holds only erased bytes. Only the slot's
 * bytes are ever programmed (the rest of its page stays as an erase left
 * it); a cut erase can leave any of them programmed, so all are read. */
static bool blank(const flash_ee_t *fe, uint32_t page)
{
    for (uint32_t i = 0; i < CO_STORE_SLOT; i += 2u) {
        uint16_t v;
        fe->ops->read(fe->ctx, page + i, &v, 2);
        if (v != 0xFFFFu) {
            return false;
        }
    }
    return true;
}

/* Erase the page of the slot at page unless it is blank already. */
static bool clean(const flash_ee_t *fe, uint32_t page)
{
    return blank(fe, page) || fe->ops->erase(fe->ctx, page);
}

/* What a write at addr does before its first byte: an empty write, which
 * cleans the page when addr starts a slot and does nothing anywhere else
 * (no code of its own: the MCU images count every byte). A failure shows
 * at the write. */
void flash_ee_prepare(const flash_ee_t *fe, uint32_t addr)
{
    (void)flash_ee_write(fe, addr, NULL, 0);
}

bool flash_ee_write(const flash_ee_t *fe, uint32_t addr, const void *buf, uint32_t len)
{
    if ((addr & 1u) != 0u || (len & 1u) != 0u || addr >= flash_ee_size(fe)) {
        return false;
    }
    uint32_t page; /* split only after the size check: it walks slot by slot */
    uint32_t off = split(fe, addr, &page);
    if (len > CO_STORE_SLOT - off) {
        return false; /* a write stays in one slot */
    }
    if (off == 0u && !clean(fe, page)) {
        return false; /* a record starts: its page erased first, unless erased ahead */
    }
    /* The write lies in one slot (checked above): its bytes follow each
     * other in the slot's page. */
    const uint8_t *b = buf;
    for (uint32_t i = 0; i < len; i += 2u) {
        uint16_t v = (uint16_t)(b[i] | (uint16_t)(b[i + 1u] << 8));
        if (!fe->ops->program16(fe->ctx, page + off + i, v)) {
            return false;
        }
    }
    return true;
}
