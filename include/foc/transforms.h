/*
 * Clarke, Park and inverse Park transforms, amplitude-invariant (a phase
 * amplitude of 1 gives a vector of magnitude 1).  All inputs and outputs Q15
 * per-unit; results rounded and saturated to Q15.
 */
#ifndef FOC_TRANSFORMS_H
#define FOC_TRANSFORMS_H

#include "foc/q15.h"
#include "foc/trig.h"

typedef struct {
    q15_t alpha;
    q15_t beta;
} foc_ab_t;

typedef struct {
    q15_t d;
    q15_t q;
} foc_dq_t;

typedef struct {
    q15_t a;
    q15_t b;
    q15_t c;
} foc_abc_t;

/* From phases a and b of a balanced set (c = -a - b):
 * alpha = a, beta = (a + 2 b) / sqrt(3). */
foc_ab_t foc_clarke2_q15(q15_t a, q15_t b);

/* From three measured phases, zero sequence removed:
 * alpha = (2a - b - c) / 3, beta = (b - c) / sqrt(3). */
foc_ab_t foc_clarke3_q15(foc_abc_t abc);

/* d = alpha cos + beta sin, q = -alpha sin + beta cos. */
foc_dq_t foc_park_q15(foc_ab_t ab, foc_sincos_t sc);

/* alpha = d cos - q sin, beta = d sin + q cos. */
foc_ab_t foc_ipark_q15(foc_dq_t dq, foc_sincos_t sc);

/* Phase values of an alpha/beta vector: a = alpha,
 * b = -alpha/2 + sqrt(3)/2 beta, c = -alpha/2 - sqrt(3)/2 beta. */
foc_abc_t foc_iclarke_q15(foc_ab_t ab);

#endif /* FOC_TRANSFORMS_H */
