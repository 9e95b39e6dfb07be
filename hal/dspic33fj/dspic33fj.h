/*
 * dsPIC33FJ32MC204 port: peripheral set-up, the two control interrupts,
 * and port.h.
 *
 * Resources (numbers from the board's board.h):
 *   MCPWM1   centre-aligned complementary PWM, dead time, fault A latch
 *            (outputs off in hardware), special event -> ADC start
 *   ADC1     10-bit, CH0..CH3 sampled simultaneously at the trigger,
 *            signed fractional; its interrupt runs foc_fast_step()
 *   Timer1   not counting: its interrupt vector is raised by software
 *            every CONTROL_SLOW_DIVIDER fast steps and runs foc_slow_step()
 *            at a lower priority (so exactly PWM / CONTROL_SLOW_DIVIDER,
 *            phase-locked to the PWM)
 *   Timer2/3 32-bit free-running at Fcy: foc_port_timestamp(), the
 *            fast-step execution time (min/avg/max)
 *   UART1    the monitor's serial line (polled)
 *   WDT      cleared by the main loop while the slow step runs
 * Traps (oscillator fail, address, stack, math, unused vectors) turn the
 * six PWM outputs off and reset the device.
 */
#ifndef DSPIC33FJ_H
#define DSPIC33FJ_H

#include <stdint.h>
#include "foc/controller.h"
#include "dspic_logic.h"

/* Clock to Fcy, peripheral pin select, MCPWM (running, outputs
 * overridden off), ADC, timers, UART.  Interrupts stay off. */
void dspic_init(void);

/* Attaches the controller (foc_init() done) and enables the fast and
 * slow interrupts: foc_fast_step() runs from the next PWM period. */
void dspic_start(foc_ctrl_t *c);

/* Execution time of the fast-step interrupt, in timestamp ticks. */
void dspic_fast_stats(dspic_stats_t *out);

/* Slow steps run so far (wraps); slow steps lost because the previous
 * one had not started when the next was due. */
uint16_t dspic_slow_count(void);
uint16_t dspic_slow_overruns(void);

/* The last foc_port_debug_out() values (the board has no DAC). */
void dspic_debug_values(q15_t *ch1, q15_t *ch2);

/* RCON as found at start-up (reset cause), before dspic_init() cleared it. */
uint16_t dspic_reset_cause(void);

/* Watchdog (period from the FWDT configuration bits). */
void dspic_watchdog_enable(void);
void dspic_watchdog_clear(void);

/* UART1, non-blocking: 1 if a byte was read / accepted. */
uint8_t dspic_uart_read(uint8_t *ch);
uint8_t dspic_uart_write(uint8_t ch);

#endif /* DSPIC33FJ_H */
