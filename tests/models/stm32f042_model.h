/*
 * stm32f042_model.h - register-level models of the parts of the STM32F042
 * that the Nucleo-F042K6 board (boards/nucleo-f042k6/board.c) drives,
 * written from the reference manual RM0091 for the host unit tests
 * (tests/unit/test_nucleo_drivers.c): the bxCAN controller and the CAN bus
 * around it (bxcan_model.c), the flash interface and the flash memory
 * (flash_model.c), and the clock, GPIO, SysTick and NVIC registers the
 * board touches (stm32f042_model.c).
 *
 * board.c built with STM32F042_MODEL calls stm_rd32()/stm_wr32()/... for
 * every access (stm32f042.h). The models answer as the chip does and
 * record a violation whenever the code does what the manual forbids in
 * that state (writing CAN_BTR outside initialization mode, a filter bank
 * outside filter initialization, FLASH_CR while locked, programming a
 * half-word that is not erased, starting a flash operation while BSY, an
 * access to a peripheral whose clock is off, ...). A test checks that none
 * was recorded (stm_violations_left()); the model self-tests provoke each
 * one on purpose and take it (stm_take_violations()).
 *
 * Time in the models is counted in register reads: a handshake bit (INAK,
 * SLAK, HSI48RDY, SWS, BSY) changes only after the code has polled for it,
 * so code that does not wait is caught. A poll that can never end (the bus
 * held dominant while the code waits for the controller to join it; an
 * interrupt handler that never releases the FIFO) is detected after
 * STM_SPIN_LIMIT reads with nothing written or changed: recorded as a
 * violation, and the code is abandoned when it was started through
 * stm_run(), else the test program stops with the violation printed.
 *
 * Not modelled (the board does not use them): CAN FIFO 1 interrupts beyond
 * their flags, time-triggered mode, the LOW flags of CAN_TSR, silent and
 * loop-back modes, option-byte programming, mass erase beyond the
 * protection check, the flash prefetch buffer's timing.
 */
#ifndef STM32F042_MODEL_H
#define STM32F042_MODEL_H

#include <stdbool.h>
#include <stdint.h>

/* ---- the accessors of stm32f042.h (what board.c calls) ---------------- */

uint32_t stm_rd32(uint32_t addr);
void stm_wr32(uint32_t addr, uint32_t v);
uint16_t stm_rd16(uint32_t addr);
void stm_wr16(uint32_t addr, uint16_t v);
uint8_t stm_rd8(uint32_t addr);
/* The core waits for an interrupt: counted (stm_wfi_count). */
void stm_wfi(void);

/* ---- the chip ---------------------------------------------------------- */

/* A new chip: every register at its reset value, flash memory holding the
 * image (a pattern) in its first 24 KB and erased (0xFF) above. */
void stm_chip_new(void);
/* The chip's 96-bit unique ID (0x1FFFF7AC, three words), kept until set again. */
void stm_uid_set(const uint32_t id[3]);
/* A system reset (or power cycle): every register at its reset value, the
 * flash memory kept, the flash key lockout lifted. */
void stm_reset(void);
/* A register's value as a debugger sees it: no side effect, no check. */
uint32_t stm_peek32(uint32_t addr);
/* The APB clock that feeds bxCAN, from the RCC registers (Hz). */
uint32_t stm_apb_hz(void);
/* WFI instructions executed since stm_chip_new(). */
unsigned stm_wfi_count(void);

/* ---- checks ------------------------------------------------------------ */

/* Register reads with nothing written and nothing changed in the models,
 * after which the code reading is taken for hanging in a poll. */
#define STM_SPIN_LIMIT 100000u

/* Violations recorded and not taken yet. */
unsigned stm_violations_left(void);
/* Prints the violations not taken (to stderr), drops them; returns how many. */
unsigned stm_violations_report(void);
/* Takes (removes) the violations whose text contains what; returns how
 * many. The model self-tests expect exactly the one they provoke. */
unsigned stm_take_violations(const char *what);
/* Drops every recorded violation (a test that failed already said so). */
void stm_violations_clear(void);
/* Runs fn(arg) and returns true; returns false when the model found it
 * polling a register that cannot change any more (a hang, recorded) and
 * abandoned it there. Outside stm_run a hang aborts the test program. */
bool stm_run(void (*fn)(void *arg), void *arg);

