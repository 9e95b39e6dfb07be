/*
 * Q15/Q31 fixed-point primitives.
 *
 * q15_t: signed 16-bit, value = raw / 32768, range [-1, 1 - 2^-15].
 * q31_t: signed 32-bit, value = raw / 2^31.
 *
 * Every function here is written for a 16-bit `int` (dsPIC33) as well as a
 * 32-bit one: operands are widened to int32_t explicitly before any product,
 * and no left shift is applied to a negative value (a multiplication is used
 * instead, which compilers turn into the same shift).  Right shifts of
 * negative values are arithmetic on every compiler we target (GCC, XC16);
 * that is implementation-defined, not undefined, behaviour.
 */
#ifndef FOC_Q15_H
#define FOC_Q15_H

#include <stdint.h>

typedef int16_t q15_t;
typedef int32_t q31_t;

/* A function off the per-period path that the compiler must not inline
 * into it (inlined, its locals and saved registers cost every period). */
#if defined(__GNUC__)
#define FOC_COLD __attribute__((noinline, cold))
#else
#define FOC_COLD
#endif

/* A small step of the per-period path that another caller shares: inlined
 * everywhere, so the second caller never turns it into a call (with its
 * saved registers) on the per-period path. */
#if defined(__GNUC__)
#define FOC_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define FOC_ALWAYS_INLINE inline
#endif

#define Q15_MAX ((q15_t)32767)
#define Q15_MIN ((q15_t)-32768)

/* Compile-time Q15 literal from a double in [-1, 1); rounds to nearest and
 * clamps +1.0 to the largest Q15 value.  Only for constant expressions. */
#define Q15(x)                                                                 \
    ((q15_t)(((x) >= 0.99998474121) ? 32767                                    \
             : ((x) <= -1.0)        ? -32768                                   \
             : ((x) >= 0.0) ? (int32_t)((x) * 32768.0 + 0.5)                   \
                            : -(int32_t)(-(x) * 32768.0 + 0.5)))

/* Saturate a 32-bit value to Q15.  Cortex-M3 and later have a one-cycle
 * SSAT (GCC and clang: __builtin_arm_ssat); elsewhere the portable compare, which gives the same
 * result for every input (the bench's Cortex-M3 replay checks it bit for
 * bit against the host build). */
static inline q15_t foc_sat_q15_portable(int32_t x)
{
    /* In range when the high half is the low half's sign extension: one
     * 16-bit compare on a 16-bit machine, where x > 32767 and x < -32768
     * are two 32-bit compares and two branches (the dsPIC33 estimate). */
    const q15_t lo = (q15_t)x; /* two's complement: the low half */
    if ((int32_t)lo == x) {
        return lo;
    }
    return (x < 0) ? Q15_MIN : Q15_MAX;
}

static inline q15_t foc_sat_q15(int32_t x)
{
#if defined(__ARM_FEATURE_SAT) && defined(__GNUC__) && !defined(FOC_PORTABLE_ONLY)
    return (q15_t)__builtin_arm_ssat(x, 16);
#else
    return foc_sat_q15_portable(x);
#endif
}

/* x limited to [-2^(bits-1), 2^(bits-1) - 1], bits a constant in 1..31:
 * one SSAT on Cortex-M3, compares elsewhere (the same result). */
static inline int32_t foc_sat_bits_portable(int32_t x, unsigned bits)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    const int32_t hi = (int32_t)((1UL << (bits - 1u)) - 1u);
    return (x > hi) ? hi : (x < -hi - 1) ? (-hi - 1) : x;
}

#if defined(__ARM_FEATURE_SAT) && defined(__GNUC__) && !defined(FOC_PORTABLE_ONLY)
#define FOC_SAT_BITS(x, bits) ((int32_t)__builtin_arm_ssat((x), (bits)))
#else
#define FOC_SAT_BITS(x, bits) foc_sat_bits_portable((x), (bits))
#endif

/* Saturating Q15 addition and subtraction (the 32-bit sum cannot overflow). */
static inline q15_t foc_add_q15(q15_t a, q15_t b)
{
    return foc_sat_q15((int32_t)a + (int32_t)b);
}

