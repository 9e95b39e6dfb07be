/*
 * PI controller with back-calculation anti-windup; see foc/pi.h.
 */
#include "foc/pi.h"

/* Integrator (Q31) of a Q15 value: the Q15 value in the upper 16 bits. */
#define Q15_TO_Q31(x) ((int32_t)(x) * 65536)

/* The Q30 product p as Q31 times 2^shift (p x 2^(1 + shift)), saturated:
 * multiplied, never shifted left, so a negative p is well defined. */
static q31_t q30_to_q31_scaled(int32_t p, uint8_t shift)
{
    const int32_t limit = INT32_MAX >> (1u + shift);
    if (p > limit) {
        return INT32_MAX;
    }
    if (p < -limit) {
        return -INT32_MAX;
    }
    return p * ((int32_t)2 << shift);
}

/* Keeps the Q15 part of the integrator within the output limits. */
static void clamp_integ(foc_pi_q15_t *pi)
{
    const q31_t lo = Q15_TO_Q31(pi->out_min);
    const q31_t hi = Q15_TO_Q31(pi->out_max) + 65535; /* <= INT32_MAX */
    if (pi->integ < lo) {
        pi->integ = lo;
    } else if (pi->integ > hi) {
        pi->integ = hi;
    }
}

static q15_t clamp_out(const foc_pi_q15_t *pi, int32_t u)
{
    if (u < pi->out_min) {
        return pi->out_min;
    }
    if (u > pi->out_max) {
        return pi->out_max;
    }
    return (q15_t)u;
}

void foc_pi_init(foc_pi_q15_t *pi, q15_t kp, uint8_t kp_shift, q15_t ki,
                 uint8_t ki_shift, q15_t kc, q15_t out_min, q15_t out_max)
{
    pi->kp = kp;
    pi->kp_shift = kp_shift;
    pi->ki = ki;
    pi->ki_shift = ki_shift;
    pi->kc = kc;
    pi->out_min = out_min;
    pi->out_max = out_max;
    pi->integ = 0;
    clamp_integ(pi); /* for limits that exclude 0 */
}

void foc_pi_set_limits(foc_pi_q15_t *pi, q15_t out_min, q15_t out_max)
{
    pi->out_min = out_min;
    pi->out_max = out_max;
    clamp_integ(pi);
}

void foc_pi_preset(foc_pi_q15_t *pi, q15_t y0)
{
    pi->integ = Q15_TO_Q31(clamp_out(pi, y0));
}

q15_t foc_pi_step(foc_pi_q15_t *pi, q15_t e)
{
    /* Proportional term Kp e, Q15 held unsaturated in 32 bits:
     * the Q30 product shifted right by 15 - kp_shift, rounded; <= 2^30. */
    const int32_t p = (int32_t)pi->kp * (int32_t)e; /* Q30 */
    const uint8_t r = (uint8_t)(15u - pi->kp_shift);
    const int32_t prop = (r == 0u) ? p : (p + ((int32_t)1 << (r - 1u))) >> r;

    const int32_t u = (pi->integ >> 16) + prop; /* Q15, unsaturated */
    const q15_t y = clamp_out(pi, u);
    /* y - u, Q15, saturated: the back-calculation only needs its sign and
     * size up to full scale. */
    const q15_t excess = foc_sat_q15((int32_t)y - u);

    /* I += Ki e + Kc (y - u), Q31 (the Q30 products doubled, Ki's scaled by
     * its exponent; saturating), then kept within the output range. */
    pi->integ = foc_add_q31(pi->integ,
                            q30_to_q31_scaled((int32_t)pi->ki * (int32_t)e, pi->ki_shift));
    pi->integ = foc_add_q31(pi->integ, 2 * ((int32_t)pi->kc * (int32_t)excess));
    clamp_integ(pi);
    return y;
}
