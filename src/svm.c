/*
 * Space-vector modulation by min-max injection.
 *
 * Duty of phase x:  d_x = 1/2 + (v_x - (v_max + v_min) / 2) / sqrt(3)
 * with v_x the phase values of the vector (inverse Clarke) in per-unit of
 * Vdc/sqrt(3), so a line-to-line duty difference is (v_x - v_y) / sqrt(3),
 * i.e. the line voltage in per-unit of Vdc.  The injected zero sequence puts
 * the centre of the duties at 1/2.  When the duty span would exceed the
 * period (outside the hexagon), the offsets from 1/2 are scaled by
 * period / span: same angle, smaller magnitude.
 */
#include "foc/svm.h"

#define INV_SQRT3 Q15(0.57735026918962576)   /* 1/sqrt(3), 18919 */
#define HALF Q15(0.5)                        /* 16384; also duty 1/2 */
#define PERIOD_Q30 ((int32_t)1 << 30)        /* duty 1, Q30 */

/* Sector by the phases holding the largest and the smallest value
 * (0 = a, 1 = b, 2 = c): a max / c min is [0, 60) deg, b max / c min is
 * [60, 120) deg, and so on.  The diagonal is the zero vector. */
static const uint8_t SECTOR_OF[3][3] = {
    /* min: a  b  c */
    { 1, 6, 1 }, /* max a */
    { 3, 1, 2 }, /* max b */
    { 4, 5, 1 }, /* max c */
};

/* Q30 -> Q15, rounded to nearest; |x| < 2^31 - 2^14. */
static int32_t q30_to_q15(int32_t x)
{
    return (x + 0x4000) >> 15;
}

static q15_t clamp_duty(int32_t d)
{
    return (d < 0) ? 0 : (d > 32767) ? Q15_MAX : (q15_t)d;
}

foc_duty_t foc_svm_q15(foc_ab_t v)
{
    /* Phase values over sqrt(3), Q30: u_a = alpha / sqrt(3),
     * u_b,c = -alpha / (2 sqrt(3)) +- beta / 2.  |u| <= |v| / sqrt(3)
     * <= 0.82 (|v| <= sqrt(2) for Q15 inputs), so < 2^30. */
    int32_t u[3];
    u[0] = (int32_t)v.alpha * INV_SQRT3;
    u[1] = (int32_t)v.beta * HALF - (u[0] >> 1);
    u[2] = -(int32_t)v.beta * HALF - (u[0] >> 1);

    /* Largest and smallest phase; on a tie the later phase wins, which
     * puts the alpha axis (u_b == u_c) into sectors 1 and 4. */
    unsigned hi = 0u;
    unsigned lo = 0u;
    for (unsigned k = 1u; k < 3u; k++) {
        if (u[k] >= u[hi]) {
            hi = k;
        }
        if (u[k] <= u[lo]) {
            lo = k;
        }
    }
    const int32_t mid = (u[hi] + u[lo]) >> 1; /* Q30, zero sequence */
    const int32_t span = u[hi] - u[lo];      /* Q30, duty span, < 2^31 */

    /* Overmodulation gain, Q15 held in 32 bits (1.0 = 32768): period / span
     * when span > period.  The values fit a 32/16-bit division (span
     * <= sqrt(2) < 2^16 in Q15, quotient < 2^15). */
    int32_t gain = 32768;
    if (span > PERIOD_Q30) {
        gain = (int32_t)((uint32_t)PERIOD_Q30 / (uint32_t)q30_to_q15(span));
    }

    /* Duties, Q15: 1/2 plus the scaled offset from the zero sequence; the
     * clamp only trims the half-LSB rounding at the edges of the period. */
    q15_t d[3];
    for (unsigned k = 0u; k < 3u; k++) {
        const int32_t offset = q30_to_q15(u[k] - mid); /* Q15, <= span/2 */
        d[k] = clamp_duty(HALF + ((offset * gain + 0x4000) >> 15));
    }

    foc_duty_t out;
    out.a = d[0];
    out.b = d[1];
    out.c = d[2];
    out.sector = SECTOR_OF[hi][lo];
    return out;
}
