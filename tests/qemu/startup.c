/*
 * startup.c - reset and fault handling for the unit tests on qemu's
 * Cortex-M0 "microbit" machine: copy .data, clear .bss, paint the free RAM
 * so the stack's high-water mark can be measured, run the test's main(),
 * print the stack figure and leave qemu with main's exit status. A hard
 * fault (on silicon: an unaligned access, a bad pointer) prints where it
 * happened and exits with status 3.
 */
#include <stdint.h>

#include "bare_io.h"

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
int main(void);
void reset_handler(void);
void fault_handler(void);

#define PAINT 0xA5C3A5C3u

/* Free RAM below the current stack pointer, painted before main() runs. */
static uint32_t *stack_floor(void)
{
    uint32_t *p = &_ebss;
    while (p < &_estack && *p == PAINT) {
        p++;
    }
    return p;
}

void reset_handler(void)
{
    uint32_t *src = &_sidata;
    for (uint32_t *dst = &_sdata; dst < &_edata;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = &_sbss; dst < &_ebss;) {
        *dst++ = 0;
    }
    /* Paint up to 64 bytes below this function's own frame. */
    uintptr_t sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    for (uint32_t *p = &_ebss; (uintptr_t)p < sp - 64u; p++) {
        *p = PAINT;
    }
    int status = main();
    unsigned used = (unsigned)((uintptr_t)&_estack - (uintptr_t)stack_floor());
    unsigned room = (unsigned)((uintptr_t)&_estack - (uintptr_t)&_ebss);
    bare_printf("Cortex-M0 stack: %u of %u bytes free RAM used at most\n", used, room);
    bare_exit(status);
}

void fault_report(const uint32_t *frame) __attribute__((noreturn, used));

/* The exception frame is on the main stack: r0-r3, r12, lr, pc, xpsr. */
void fault_report(const uint32_t *frame)
{
    bare_printf("HARD FAULT: pc=0x%08lx lr=0x%08lx\n", (unsigned long)frame[6],
                (unsigned long)frame[5]);
    bare_exit(3);
}

/* Naked: the stack pointer still points at the frame the core pushed. */
__attribute__((naked)) void fault_handler(void)
{
    __asm__ volatile("mrs r0, msp\n\tbl fault_report\n");
}

typedef void (*vector_t)(void);

__attribute__((section(".isr_vector"), used)) static const vector_t vectors[16] = {
    (vector_t)(uintptr_t)&_estack, /* initial stack pointer */
    reset_handler,
    fault_handler,        /* NMI */
    fault_handler,        /* HardFault */
    [11] = fault_handler, /* SVCall */
    [14] = fault_handler, /* PendSV */
    [15] = fault_handler, /* SysTick: never enabled */
};
