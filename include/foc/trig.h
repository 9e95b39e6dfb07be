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

/* sin(angle), Q15. */
q15_t foc_sin_q15(uint16_t angle);

/* cos(angle), Q15. */
q15_t foc_cos_q15(uint16_t angle);

/* Both at once (one table fold shared). */
foc_sincos_t foc_sincos_q15(uint16_t angle);

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