static inline q15_t foc_sub_q15(q15_t a, q15_t b)
{
    return foc_sat_q15((int32_t)a - (int32_t)b);
}

/* Q15 x Q15 -> Q15, rounded to nearest (half up), saturated: only
 * -1 x -1 = +1 saturates, to 32767.  The Q30 product fits int32_t. */
static inline q15_t foc_mul_q15(q15_t a, q15_t b)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return foc_sat_q15(((int32_t)a * (int32_t)b + (int32_t)0x4000) >> 15);
}

/* Q15 x Q15 with a gain exponent: (a * b * 2^shift) / 2^15, rounded,
 * saturated.  Lets a gain above 1 be held as a Q15 mantissa and a shift
 * (0 <= shift <= 15).  The Q30 product is at most 2^30 in magnitude; it is
 * shifted right by (15 - shift) so no left shift of a signed value occurs. */
static inline q15_t foc_mul_q15_shift(q15_t a, q15_t b, uint8_t shift)
{
    const int32_t p = (int32_t)a * (int32_t)b;
    const uint8_t r = (uint8_t)(15u - shift);
    if (r == 0u) {
        return foc_sat_q15(p);
    }
    /* cppcheck-suppress [misra-c2012-10.1, misra-c2012-10.7] ; D1 Q-format shift */
    return foc_sat_q15((p + (int32_t)(1L << (r - 1u))) >> r);
}

/* a x b x 2^shift in Q30 (a, b Q15; 0 <= shift <= 15): the product
 * multiplied (never shifted left), limited to +-2^30 (one per unit). */
static inline int32_t foc_mul_q30_shift(q15_t a, q15_t b, uint8_t shift)
{
    const int32_t p = (int32_t)a * (int32_t)b; /* |p| <= 2^30 */
    if (shift == 0u) {
        return p;
    }
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t limit = ((int32_t)1 << 30) >> shift;
    if (p > limit) {
        return (int32_t)0x40000000; /* 2^30 */
    }
    if (p < -limit) {
        return -(int32_t)0x40000000;
    }
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return p * ((int32_t)1 << shift);
}

/* Saturating Q31 addition (for integrators). */
static inline q31_t foc_add_q31(q31_t a, q31_t b)
{
    if ((b > 0) && (a > (INT32_MAX - b))) {
        return INT32_MAX;
    }
    if ((b < 0) && (a < (INT32_MIN - b))) {
        return INT32_MIN;
    }
    return a + b;
}

/* `from` moved toward `to` by at most `step` (> 0): a slew-rate limit.
 * The result lies between `from` and `to`, so it cannot overflow. */
static inline q15_t foc_slew_q15(q15_t from, q15_t to, q15_t step)
{
    const int32_t diff = (int32_t)to - (int32_t)from;
    if (diff > step) {
        return (q15_t)(from + step);
    }
    if (diff < -(int32_t)step) {
        return (q15_t)(from - step);
    }
    return to;
}

/* Absolute value with -32768 mapped to 32767. */
static inline q15_t foc_abs_q15(q15_t a)
{
    return (a < 0) ? foc_sat_q15(-(int32_t)a) : a;
}

/* a x mant / 2^rshift, rounded to nearest (half up), as a 32-bit value.
 * Holds a constant of any size with 15 significant bits: a Q15 mantissa in
 * [0.5, 1) and a right shift 1..30 (config.h FOC_NORM_MANT/FOC_NORM_RSHIFT).
 * |a * mant| <= 2^30, so the product and the rounding term fit int32_t. */
static inline int32_t foc_mul_norm32(q15_t a, q15_t mant, uint8_t rshift)
{
    const int32_t p = (int32_t)a * (int32_t)mant;
    /* cppcheck-suppress [misra-c2012-10.1, misra-c2012-10.7] ; D1 Q-format shift */
    return (p + (int32_t)(1L << (rshift - 1u))) >> rshift;
}

/* Q31 -> Q15, rounded to nearest (half up), saturated (INT32_MAX gives
 * 32767, not 32768). */
static inline q15_t foc_q31_to_q15(q31_t x)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return foc_sat_q15(((x >> 15) + 1) >> 1);
}

#endif /* FOC_Q15_H */
