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
    } else if (n == 15u) {
        systick_handler();
    } else {
        default_handler();
    }
}
#define nmi_h forward
#define hardfault_h forward
#define svc_h forward
#define pendsv_h forward
#define systick_h forward
#define can_h forward /* the bootloader polls its CAN controller (board.c) */
#else
#define nmi_h default_handler
#define hardfault_h default_handler
#define svc_h default_handler
#define pendsv_h default_handler
#define systick_h systick_handler
#define can_h can_irq_handler
#endif

/* 16 core exceptions, then IRQ 0..31 (RM0091 table 37). Vectors left 0
 * fault into the hard-fault handler if their interrupt ever fires. */
__attribute__((section(".isr_vector"), used)) static const vector_t vectors[48] = {
    (vector_t)(uintptr_t)&_estack, /* initial stack pointer */
    reset_handler,
    nmi_h,             /* NMI */
    hardfault_h,       /* HardFault */
    [11] = svc_h,      /* SVCall */
    [14] = pendsv_h,   /* PendSV */
    [15] = systick_h,  /* SysTick */
    [16 + 30] = can_h, /* CEC_CAN */
};
