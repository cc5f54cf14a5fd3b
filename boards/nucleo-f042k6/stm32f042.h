/*
 * stm32f042.h - the few STM32F042 registers this board uses (RM0091), as
 * plain addresses: no vendor HAL.
 *
 * Every access goes through the accessors below: RD32/WR32 for a
 * register, RD16/WR16/RD8 for flash memory, WFI() for the sleep. On the
 * target they are plain volatile accesses and the instruction, so the
 * image is the same code as with direct dereferences (tools/footprint
 * measures it). The host tests build board.c with STM32F042_MODEL defined:
 * then each access is a call into the register-level models of
 * tests/models (stm32f042_model.h), which check it against the manual.
 */
#ifndef STM32F042_H
#define STM32F042_H

#include <stdint.h>

#ifdef STM32F042_MODEL
#include "stm32f042_model.h" /* host tests: stm_rd32() and friends */
#define RD32(addr) stm_rd32(addr)
#define WR32(addr, v) stm_wr32((addr), (v))
#define RD16(addr) stm_rd16(addr)
#define WR16(addr, v) stm_wr16((addr), (v))
#define RD8(addr) stm_rd8(addr)
#define WFI() stm_wfi()
#else
#define RD32(addr) (*(volatile uint32_t *)(addr))
#define WR32(addr, v) (*(volatile uint32_t *)(addr) = (v))
#define RD16(addr) (*(volatile uint16_t *)(addr))
#define WR16(addr, v) (*(volatile uint16_t *)(addr) = (v))
#define RD8(addr) (*(volatile uint8_t *)(addr))
#define WFI() __asm__ volatile("wfi")
#endif

/* RCC */
/* Unique device ID, 96 bits (RM0091 33.1). */
#define UID_BASE 0x1FFFF7ACu

#define RCC_BASE 0x40021000u
#define RCC_CFGR (RCC_BASE + 0x04u)
#define RCC_AHBENR (RCC_BASE + 0x14u)
#define RCC_APB1ENR (RCC_BASE + 0x1Cu)
#define RCC_CR2 (RCC_BASE + 0x34u)
#define RCC_CR2_HSI48ON (1u << 16)
#define RCC_CR2_HSI48RDY (1u << 17)
#define RCC_CFGR_SW_HSI48 3u
#define RCC_AHBENR_IOPA (1u << 17)
#define RCC_AHBENR_IOPB (1u << 18)
#define RCC_APB1ENR_CAN (1u << 25)

/* FLASH */
#define FLASH_BASE_R 0x40022000u
#define FLASH_ACR (FLASH_BASE_R + 0x00u)
#define FLASH_KEYR (FLASH_BASE_R + 0x04u)
#define FLASH_SR (FLASH_BASE_R + 0x0Cu)
#define FLASH_CR (FLASH_BASE_R + 0x10u)
#define FLASH_AR (FLASH_BASE_R + 0x14u)
#define FLASH_SR_BSY (1u << 0)
#define FLASH_SR_PGERR (1u << 2)
#define FLASH_SR_WRPRTERR (1u << 4)
#define FLASH_SR_EOP (1u << 5)
#define FLASH_CR_PG (1u << 0)
#define FLASH_CR_PER (1u << 1)
#define FLASH_CR_STRT (1u << 6)
#define FLASH_CR_LOCK (1u << 7)

/* GPIO */
#define GPIOA_BASE 0x48000000u
#define GPIOB_BASE 0x48000400u
#define GPIO_MODER(b) ((b) + 0x00u)
#define GPIO_BSRR(b) ((b) + 0x18u)
#define GPIO_AFRH(b) ((b) + 0x24u)

/* bxCAN */
#define CAN_BASE 0x40006400u
#define CAN_MCR (CAN_BASE + 0x000u)
#define CAN_MSR (CAN_BASE + 0x004u)
#define CAN_TSR (CAN_BASE + 0x008u)
#define CAN_RF0R (CAN_BASE + 0x00Cu)
#define CAN_IER (CAN_BASE + 0x014u)
#define CAN_ESR (CAN_BASE + 0x018u)
#define CAN_BTR (CAN_BASE + 0x01Cu)
#define CAN_TIR(n) (CAN_BASE + 0x180u + 0x10u * (n))
#define CAN_TDTR(n) (CAN_BASE + 0x184u + 0x10u * (n))
#define CAN_TDLR(n) (CAN_BASE + 0x188u + 0x10u * (n))
#define CAN_TDHR(n) (CAN_BASE + 0x18Cu + 0x10u * (n))
#define CAN_RI0R (CAN_BASE + 0x1B0u)
#define CAN_RDT0R (CAN_BASE + 0x1B4u)
#define CAN_RDL0R (CAN_BASE + 0x1B8u)
#define CAN_RDH0R (CAN_BASE + 0x1BCu)
#define CAN_FMR (CAN_BASE + 0x200u)
#define CAN_FM1R (CAN_BASE + 0x204u)
#define CAN_FS1R (CAN_BASE + 0x20Cu)
#define CAN_FFA1R (CAN_BASE + 0x214u)
#define CAN_FA1R (CAN_BASE + 0x21Cu)
#define CAN_F0R1 (CAN_BASE + 0x240u)
#define CAN_F0R2 (CAN_BASE + 0x244u)
#define CAN_MCR_INRQ (1u << 0)
#define CAN_MCR_SLEEP (1u << 1)
#define CAN_MCR_TXFP (1u << 2)
#define CAN_MCR_ABOM (1u << 6)
#define CAN_MSR_INAK (1u << 0)
#define CAN_TSR_TME0 (1u << 26)
#define CAN_RF0R_FMP0 3u
#define CAN_RF0R_FOVR0 (1u << 4)
#define CAN_RF0R_RFOM0 (1u << 5)
#define CAN_IER_FMPIE0 (1u << 1)
#define CAN_ESR_EWGF (1u << 0)
#define CAN_ESR_EPVF (1u << 1)
#define CAN_ESR_BOFF (1u << 2)
#define CAN_RI0R_IDE (1u << 2)
#define CAN_RI0R_RTR (1u << 1)
#define CAN_TIR_TXRQ (1u << 0)
#define CAN_TIR_RTR (1u << 1)
#define CAN_IRQ 30u

/* Cortex-M0 core */
#define SYST_CSR 0xE000E010u
#define SYST_RVR 0xE000E014u
#define SYST_CVR 0xE000E018u
#define NVIC_ISER 0xE000E100u
#define SCB_AIRCR 0xE000ED0Cu
#define SCB_AIRCR_SYSRESETREQ 0x05FA0004u /* the key, and a system reset */

#define SYSCLK_HZ 48000000u

#endif /* STM32F042_H */
