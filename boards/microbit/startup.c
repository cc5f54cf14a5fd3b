/*
 * startup.c - vector table and reset for the nRF51822 (Cortex-M0): copy
 * .data, clear .bss, then main(). The same steps as the Nucleo's
 * start-up; only the vector table differs (the chip's interrupt numbers).
 * Unused interrupts stop in default_handler; a hard fault too (a debugger
 * shows where). Built twice, as the Nucleo's: with BOARD_BOOT the
 * bootloader's table forwards to the application's while it runs (the
 * Nucleo's startup.c says how and why).
 */
#include <stdint.h>

#include "nrf51.h"

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
int main(void);
void reset_handler(void);
void default_handler(void);
void uart0_handler(void);
void timer0_handler(void);

#ifdef BOARD_BOOT
#define BOOT_APP_RUNNING 0x4E555241u /* "ARUN" */
extern volatile uint32_t _app_running;
extern const uint32_t _app_vectors[];
#endif

void reset_handler(void)
{
#ifdef BOARD_BOOT
    _app_running = 0;
#endif
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

#ifdef BOARD_BOOT
/* Every exception the bootloader's table names comes here: while the
 * application runs, its handler of the same number (its table, as the
 * hardware would have used it); else the bootloader's own. One forwarder
 * for all, the number read from IPSR: a forwarder per vector cost the
 * 4 KiB bootloader 200 bytes more. */
static void forward(void)
{
    uint32_t n;
    __asm__ volatile("mrs %0, ipsr" : "=r"(n));
    n &= 0x3Fu;
    if (_app_running == BOOT_APP_RUNNING) {
        ((vector_t)(uintptr_t)_app_vectors[n])();
    } else {
        default_handler(); /* the bootloader takes no interrupt (board.c) */
    }
}
#define nmi_h forward
#define hardfault_h forward
#define svc_h forward
#define pendsv_h forward
#define uart_h forward
#define timer_h forward
#else
#define nmi_h default_handler
#define hardfault_h default_handler
#define svc_h default_handler
#define pendsv_h default_handler
#define uart_h uart0_handler
#define timer_h timer0_handler
#endif

/* 16 core exceptions (the nRF51's Cortex-M0 has no SysTick), then IRQ
 * 0..31 (nRF51 reference manual, the instantiation table: the ID of a
 * peripheral is its interrupt number). Vectors left 0 fault into the
 * hard-fault handler if their interrupt ever fires. */
__attribute__((section(".isr_vector"), used)) static const vector_t vectors[48] = {
    (vector_t)(uintptr_t)&_estack, /* initial stack pointer */
    reset_handler,
    nmi_h,           /* NMI */
    hardfault_h,     /* HardFault */
    [11] = svc_h,    /* SVCall */
    [14] = pendsv_h, /* PendSV */
    [16 + UART_IRQ] = uart_h,
    [16 + TIMER0_IRQ] = timer_h,
};
