/*
 * Start-up of the Cortex-M3 bench image: vector table, .data/.bss set-up,
 * then main().  The instruction-set simulator (tools/bench/bench.py) starts
 * at bench_reset with SP from the vector table, as the core would, and
 * stops when execution reaches bench_done.
 */
#include <stdint.h>

extern uint32_t _data_load[], _data_start[], _data_end[];
extern uint32_t _bss_start[], _bss_end[], _stack_top[];

int main(void);
void bench_reset(void);
void bench_done(void);
void bench_fault(void);

__attribute__((section(".vectors"), used))
static void (*const vectors[16])(void) = {
    (void (*)(void))(uintptr_t)_stack_top, /* initial SP */
    bench_reset,
    bench_fault, bench_fault, bench_fault, bench_fault, bench_fault,
    0, 0, 0, 0,
    bench_fault, bench_fault, 0, bench_fault, bench_fault,
};

void bench_reset(void)
{
    uint32_t *src = _data_load;
    for (uint32_t *dst = _data_start; dst < _data_end; dst++) {
        *dst = *src++;
    }
    for (uint32_t *dst = _bss_start; dst < _bss_end; dst++) {
        *dst = 0u;
    }
    (void)main();
    bench_done();
}

/* The simulator stops here (its stop address). */
__attribute__((noinline, noreturn)) void bench_done(void)
{
    for (;;) {
        __asm volatile("bkpt #0");
    }
}

/* Any exception: the simulator reports it (stops on the breakpoint). */
__attribute__((noinline, noreturn)) void bench_fault(void)
{
    for (;;) {
        __asm volatile("bkpt #1");
    }
}