/* ---- SysTick ------------------------------------------------------------ */

/* Sets the SysTick current value (the counter counts down from RVR). */
void stm_systick_set(uint32_t cvr);
/* At the nth read of SYST_CVR from now (1: the next one) the counter
 * reloads and the SysTick exception runs handler before the read returns
 * the reloaded value (the exception taken between two instructions). */
void stm_systick_wrap_at_read(unsigned nth, void (*handler)(void));

/* ---- GPIO --------------------------------------------------------------- */

/* The output data register of port 'A' or 'B'. */
uint32_t stm_gpio_odr(char port);

/* ---- bxCAN and the bus -------------------------------------------------- */

typedef struct stm_can_frame {
    uint32_t id; /* 11 bits, or 29 with ide */
    bool ide;
    bool rtr;
    uint8_t dlc; /* 0..15 as on the bus */
    uint8_t data[8];
} stm_can_frame_t;

typedef enum { STM_CAN_SLEEP, STM_CAN_INIT, STM_CAN_NORMAL } stm_can_mode_t;

/* Where stm_can_bus_send() put a frame. */
#define STM_CAN_FIFO0 0
#define STM_CAN_FIFO1 1
#define STM_CAN_FILTERED (-1) /* acknowledged, no active filter took it */
#define STM_CAN_OFF_BUS (-2)  /* the controller does not take part in bus traffic */

/* Another node sends f, after the 11 recessive bits that end the frame
 * before it (they let a controller that left initialization join, and
 * count for a bus-off recovery): the controller receives it when it is in
 * normal mode, not bus-off and its filters are active (FINIT clear); a
 * filter match stores it in that FIFO (overrun rules of RFLM). */
int stm_can_bus_send(const stm_can_frame_t *f);
/* The bus takes the next frame the controller transmits (the transmit
 * priority of TXFP), after the same 11 recessive bits, and acknowledges
 * it; false when nothing is pending or the controller is not on the bus. */
bool stm_can_bus_take(stm_can_frame_t *f);
/* The next transmission fails: a bit error (TEC + 8), or an acknowledgement
 * error (TEC + 8, except while error passive: ISO 11898-1 fault
 * confinement, no dominant bit during the passive error flag). The
 * mailbox stays pending (automatic retransmission). */
void stm_can_bus_tx_error(bool ack_error);
/* n receive errors (REC + 1 each). */
void stm_can_bus_rx_error(unsigned n);
/* n periods of 11 consecutive recessive bits on the bus (bus-off recovery
 * counts 128 of them). */
void stm_can_bus_idle(unsigned n);
/* The bus held dominant (a fault): no 11 recessive bits ever. */
void stm_can_bus_stuck_dominant(bool on);
/* The controller's interrupt request, enabled in the NVIC (CEC_CAN, IRQ 30). */
bool stm_can_irq(void);
stm_can_mode_t stm_can_mode(void);
/* Transmit and receive error counters (TEC has 9 bits). */
unsigned stm_can_tec(void);
unsigned stm_can_rec(void);
/* Messages pending in receive FIFO 0 (FMP0) and transmit mailboxes pending. */
unsigned stm_can_fmp0(void);
unsigned stm_can_tx_pending(void);

/* ---- flash -------------------------------------------------------------- */

#define STM_FLASH_BASE 0x08000000u
#define STM_FLASH_SIZE 0x8000u /* 32 KB: 32 pages of 1 KB */
#define STM_FLASH_PAGE 1024u

/* The flash memory's bytes (offset from STM_FLASH_BASE), for checks. */
const uint8_t *stm_flash_mem(void);
/* Write protection of 4-KB sector s (FLASH_WRPR bit s cleared). */
void stm_flash_write_protect(unsigned sector, bool on);
/* The half-word at addr is worn out (beyond the datasheet's endurance):
 * programs of it end normally (EOP) but leave its bits as they were. */
void stm_flash_wear_out(uint32_t addr);
/* FLASH_SR reads an erase or a program keeps BSY set (default 3). */
void stm_flash_busy_reads(unsigned n);
/* Page erases and half-word programs performed since stm_chip_new(). */
unsigned stm_flash_erases(void);
unsigned stm_flash_programs(void);
/* Whether the image part (first 24 KB) still holds the image's pattern. */
bool stm_flash_image_intact(void);

#endif /* STM32F042_MODEL_H */
