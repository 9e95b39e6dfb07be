/*
 * PI controller with output limits and back-calculation anti-windup
 * (AN1292's "Kc" form):
 *
 *   u      = I + Kp e                  (unsaturated, Q15 computed in 32 bits)
 *   y      = clamp(u, out_min, out_max)
 *   I     += Ki e + Kc (y - u)
 *
 * Why back-calculation: when the output saturates the integrator is pulled
 * back toward the limit at a rate set by Kc, so it recovers without the
 * overshoot a frozen (clamped) integrator leaves when the error changes sign
 * slowly, and Kc is one more knob AN1292 users already know.  The integrator
 * is also clamped to the output range, so it can never hold a value the
 * output could not use.
 *
 * Gains: Kp = kp * 2^kp_shift / 32768 (kp Q15, kp_shift 0..15) so gains
 * above 1 are possible; Ki and Kc are Q15 (per execution), in [0, 32767].
 * Error, output and limits are Q15; the integrator is Q31 (upper 16 bits =
 * Q15 value).
 */
#ifndef FOC_PI_H
#define FOC_PI_H

#include <stdint.h>
#include "foc/q15.h"

typedef struct {
    q15_t kp;         /* proportional gain mantissa, Q15 */
    uint8_t kp_shift; /* proportional gain exponent, 0..15 */
    q15_t ki;         /* integral gain per execution, mantissa, Q15 */
    uint8_t ki_shift; /* integral gain exponent, 0..15 */
    q15_t kc;         /* anti-windup back-calculation gain, Q15 */
    q15_t out_min;    /* output limits, Q15, out_min <= out_max */
    q15_t out_max;
    q31_t integ;      /* integrator, Q31 */
} foc_pi_q15_t;

/* Sets gains and limits, clears the integrator. */
void foc_pi_init(foc_pi_q15_t *pi, q15_t kp, uint8_t kp_shift, q15_t ki,
                 uint8_t ki_shift, q15_t kc, q15_t out_min, q15_t out_max);

/* Changes the limits at run time (the integrator is clamped to them). */
void foc_pi_set_limits(foc_pi_q15_t *pi, q15_t out_min, q15_t out_max);

/* Presets the integrator so the next output with zero error is y0
 * (bumpless transfer); y0 is clamped to the limits. */
void foc_pi_preset(foc_pi_q15_t *pi, q15_t y0);

/* One execution with error e = reference - feedback; returns the output. */
q15_t foc_pi_step(foc_pi_q15_t *pi, q15_t e);

#endif /* FOC_PI_H */
