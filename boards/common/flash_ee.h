/*
 * flash_ee.h - EEPROM emulation on internal flash, for co_port_nvm_*.
 *
 * Each parameter-store slot (CO_STORE_SLOT bytes of the node's NVM) lives
 * in a flash page of its own. The store always writes a record from the
 * start of a slot (header, data, CRC, in order), and only into the slot
 * that does not hold the newest record; so a write at a slot's offset 0
 * erases that page first unless the slot is blank, then half-words are
 * programmed. The store offers that slot ahead, when no SDO answer is due
 * (co_port_nvm_prepare -> flash_ee_prepare), so that a save's answer waits
 * for programming only, never for an erase (20-40 ms on an STM32F0). A power cut at
 * any step leaves the other slot's complete record, which the store finds
 * (tests/unit/test_flash_ee.c cuts at every step). Writes must be even in
 * address and length (the record layout is), and never program a half-word
 * twice (the driver refuses: erase-before-write). Wear: one erase per save
 * per slot; the store counts saves against the product's limit.
 */
#ifndef FLASH_EE_H
#define FLASH_EE_H

#include <stdbool.h>
#include <stdint.h>

/* The flash driver a board provides (host tests: a simulated flash). */
typedef struct flash_ops {
    bool (*erase)(void *ctx, uint32_t page_addr);            /* one page */
    bool (*program16)(void *ctx, uint32_t addr, uint16_t v); /* an erased half-word */
    void (*read)(void *ctx, uint32_t addr, void *buf, uint32_t len);
} flash_ops_t;

typedef struct flash_ee {
    const flash_ops_t *ops;
    void *ctx;
    uint32_t base;      /* address of the first page */
    uint32_t page_size; /* bytes */
    uint32_t pages;     /* pages available: one per slot */
} flash_ee_t;

/* Bytes of emulated EEPROM (pages x CO_STORE_SLOT); 0 when a page cannot
 * hold a slot (page_size below CO_STORE_SLOT or odd) or base is odd. */
uint32_t flash_ee_size(const flash_ee_t *fe);
bool flash_ee_read(const flash_ee_t *fe, uint32_t addr, void *buf, uint32_t len);
bool flash_ee_write(const flash_ee_t *fe, uint32_t addr, const void *buf, uint32_t len);
/* Erase the page of the slot starting at addr unless it is blank (what a
 * write there would do first); any other addr is ignored. */
void flash_ee_prepare(const flash_ee_t *fe, uint32_t addr);

#endif /* FLASH_EE_H */
