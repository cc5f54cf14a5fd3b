/*
 * startup.c - vector table and reset for the nRF51822 (Cortex-M0): copy
 * .data, clear .bss, then main(). The same steps as the Nucleo's
 * start-up; only the vector table differs (the chip's interrupt numbers).
 * Unused interrupts stop in default_handler; a hard fault too (a debugger
 * shows where).
 */
#include <stdint.h>

#include "nrf51.h"

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
int main(void);
void reset_handler(void);
void default_handler(void);
void uart0_handler(void);
void timer0_handler(void);

void reset_handler(void)
{
    uint32_t *src = &_sidata;
    for (uint32_t *dst = &_sdata; dst < &_edata;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = &_sbss; dst < &_ebss;) {
        *dst++ = 0;
    }
    (void)main();
    for (;;) {
    }
}

void default_handler(void)
{
    for (;;) {
    }
}

typedef void (*vector_t)(void);

/* 16 core exceptions (the nRF51's Cortex-M0 has no SysTick), then IRQ
 * 0..31 (nRF51 reference manual, the instantiation table: the ID of a
 * peripheral is its interrupt number). Vectors left 0 fault into the
 * hard-fault handler if their interrupt ever fires. */
__attribute__((section(".isr_vector"), used)) static const vector_t vectors[48] = {
    (vector_t)(uintptr_t)&_estack, /* initial stack pointer */
    reset_handler,
    default_handler,        /* NMI */
    default_handler,        /* HardFault */
    [11] = default_handler, /* SVCall */
    [14] = default_handler, /* PendSV */
    [16 + UART_IRQ] = uart0_handler,
    [16 + TIMER0_IRQ] = timer0_handler,
};
