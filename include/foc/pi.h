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
 * above 1 are possible; kp may reach +-65535 (a mantissa up to 2.0, the
 * monitor's headroom) where kp_shift <= 14: |kp e| < 2^31 and, shifted
 * right by at least 1, |Kp e| <= 2^30.  Ki = ki * 2^ki_shift / 32768 and
 * Kc are Q15 (per execution), in [0, 32767].  They are constants of the
 * build (config.h), held apart from the state in a `static const`
 * foc_pi_gains_t: the inline steps then fold them into immediates and
 * constant shifts, and the state in RAM is the integrator and the limits.
 * Where the monitor may write kp and ki, only those two mantissas live in
 * RAM (foc_pi_tune_t); the exponents and Kc stay folded.  Error, output
 * and limits are
 * Q15; the integrator is Q30 (the Q15 value times 2^15, with 15 fraction
 * bits: the Q30 products Ki e and Kc (y - u) add to it exactly).  It is
 * kept within the output range, |I| <= 2^30, so adding a product (< 2^30)
 * cannot overflow 32 bits.
 */
#ifndef FOC_PI_H
#define FOC_PI_H

#include <stdint.h>
#include "foc/q15.h"

typedef struct {
    int32_t kp;        /* proportional gain mantissa, Q15, |kp| <= 65535 */
    q15_t ki;          /* integral gain per execution, mantissa, Q15 */
    q15_t kc;          /* anti-windup back-calculation gain, Q15 */
    uint8_t kp_rshift; /* 15 - kp_shift: the product's right shift */
    uint8_t ki_shift;  /* integral gain exponent, 0..15 */
} foc_pi_gains_t;

/* A gains initialiser from the mantissas and exponents above. */
#define FOC_PI_GAINS(kp, kp_shift, ki, ki_shift, kc) \
    { (kp), (ki), (kc), (uint8_t)(15u - (kp_shift)), (uint8_t)(ki_shift) }

/* The mantissas of a PI's gains held in RAM so that the monitor can write
 * them (docs/monitor.md), at the build's exponents, which stay constants:
 * kp Q15 in [0, 65535] (0 .. 2 x 2^kp_shift per unit: 2 to 4 times the
 * build's normalised mantissa; kp_shift <= 14, config.h), ki Q15 in
 * [0, 32767].  Kc stays the build's. */
typedef struct {
    uint16_t kp;
    q15_t ki;
} foc_pi_tune_t;

/* The build's mantissas, to initialise a foc_pi_tune_t. */
static inline foc_pi_tune_t foc_pi_tune_of(const foc_pi_gains_t *build)
{
    const foc_pi_tune_t t = { (uint16_t)build->kp, build->ki }; /* 0 <= kp <= 32767 */
    return t;
}

/* The gains to step with: the RAM mantissas `t`, the rest the build's
 * (`build`, a static const: its exponents and Kc fold as before, and the
 * per-period code only loads two mantissas instead of immediates). */
static inline foc_pi_gains_t foc_pi_gains_with(const foc_pi_tune_t *t, const foc_pi_gains_t *build)
{
    const foc_pi_gains_t g = { (int32_t)t->kp, t->ki, build->kc, build->kp_rshift, build->ki_shift };
    return g;
}

typedef struct {
    q31_t integ;   /* integrator, Q30 */
    q15_t out_min; /* output limits, Q15, out_min <= out_max */
    q15_t out_max;
} foc_pi_q15_t;    /* 8 bytes */

/* Sets the limits, clears the integrator (within the limits). */
void foc_pi_init(foc_pi_q15_t *pi, q15_t out_min, q15_t out_max);

/* Integrator (Q30) of a Q15 value. */
#define FOC_PI_Q15_TO_Q30(x) ((int32_t)(x) * 32768)

/* Keeps the Q15 part of the integrator within the output limits. */
static inline void foc_pi_clamp_integ(foc_pi_q15_t *pi)
{
    const q31_t lo = FOC_PI_Q15_TO_Q30(pi->out_min);
    const q31_t hi = FOC_PI_Q15_TO_Q30(pi->out_max) + 32767;
    if (pi->integ < lo) {
        pi->integ = lo;
    } else if (pi->integ > hi) {
        pi->integ = hi;
    } else {
        /* within the limits */
    }
}

/* Changes the limits at run time (the integrator is clamped to them). */
static inline void foc_pi_set_limits(foc_pi_q15_t *pi, q15_t out_min, q15_t out_max)
{
    pi->out_min = out_min;
    pi->out_max = out_max;
    foc_pi_clamp_integ(pi);
}

/* Limits +-lim (0 <= lim) for the step that follows, which clamps the
 * integrator to them itself. */
static inline void foc_pi_limit_next(foc_pi_q15_t *pi, q15_t lim)
{
    pi->out_min = (q15_t)-lim;
    pi->out_max = lim;
}

/* u clamped to the output limits. */
static inline q15_t foc_pi_clamp_out(const foc_pi_q15_t *pi, int32_t u)
{
    if (u < pi->out_min) {
        return pi->out_min;
    }
    if (u > pi->out_max) {
        return pi->out_max;
    }
    return (q15_t)u;
}

/* Presets the integrator so the next output with zero error is y0
 * (bumpless transfer); y0 is clamped to the limits. */
static inline void foc_pi_preset(foc_pi_q15_t *pi, q15_t y0)
{
    pi->integ = FOC_PI_Q15_TO_Q30(foc_pi_clamp_out(pi, y0));
}

/* Kp e, Q15 held in 32 bits (not saturated): the product (< 2^31)
 * shifted right by 15 - kp_shift, rounded; |Kp e| <= 2^30. */
static inline int32_t foc_pi_kp_term(const foc_pi_gains_t *g, q15_t e)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t half = ((int32_t)1 << g->kp_rshift) >> 1; /* 0 for no shift */
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return ((int32_t)g->kp * (int32_t)e + half) >> g->kp_rshift;
}

