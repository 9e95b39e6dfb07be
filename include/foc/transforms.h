/*
 * Clarke, Park and inverse transforms, amplitude-invariant (a phase
 * amplitude of 1 gives a vector of magnitude 1).  All inputs and outputs Q15
 * per-unit; results rounded and saturated to Q15.
 *
 * Each output is a sum of Q15 x Q15 products.  The products are taken in
 * Q29 (the Q30 product halved), so that a sum of up to three of them stays
 * below 2^31 for any inputs, then rounded to Q15 and saturated.  Halving
 * drops at most 2^-16 LSB of the result.  Inline: the fast step uses each
 * of them every period.
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

#define FOC_ONE_THIRD Q15(1.0 / 3.0)              /* 10923 */
#define FOC_INV_SQRT3 Q15(0.57735026918962576)    /* 1/sqrt(3), 18919 */
#define FOC_HALF_SQRT3 Q15(0.86602540378443865)   /* sqrt(3)/2, 28378 */

/* a * b, Q29, |result| <= 2^29. */
static inline int32_t foc_mul_q29(q15_t a, q15_t b)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return ((int32_t)a * (int32_t)b) >> 1;
}

/* Q29 -> Q15, rounded to nearest, saturated; |x| <= 3 * 2^29. */
static inline q15_t foc_q29_to_q15(int32_t x)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return foc_sat_q15((x + 0x2000) >> 14);
}

/* From phases a and b of a balanced set (c = -a - b):
 * alpha = a, beta = (a + 2 b) / sqrt(3). */
static inline foc_ab_t foc_clarke2_q15(q15_t a, q15_t b)
{
    foc_ab_t ab;
    ab.alpha = a;
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    ab.beta = foc_q29_to_q15(foc_mul_q29(a, FOC_INV_SQRT3) + 2 * foc_mul_q29(b, FOC_INV_SQRT3));
    return ab;
}

/* From three measured phases, zero sequence removed:
 * alpha = (2a - b - c) / 3, beta = (b - c) / sqrt(3).  Written as
 * alpha = a - (a + b + c) / 3: the error of the 1/3 constant then only
 * scales the zero sequence, which is small. */
static inline foc_ab_t foc_clarke3_q15(foc_abc_t abc)
{
    /* |sum| < 2^17 and |b - c| <= 2^16: the products fit int32_t */
    const int32_t sum = (int32_t)abc.a + abc.b + abc.c;
    foc_ab_t ab;
    /* cppcheck-suppress [misra-c2012-10.1, misra-c2012-10.8] ; D1 Q-format shift, D2 compile-time constant */
    ab.alpha = foc_q29_to_q15((int32_t)abc.a * 16384 - ((sum * FOC_ONE_THIRD) >> 1));
    /* cppcheck-suppress [misra-c2012-10.1, misra-c2012-10.8] ; D1 Q-format shift, D2 compile-time constant */
    ab.beta = foc_q29_to_q15((((int32_t)abc.b - abc.c) * FOC_INV_SQRT3) >> 1);
    return ab;
}

/* d = alpha cos + beta sin, q = -alpha sin + beta cos. */
static inline foc_dq_t foc_park_q15(foc_ab_t ab, foc_sincos_t sc)
{
    foc_dq_t dq;
    dq.d = foc_q29_to_q15(foc_mul_q29(ab.alpha, sc.cos) + foc_mul_q29(ab.beta, sc.sin));
    dq.q = foc_q29_to_q15(foc_mul_q29(ab.beta, sc.cos) - foc_mul_q29(ab.alpha, sc.sin));
    return dq;
}

/* alpha = d cos - q sin, beta = d sin + q cos. */
static inline foc_ab_t foc_ipark_q15(foc_dq_t dq, foc_sincos_t sc)
{
    foc_ab_t ab;
    ab.alpha = foc_q29_to_q15(foc_mul_q29(dq.d, sc.cos) - foc_mul_q29(dq.q, sc.sin));
    ab.beta = foc_q29_to_q15(foc_mul_q29(dq.d, sc.sin) + foc_mul_q29(dq.q, sc.cos));
    return ab;
}

/* Phase values of an alpha/beta vector: a = alpha,
 * b = -alpha/2 + sqrt(3)/2 beta, c = -alpha/2 - sqrt(3)/2 beta. */
static inline foc_abc_t foc_iclarke_q15(foc_ab_t ab)
{
    const int32_t half_alpha = (int32_t)ab.alpha * 8192;              /* Q29 */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const int32_t beta_part = foc_mul_q29(ab.beta, FOC_HALF_SQRT3);   /* Q29 */
    foc_abc_t abc;
    abc.a = ab.alpha;
    abc.b = foc_q29_to_q15(beta_part - half_alpha);
    abc.c = foc_q29_to_q15(-beta_part - half_alpha);
    return abc;
}

#endif /* FOC_TRANSFORMS_H */
