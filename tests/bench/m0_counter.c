/*
 * m0_counter.c - the check of tools/m0count.py, the Cortex-M0 instruction
 * counter of tools/bench (ctest bench.m0_counter): loops of a known number
 * of Thumb-1 instructions, so that the count it must give is known exactly.
 *
 * counter_loop: movs, then COUNTER_TURNS turns of five instructions (three
 * nops, subs, bne; the last bne, not taken, counts too), then bx lr:
 * 5 * 50 + 2 = 252 instructions a call.
 * counter_outer: push, bl counter_loop, bl counter_loop, pop: 4 + 2 * 252
 * = 508 a call (nested calls are counted inside their caller).
 * main calls counter_outer three times: counter_loop runs six times.
 */
#include "bare_io.h"

void counter_loop(void);
void counter_outer(void);
int main(void);

/* Its turn count (50) is in tests/CMakeLists.txt's expected figure. */
__attribute__((naked, noinline, used)) void counter_loop(void)
{
    __asm__ volatile(".syntax unified\n\t"
                     "movs r0, #50\n"
                     "1: nop\n\tnop\n\tnop\n\t"
                     "subs r0, #1\n\t"
                     "bne 1b\n\t"
                     "bx lr\n");
}

__attribute__((naked, noinline, used)) void counter_outer(void)
{
    __asm__ volatile(".syntax unified\n\t"
                     "push {lr}\n\t"
                     "bl counter_loop\n\t"
                     "bl counter_loop\n\t"
                     "pop {pc}\n");
}

int main(void)
{
    for (int i = 0; i < 3; i++) {
        counter_outer();
    }
    printf("m0_counter: done\n");
    return 0;
}
