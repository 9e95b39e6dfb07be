/*
 * Clarke, Park and inverse transforms, amplitude-invariant.
 *
 * Each output is a sum of Q15 x Q15 products.  The products are taken in
 * Q29 (the Q30 product halved), so that a sum of up to three of them stays
 * below 2^31 for any inputs, then rounded to Q15 and saturated.  Halving
 * drops at most 2^-16 LSB of the result.
 */
#include "foc/transforms.h"

#define ONE_THIRD Q15(1.0 / 3.0)                 /* 10923 */
#define INV_SQRT3 Q15(0.57735026918962576)       /* 1/sqrt(3), 18919 */
#define HALF_SQRT3 Q15(0.86602540378443865)      /* sqrt(3)/2, 28378 */
#define HALF Q15(0.5)                            /* 16384 */

/* a * b, Q29, |result| <= 2^29. */
static int32_t mul_q29(q15_t a, q15_t b)
{
    return ((int32_t)a * (int32_t)b) >> 1;
}

/* Q29 -> Q15, rounded to nearest, saturated; |x| <= 3 * 2^29. */
static q15_t q29_to_q15(int32_t x)
{
    return foc_sat_q15((x + 0x2000) >> 14);
}

foc_ab_t foc_clarke2_q15(q15_t a, q15_t b)
{
    foc_ab_t ab;
    ab.alpha = a;
    ab.beta = q29_to_q15(mul_q29(a, INV_SQRT3) + 2 * mul_q29(b, INV_SQRT3));
    return ab;
}

foc_ab_t foc_clarke3_q15(foc_abc_t abc)
{
    foc_ab_t ab;
    /* alpha = a - (a + b + c) / 3: the error of the 1/3 constant then only
     * scales the zero sequence, which is small. */
    ab.alpha = q29_to_q15((int32_t)abc.a * 16384
                          - mul_q29(abc.a, ONE_THIRD)
                          - mul_q29(abc.b, ONE_THIRD)
                          - mul_q29(abc.c, ONE_THIRD));
    ab.beta = q29_to_q15(mul_q29(abc.b, INV_SQRT3)
                         - mul_q29(abc.c, INV_SQRT3));
    return ab;
}

foc_dq_t foc_park_q15(foc_ab_t ab, foc_sincos_t sc)
{
    foc_dq_t dq;
    dq.d = q29_to_q15(mul_q29(ab.alpha, sc.cos) + mul_q29(ab.beta, sc.sin));
    dq.q = q29_to_q15(mul_q29(ab.beta, sc.cos) - mul_q29(ab.alpha, sc.sin));
    return dq;
}

foc_ab_t foc_ipark_q15(foc_dq_t dq, foc_sincos_t sc)
{
    foc_ab_t ab;
    ab.alpha = q29_to_q15(mul_q29(dq.d, sc.cos) - mul_q29(dq.q, sc.sin));
    ab.beta = q29_to_q15(mul_q29(dq.d, sc.sin) + mul_q29(dq.q, sc.cos));
    return ab;
}

foc_abc_t foc_iclarke_q15(foc_ab_t ab)
{
    const int32_t half_alpha = mul_q29(ab.alpha, HALF);       /* Q29 */
    const int32_t beta_part = mul_q29(ab.beta, HALF_SQRT3);   /* Q29 */
    foc_abc_t abc;
    abc.a = ab.alpha;
    abc.b = q29_to_q15(beta_part - half_alpha);
    abc.c = q29_to_q15(-beta_part - half_alpha);
    return abc;
}
