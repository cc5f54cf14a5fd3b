/*
 * stm32f042_parts.h - between the model files of tests/models: the bus
 * dispatch (stm32f042_model.c) hands each access to the peripheral model
 * that owns the address; the peripheral models record violations and ask
 * for the clock state through the dispatcher.
 */
#ifndef STM32F042_PARTS_H
#define STM32F042_PARTS_H

#include "stm32f042_model.h"

/* Records a violation of the manual (printf-style text, printed at once). */
void stm_violation(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Something changed that a poll may be waiting for (restarts the spin count). */
void stm_progress(void);

/* bxCAN: offset from its base 0x40006400. */
void bxcan_reset(void);
uint32_t bxcan_read(uint32_t off, bool peek);
void bxcan_write(uint32_t off, uint32_t v);
bool bxcan_irq_line(void);

/* Flash interface registers: offset from 0x40022000; ACR is the clock
 * model's (wait states), the rest the flash model's. */
void flash_reset(bool new_chip);
uint32_t flash_reg_read(uint32_t off, bool peek);
void flash_reg_write(uint32_t off, uint32_t v);
/* Flash memory: offset from STM_FLASH_BASE; size 1, 2 or 4 bytes. */
uint32_t flash_mem_read(uint32_t off, unsigned size);
void flash_mem_write(uint32_t off, uint32_t v, unsigned size);

#endif /* STM32F042_PARTS_H */
