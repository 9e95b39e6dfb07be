/*
 * Sine, cosine and atan2 on 16-bit angles.
 *
 * Angle: uint16_t, 65536 counts = 360 electrical degrees (wraps for free).
 * Sine/cosine: a quarter-wave table of 129 points (512 points per turn) with
 * linear interpolation; result Q15, max error 2 LSB against double (1.44
 * measured over all angles; sin(90 deg) saturates to 32767).  No division.
 * atan2: octant reduction, one 32/16-bit division for the ratio, and a
 * 33-point table with linear interpolation; max error 0.05 electrical
 * degrees (9 counts; 0.01 deg measured), at any input magnitude.
 */
#ifndef FOC_TRIG_H
#define FOC_TRIG_H

#include <stdint.h>
#include "foc/q15.h"

typedef struct {
    q15_t sin; /* Q15 */
    q15_t cos; /* Q15 */
} foc_sincos_t;

/* The quarter-wave table of trig.c: sin(2 pi i / 512), i = 0..128, Q15,
 * point 128 repeated (index 128 read with a zero fraction). */
extern const int16_t foc_sin_table[130];

/* sin(x) for x in [0, 16384] counts, Q15 in [0, 32767]: table step x / 128,
 * 7-bit fraction, interpolated and rounded. */
static inline q15_t foc_quarter_sin_q15(uint16_t x)
{
    const uint16_t i = (uint16_t)(x >> 7);
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    const int32_t frac = (int32_t)(x & 127u);
    const int32_t y0 = foc_sin_table[i];
    const int32_t dy = (int32_t)foc_sin_table[i + 1u] - y0; /* 0..402 */
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return (q15_t)(y0 + ((dy * frac + 64) >> 7));         /* <= 32767 */
}

/* sin and cos of one angle, Q15.  With p the position inside the
 * quadrant, they are sin(p) and cos(p) = sin(90 deg - p), turned by the
 * quadrant: a quarter turn maps (sin, cos) to (cos, -sin), a half turn
 * negates both. */
static inline foc_sincos_t foc_sincos_q15(uint16_t angle)
{
    const uint16_t p = (uint16_t)(angle & 16383u);
    q15_t s = foc_quarter_sin_q15(p);
    q15_t c = foc_quarter_sin_q15((uint16_t)(16384u - p));
    if ((angle & 16384u) != 0u) {
        const q15_t t = s;
        s = c;
        c = (q15_t)-t;
    }
    if ((angle & 32768u) != 0u) {
        s = (q15_t)-s;
        c = (q15_t)-c;
    }
    foc_sincos_t r;
    r.sin = s;
    r.cos = c;
    return r;
}

/* sin and cos of the sum of two angles from theirs (a rotation, four
 * products), Q15, rounded, saturated: cheaper than a table look-up. */
static inline foc_sincos_t foc_sincos_sum(foc_sincos_t a, foc_sincos_t b)
{
    foc_sincos_t r;
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    r.sin = foc_sat_q15(((int32_t)a.sin * b.cos + (int32_t)a.cos * b.sin + 0x4000) >> 15);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    r.cos = foc_sat_q15(((int32_t)a.cos * b.cos - (int32_t)a.sin * b.sin + 0x4000) >> 15);
    return r;
}

/* sin(angle), Q15. */
static inline q15_t foc_sin_q15(uint16_t angle)
{
    return foc_sincos_q15(angle).sin;
}

/* cos(angle), Q15. */
static inline q15_t foc_cos_q15(uint16_t angle)
{
    return foc_sincos_q15(angle).cos;
}

/* Angle of the vector (x, y), same scaling as above; (0, 0) gives 0.
 * x and y share any common scale (Q15 or raw). */
uint16_t foc_atan2_q15(q15_t y, q15_t x);

/* Signed difference a - b of two angles, counts in [-32768, 32767]
 * (the shorter way round). */
static inline int16_t foc_angle_diff(uint16_t a, uint16_t b)
{
    const uint16_t d = (uint16_t)(a - b);
    return (int16_t)((d >= 32768u) ? (int32_t)d - (int32_t)65536 : (int32_t)d);
}

#endif /* FOC_TRIG_H */
