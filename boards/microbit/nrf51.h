/*
 * nrf51.h - the few nRF51822 registers this board uses (nRF51 Series
 * Reference Manual v3.0: CLOCK, UART, TIMER, NVMC), as plain addresses: no
 * vendor SDK. A peripheral's interrupt number is bits 12..16 of its base.
 */
#ifndef NRF51_H
#define NRF51_H

#include <stdint.h>

#define REG(addr) (*(volatile uint32_t *)(addr))

/* Factory information: the 64-bit device identifier. */
#define FICR_DEVICEID0 0x10000060u
#define FICR_DEVICEID1 0x10000064u

/* Tasks are started by writing 1; events read 1 when they occurred and
 * are cleared by writing 0 (their interrupt line stays up until then). */

/* CLOCK */
#define CLOCK_BASE 0x40000000u
#define CLOCK_TASKS_HFCLKSTART REG(CLOCK_BASE + 0x000u)
#define CLOCK_EVENTS_HFCLKSTARTED REG(CLOCK_BASE + 0x100u)

/* UART0 */
#define UART_BASE 0x40002000u
#define UART_TASKS_STARTRX REG(UART_BASE + 0x000u)
#define UART_TASKS_STARTTX REG(UART_BASE + 0x008u)
#define UART_EVENTS_RXDRDY REG(UART_BASE + 0x108u)
#define UART_EVENTS_TXDRDY REG(UART_BASE + 0x11Cu)
#define UART_INTENSET REG(UART_BASE + 0x304u)
#define UART_INTENCLR REG(UART_BASE + 0x308u)
#define UART_ENABLE REG(UART_BASE + 0x500u)
#define UART_PSELTXD REG(UART_BASE + 0x50Cu)
#define UART_PSELRXD REG(UART_BASE + 0x514u)
#define UART_RXD REG(UART_BASE + 0x518u)
#define UART_TXD REG(UART_BASE + 0x51Cu)
#define UART_BAUDRATE REG(UART_BASE + 0x524u)
#define UART_INT_RXDRDY (1u << 2)
#define UART_ENABLE_ON 4u
#define UART_BAUD_115200 0x01D7E000u
#define UART_IRQ 2u

/* TIMER0 */
#define TIMER0_BASE 0x40008000u
#define TIMER0_TASKS_START REG(TIMER0_BASE + 0x000u)
#define TIMER0_TASKS_CLEAR REG(TIMER0_BASE + 0x00Cu)
#define TIMER0_TASKS_CAPTURE(n) REG(TIMER0_BASE + 0x040u + 4u * (n))
#define TIMER0_EVENTS_COMPARE(n) REG(TIMER0_BASE + 0x140u + 4u * (n))
#define TIMER0_INTENSET REG(TIMER0_BASE + 0x304u)
#define TIMER0_MODE REG(TIMER0_BASE + 0x504u)
#define TIMER0_BITMODE REG(TIMER0_BASE + 0x508u)
#define TIMER0_PRESCALER REG(TIMER0_BASE + 0x510u)
#define TIMER0_CC(n) REG(TIMER0_BASE + 0x540u + 4u * (n))
#define TIMER_INT_COMPARE(n) (1u << (16u + (n)))
#define TIMER_BITMODE_32 3u
#define TIMER0_IRQ 8u

/* NVMC: CONFIG selects what writes to flash do; READY is 1 when idle. */
#define NVMC_BASE 0x4001E000u
#define NVMC_READY REG(NVMC_BASE + 0x400u)
#define NVMC_CONFIG REG(NVMC_BASE + 0x504u)
#define NVMC_ERASEPAGE REG(NVMC_BASE + 0x508u)
#define NVMC_CONFIG_REN 0u
#define NVMC_CONFIG_WEN 1u
#define NVMC_CONFIG_EEN 2u
#define NRF51_PAGE_SIZE 1024u

/* Cortex-M0 core */
#define NVIC_ISER REG(0xE000E100u)
#define SCB_AIRCR REG(0xE000ED0Cu)

#endif /* NRF51_H */
