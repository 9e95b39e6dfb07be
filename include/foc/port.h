/*
 * The port: everything the core needs from a board, and nothing else.
 *
 * Each port (hal/stm32f10x, hal/dspic33fj, hal/host) implements every
 * function below; there are no weak defaults, so a missing one is a link
 * error.  Ports only move data between registers and the core and apply the
 * board's analog scaling; all control decisions stay in the core.
 *
 * Calls into the core come from the port's interrupts, through two entry
 * points of controller.h: foc_fast_step() once per PWM period after the
 * ADC has converted (highest priority after the hardware fault), and
 * foc_slow_step() every CONTROL_SLOW_DIVIDER periods at a lower priority.
 */
#ifndef FOC_PORT_H
#define FOC_PORT_H

#include <stdint.h>
#include "foc/q15.h"
#include "foc/svm.h"

/* Bits of foc_samples_t.phases: which current readings are valid. */
#define FOC_PHASE_A 0x1u
#define FOC_PHASE_B 0x2u
#define FOC_PHASE_C 0x4u

/* One PWM period's measurements, scaled by the port from board facts. */
typedef struct {
    /* Phase currents, Q15 of BOARD_CURRENT_FULL_SCALE_A, positive into the
     * motor, sign and gain corrected by the port but offset NOT removed
     * (the core calibrates it).  Only phases flagged in `phases` are valid:
     * two of three on a 2-shunt board or a 3-shunt board in a sector where
     * one low-side pulse is too short; all three otherwise.  Fewer than two
     * (no clean sampling window this period): the core keeps the previous
     * period's current. */
    q15_t i_a, i_b, i_c;
    uint8_t phases;
    q15_t vdc;          /* bus voltage, Q15 of BOARD_VDC_FULL_SCALE_V, >= 0 */
    q15_t temp;         /* temperature sensor, Q15 of BOARD_ADC_VREF_V, >= 0 */
    q15_t pot;          /* potentiometer, Q15 fraction of its range, >= 0 */
    uint16_t theta_sensor; /* rotor electrical angle from a position sensor */
                           /* (65536 = 360 deg); 0 where the board has none */
} foc_samples_t;

/* Fills *s with the samples converted for the present period. */
void foc_port_read_samples(foc_samples_t *s);

/* Loads the duties (Q15 fraction of the period, [0, 32767]) for the next
 * period; `sector` lets a 3-shunt port choose its sampling phases. */
void foc_port_set_duties(const foc_duty_t *d);

/* Turns the bridge's PWM outputs on from the next period boundary, where
 * the duties set in this fast step take effect: turned on at once, the
 * outputs would apply the period's old duties (a zero vector while off)
 * to a turning rotor's back-EMF until then. */
void foc_port_pwm_enable(void);

/* CATCH's probe: turns the PWM outputs on (duties 1/2, the zero vector)
 * half a PWM period after the sample that started this fast step, so
 * that the windings are shorted for the half period before the next
 * sample.  A port may wait for that instant here: the probe's fast step
 * has nothing else to do. */
void foc_port_pwm_enable_at_half(void);

/* Turns all six switches off at once (coast; diodes only), not at the
 * period boundary. */
void foc_port_pwm_disable(void);

/* Turns all three low sides on, high sides off (shorts the windings), at
 * once. */
void foc_port_low_sides_on(void);

/* Switches the bus brake resistor on (1) or off (0). */
void foc_port_brake_resistor(uint8_t on);

/* 1 while the hardware over-current/fault input has latched the outputs
 * off; the hardware latch turns the bridge off by itself. */
uint8_t foc_port_overcurrent_latched(void);

/* Clears the hardware latch (outputs stay off until enabled). */
void foc_port_overcurrent_clear(void);

/* Writes two Q15 debug values to the board's "DAC" outputs. */
void foc_port_debug_out(q15_t ch1, q15_t ch2);

/* Free-running time base in port-specific ticks, for execution-time
 * measurement; wraps. */
uint32_t foc_port_timestamp(void);

#endif /* FOC_PORT_H */
