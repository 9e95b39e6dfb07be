/*
 * STM32F10x port of the FOC core (include/foc/port.h) for a three-shunt
 * inverter on TIM1 (full remap) with ADC1 + ADC2 in injected simultaneous
 * mode, plus what the board's main.c needs around it.
 *
 * Interrupts (4 preemption bits, lower is more urgent):
 *   TIM1 break      0  hardware already turned the outputs off; latch it,
 *                      keep the ADC converting (update trigger)
 *   ADC1/2 JEOC     1  foc_fast_step(), then the next period's sampling plan
 *   TIM1 update     1  re-enables the ADC trigger at the period boundary
 *   SysTick         3  foc_slow_step() every CONTROL_SLOW_DIVIDER periods,
 *                      watchdog refresh while the fast step keeps running
 *
 * Timing: duties the fast step sets in period k are loaded into TIM1's
 * preload registers and take effect at the update that starts period k+1;
 * the phases and sampling point for period k+1's conversion are chosen
 * from those same duties (stm32_logic.h).  Because the ADC sequence and
 * the CC4 polarity have no preload, the ADC trigger is switched off from
 * the end of the fast step until that update, so no conversion can use the
 * new sequence with the old duties.  The fast step must therefore finish
 * within half a PWM period of the sampling point; a late finish is counted
 * as an overrun.
 */
#ifndef STM32_PORT_H
#define STM32_PORT_H

#include <stdint.h>
#include "foc/controller.h"

/* Execution time of the ADC interrupt (fast step included), in CPU cycles
 * of the DWT counter. */
typedef struct {
    uint32_t min;
    uint32_t max;
    uint32_t avg;        /* exponential average over about 16 periods */
    uint32_t overruns;   /* fast step finished after the next update */
    uint32_t unclean;    /* periods sampled without a clean window */
    uint32_t breaks;     /* hardware break (over-current) events */
    uint32_t spurious;   /* conversions not from the planned trigger */
} stm32_isr_stats_t;

/* Sets up TIM1, the ADCs, TIM3 ("DAC"), the brake pin, the interrupts and
 * SysTick, and starts the PWM timer with the outputs off.  foc_init(c) must
 * have been called; c is used by the interrupts from now on.  Requires the
 * 72 MHz clock (stm32_clock_init() returned 1).  Returns 0 if TIM1's
 * update could not be placed at the bottom of the count: the port then
 * never turns the bridge on (control and monitor keep running). */
uint8_t stm32_port_init(foc_ctrl_t *c);

/* Copy of the execution-time statistics (consistent snapshot). */
void stm32_port_isr_stats(stm32_isr_stats_t *out);
void stm32_port_isr_stats_reset(void);

/* Slow ticks since start (CONTROL_SLOW_DIVIDER PWM periods each). */
uint32_t stm32_port_slow_ticks(void);

/* PWM period in CPU cycles (the fast step's budget is under half of it). */
uint32_t stm32_port_period_cycles(void);

#endif /* STM32_PORT_H */
