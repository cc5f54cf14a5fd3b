/*
 * startup.c - vector table and reset for the STM32F042 (Cortex-M0):
 * copy .data, clear .bss, then main(). Unused interrupts stop in
 * default_handler; a hard fault too (a debugger shows where).
 */
#include <stdint.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
int main(void);
void reset_handler(void);
void default_handler(void);
void systick_handler(void);
void can_irq_handler(void);

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

/* 16 core exceptions, then IRQ 0..31 (RM0091 table 37). Vectors left 0
 * fault into the hard-fault handler if their interrupt ever fires. */
__attribute__((section(".isr_vector"), used)) static const vector_t vectors[48] = {
    (vector_t)(uintptr_t)&_estack, /* initial stack pointer */
    reset_handler,
    default_handler,        /* NMI */
    default_handler,        /* HardFault */
    [11] = default_handler, /* SVCall */
    [14] = default_handler, /* PendSV */
    [15] = systick_handler,
    [16 + 30] = can_irq_handler, /* CEC_CAN */
};