/* I + Kp e, the unsaturated output (Q15 held in 32 bits). */
static inline int32_t foc_pi_unsat(const foc_pi_q15_t *pi, const foc_pi_gains_t *g, q15_t e)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return (pi->integ >> 15) + foc_pi_kp_term(g, e);
}

/* Ki e, Q30, limited to +-2^30 (a step beyond the whole range ends at the
 * limit all the same). */
static inline int32_t foc_pi_ki_term(const foc_pi_gains_t *g, q15_t e)
{
    return foc_mul_q30_shift(g->ki, e, g->ki_shift);
}

/* The rest of an execution once the limits are known, given the integral
 * step ki_e (Q30, |ki_e| <= 2^30: Ki e, or less): y = u clamped, and
 * I += ki_e + Kc (y - u), then I kept within the output range.  y - u is
 * saturated to Q15: the back-calculation only needs its sign and size up
 * to full scale; it is 0 unless the output is limited. */
static inline q15_t foc_pi_finish_ki(foc_pi_q15_t *pi, const foc_pi_gains_t *g, int32_t ki_e, int32_t u)
{
    const q15_t y = foc_pi_clamp_out(pi, u);
    pi->integ += ki_e; /* |I| <= 2^30: no overflow */
    if (y != u) {
        const q15_t excess = foc_sat_q15((int32_t)y - u);
        pi->integ = foc_add_q31(pi->integ, (int32_t)g->kc * (int32_t)excess);
    }
    foc_pi_clamp_integ(pi);
    return y;
}

/* The same with I += Ki e. */
static inline q15_t foc_pi_finish(foc_pi_q15_t *pi, const foc_pi_gains_t *g, q15_t e, int32_t u)
{
    return foc_pi_finish_ki(pi, g, foc_pi_ki_term(g, e), u);
}

/* One execution with error e = reference - feedback; returns the output.
 * Inline: the current loop runs two every PWM period. */
static inline q15_t foc_pi_step(foc_pi_q15_t *pi, const foc_pi_gains_t *g, q15_t e)
{
    return foc_pi_finish(pi, g, e, foc_pi_unsat(pi, g, e));
}

#endif /* FOC_PI_H */
