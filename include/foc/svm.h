/*
 * Space-vector modulation by min-max (zero-sequence) injection.
 *
 * Input: the stator voltage vector (alpha, beta) in Q15 per-unit of the
 * voltage that linear SVM reaches at the present bus voltage, i.e. 1.0 =
 * Vdc/sqrt(3) (the caller scales by the measured bus, see controller).
 * Output: three duty cycles, Q15 fraction of the PWM period in [0, 32767]
 * (high-side on-time / period), and the sector 1..6 of the vector (used by a
 * 3-shunt port to pick the two phases whose low side is on long enough).
 *
 * Inside the hexagon (which contains the linear circle |v| <= 1) the
 * phase-to-phase voltages are exact.  Beyond it the three phase voltages are
 * scaled down together so the duty span is exactly the period: the vector
 * keeps its angle and only its magnitude is reduced.
 */
#ifndef FOC_SVM_H
#define FOC_SVM_H

#include <stdint.h>
#include "foc/transforms.h"

typedef struct {
    q15_t a;        /* Q15 duty, [0, 32767] */
    q15_t b;
    q15_t c;
    uint8_t sector; /* 1..6, sector of the voltage vector, 60 deg each, */
                    /* sector 1 = [0, 60) deg from the alpha axis; the */
                    /* 60/120/.. deg edges are placed within 0.001 deg */
} foc_duty_t;

/* Sector by the phases holding the largest and the smallest value
 * (0 = a, 1 = b, 2 = c), svm.c. */
extern const uint8_t foc_svm_sector_of[3][3];

/* A duty within [0, 32767]: USAT on Cortex-M3, compares elsewhere. */
static inline q15_t foc_svm_duty_clamp(int32_t d)
{
#if defined(__ARM_FEATURE_SAT) && defined(__GNUC__) && !defined(FOC_PORTABLE_ONLY)
    return (q15_t)__builtin_arm_usat(d, 15);
#else
    return (d < 0) ? 0 : (d > 32767) ? Q15_MAX : (q15_t)d;
#endif
}

/* One phase's offset from the zero sequence `mid`, Q30 -> Q15, rounded. */
static inline int32_t foc_svm_offset(int32_t u, int32_t mid)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return (u - mid + 0x4000) >> 15;
}

/* One phase's duty, Q15: 1/2 plus its offset, clamped to the period. */
static inline q15_t foc_svm_duty(int32_t u, int32_t mid)
{
    return foc_svm_duty_clamp(16384 + foc_svm_offset(u, mid));
}

/* The same with the offset scaled by `gain` (Q15 held in 32 bits, the
 * period over the span beyond the hexagon). */
static inline q15_t foc_svm_duty_scaled(int32_t u, int32_t mid, int32_t gain)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return foc_svm_duty_clamp(16384 + ((foc_svm_offset(u, mid) * gain + 0x4000) >> 15));
}

/* Duties for the vector v.  Duty of phase x:
 *   d_x = 1/2 + (v_x - (v_max + v_min) / 2) / sqrt(3)
 * with v_x the phase values of the vector (inverse Clarke) in per-unit of
 * Vdc/sqrt(3), so a line-to-line duty difference is (v_x - v_y) / sqrt(3),
 * i.e. the line voltage in per-unit of Vdc.  The injected zero sequence
 * puts the centre of the duties at 1/2.  When the duty span would exceed
 * the period (outside the hexagon), the offsets from 1/2 are scaled by
 * period / span: same angle, smaller magnitude.  Inline: once per period. */
static inline foc_duty_t foc_svm_q15(foc_ab_t v)
{
    /* Phase values over sqrt(3), Q30: u_a = alpha / sqrt(3),
     * u_b,c = -alpha / (2 sqrt(3)) +- beta / 2.  |u| <= |v| / sqrt(3)
     * <= 0.82 (|v| <= sqrt(2) for Q15 inputs), so < 2^30.  In registers,
     * not an array: the phases are named, the loops written out. */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const int32_t ua = (int32_t)v.alpha * FOC_INV_SQRT3;
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t ub = (int32_t)v.beta * 16384 - (ua >> 1);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t uc = -(int32_t)v.beta * 16384 - (ua >> 1);

    /* Largest and smallest phase (0 = a, 1 = b, 2 = c) and their values;
     * on a tie the later phase wins, which puts the alpha axis (u_b ==
     * u_c) into sectors 1 and 4. */
    unsigned hi = (ub >= ua) ? (unsigned)1u : (unsigned)0u;
    unsigned lo = (ub <= ua) ? (unsigned)1u : (unsigned)0u;
    int32_t u_hi = (hi != 0u) ? ub : ua;
    int32_t u_lo = (lo != 0u) ? ub : ua;
    if (uc >= u_hi) {
        hi = 2u;
        u_hi = uc;
    }
    if (uc <= u_lo) {
        lo = 2u;
        u_lo = uc;
    }
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t mid = (u_hi + u_lo) >> 1; /* Q30, zero sequence */
    const int32_t span = u_hi - u_lo;       /* Q30, duty span, < 2^31 */

    /* Duties, Q15, within the period but for the half-LSB rounding at its
     * edges, which the clamp trims.  Beyond the hexagon the offsets are
     * scaled by period / span, a Q15 gain held in 32 bits: the values fit
     * a 32/16-bit division (span <= sqrt(2) < 2^16 in Q15, quotient
     * < 2^15). */
    foc_duty_t out;
    if (span > (int32_t)0x40000000) { /* 2^30 */
        const int32_t gain =
            /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
            (int32_t)((uint32_t)1 << 30) / (int32_t)((span + 0x4000) >> 15);
        out.a = foc_svm_duty_scaled(ua, mid, gain);
        out.b = foc_svm_duty_scaled(ub, mid, gain);
        out.c = foc_svm_duty_scaled(uc, mid, gain);
    } else {
        out.a = foc_svm_duty(ua, mid);
        out.b = foc_svm_duty(ub, mid);
        out.c = foc_svm_duty(uc, mid);
    }
    out.sector = foc_svm_sector_of[hi][lo];
    return out;
}

#endif /* FOC_SVM_H */
