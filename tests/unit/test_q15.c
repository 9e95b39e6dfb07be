/*
 * Q15/Q31 primitives (foc/q15.h) against exact integer or double references.
 */
#include <math.h>
#include <stdint.h>

#include "foc/q15.h"
#include "testkit.h"

/* Every value of the first operand on this stride (plus the edges) is
 * paired with every value of the second: dense, and fast enough. */
#define STRIDE 61

static const int32_t EDGES[] = { -32768, -32767, -16384, -1, 0, 1, 16384,
                                 32766, 32767 };

static int32_t clamp_q15(double x)
{
    return (x > 32767.0) ? 32767 : (x < -32768.0) ? -32768 : (int32_t)x;
}

/* Calls check(a, b) for a on the stride and the edges, b over all Q15. */
static void for_dense_pairs(void (*check)(q15_t a, q15_t b))
{
    for (int32_t a = -32768; a <= 32767; a += STRIDE) {
        for (int32_t b = -32768; b <= 32767; b++) {
            check((q15_t)a, (q15_t)b);
        }
    }
    for (size_t i = 0; i < sizeof EDGES / sizeof EDGES[0]; i++) {
        for (int32_t b = -32768; b <= 32767; b++) {
            check((q15_t)EDGES[i], (q15_t)b);
        }
    }
}

static void case_sat(void)
{
    static const int32_t big[] = { INT32_MIN, -65536, -32769, 32768, 65536,
                                   INT32_MAX };
    for (int32_t x = -32768; x <= 32767; x++) {
        TK_CHECK(foc_sat_q15(x) == x, "x=%ld", (long)x);
    }
    for (size_t i = 0; i < sizeof big / sizeof big[0]; i++) {
        const q15_t want = (big[i] > 0) ? Q15_MAX : Q15_MIN;
        TK_CHECK(foc_sat_q15(big[i]) == want, "x=%ld", (long)big[i]);
    }
}

static int add_sub_errors;

static void check_add_sub(q15_t a, q15_t b)
{
    if (foc_add_q15(a, b) != clamp_q15((double)a + b)
        || foc_sub_q15(a, b) != clamp_q15((double)a - b)) {
        if (add_sub_errors++ < 5) {
            TK_CHECK(0, "a=%d b=%d add=%d sub=%d", a, b, foc_add_q15(a, b),
                     foc_sub_q15(a, b));
        }
    }
}

static void case_add_sub(void)
{
    add_sub_errors = 0;
    for_dense_pairs(check_add_sub);
    TK_CHECK(add_sub_errors == 0, "%d mismatches", add_sub_errors);
}

/* round(a * b * 2^shift / 2^15), half up, saturated; exact in double. */
static int32_t ref_mul(q15_t a, q15_t b, unsigned shift)
{
    return clamp_q15(floor((double)a * b * ldexp(1.0, (int)shift) / 32768.0
                           + 0.5));
}

static int mul_errors;

static void check_mul(q15_t a, q15_t b)
{
    if (foc_mul_q15(a, b) != ref_mul(a, b, 0)) {
        if (mul_errors++ < 5) {
            TK_CHECK(0, "a=%d b=%d got=%d want=%ld", a, b, foc_mul_q15(a, b),
                     (long)ref_mul(a, b, 0));
        }
    }
}

static void case_mul(void)
{
    mul_errors = 0;
    for_dense_pairs(check_mul);
    TK_CHECK(mul_errors == 0, "%d mismatches", mul_errors);
    /* -1 x -1 = +1 saturates; -1 x x = -x; half-LSB products round up. */
    TK_CHECK(foc_mul_q15(Q15_MIN, Q15_MIN) == Q15_MAX, "-1*-1=%d",
             foc_mul_q15(Q15_MIN, Q15_MIN));
    TK_CHECK(foc_mul_q15(Q15_MIN, 12345) == -12345, "-1*x=%d",
             foc_mul_q15(Q15_MIN, 12345));
    TK_CHECK(foc_mul_q15(1, 16384) == 1, "0.5 LSB rounds up: %d",
             foc_mul_q15(1, 16384));
    TK_CHECK(foc_mul_q15(-1, 16384) == 0, "-0.5 LSB rounds up: %d",
             foc_mul_q15(-1, 16384));
}

static void case_mul_shift(void)
{
    int errors = 0;
    for (unsigned shift = 0; shift <= 15; shift++) {
        for (int32_t a = -32768; a <= 32767; a += 127) {
            for (int32_t b = -32768; b <= 32767; b += 13) {
                const q15_t got =
                    foc_mul_q15_shift((q15_t)a, (q15_t)b, (uint8_t)shift);
                if (got != ref_mul((q15_t)a, (q15_t)b, shift) && errors++ < 5) {
                    TK_CHECK(0, "shift=%u a=%ld b=%ld got=%d", shift, (long)a,
                             (long)b, got);
                }
            }
        }
        TK_CHECK(foc_mul_q15_shift(Q15_MIN, Q15_MIN, (uint8_t)shift)
                     == Q15_MAX, "shift=%u -1*-1", shift);
    }
    TK_CHECK(errors == 0, "%d mismatches", errors);
    /* 0.75 * 2^2 = 3: a gain above 1. */
    TK_CHECK(foc_mul_q15_shift(Q15(0.75), 1000, 2) == 3000, "3*1000=%d",
             foc_mul_q15_shift(Q15(0.75), 1000, 2));
}

static int64_t clamp_q31(int64_t x)
{
    return (x > INT32_MAX) ? INT32_MAX : (x < INT32_MIN) ? INT32_MIN : x;
}

static void case_add_q31(void)
{
    static const int32_t edges[] = { INT32_MIN, INT32_MIN + 1, -65536, -1, 0,
                                     1, 65536, INT32_MAX - 1, INT32_MAX };
    const size_t n = sizeof edges / sizeof edges[0];
    for (size_t i = 0; i < n; i++) {
        for (size_t j = 0; j < n; j++) {
            const int64_t want = clamp_q31((int64_t)edges[i] + edges[j]);
            TK_CHECK(foc_add_q31(edges[i], edges[j]) == want, "%ld + %ld",
                     (long)edges[i], (long)edges[j]);
        }
    }
    uint32_t s = 12345u; /* LCG over the whole 32-bit range */
    int errors = 0;
    for (int k = 0; k < 1000000; k++) {
        s = s * 1664525u + 1013904223u;
        const int32_t a = (int32_t)s;
        s = s * 1664525u + 1013904223u;
        const int32_t b = (int32_t)s;
        if (foc_add_q31(a, b) != clamp_q31((int64_t)a + b) && errors++ < 5) {
            TK_CHECK(0, "%ld + %ld", (long)a, (long)b);
        }
    }
    TK_CHECK(errors == 0, "%d mismatches", errors);
}

static void case_q15_macro(void)
{
    /* As constant expressions (what the macro is for). */
    static const q15_t c[] = { Q15(0.5), Q15(-0.5), Q15(1.0), Q15(-1.0),
                               Q15(2.0), Q15(-3.0), Q15(1.0 / 3.0),
                               Q15(-1.0 / 3.0), Q15(0.0) };
    static const q15_t want[] = { 16384, -16384, 32767, -32768, 32767,
                                  -32768, 10923, -10923, 0 };
    for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
        TK_CHECK(c[i] == want[i], "[%zu] %d != %d", i, c[i], want[i]);
    }
    /* Every Q15 value, and rounding to nearest from either side (half
     * away from zero), symmetric for negative values. */
    for (int32_t i = -32768; i <= 32767; i++) {
        TK_CHECK(Q15(i / 32768.0) == i, "exact %ld", (long)i);
        TK_CHECK(Q15((i - 0.49) / 32768.0) == i, "below %ld", (long)i);
        if (i < 32767) {
            TK_CHECK(Q15((i + 0.49) / 32768.0) == i, "above %ld", (long)i);
        }
    }
    TK_CHECK(Q15(0.5 / 32768.0) == 1 && Q15(-0.5 / 32768.0) == -1,
             "half LSB: %d %d", Q15(0.5 / 32768.0), Q15(-0.5 / 32768.0));
    TK_CHECK(Q15(32767.6 / 32768.0) == 32767, "near +1: %d",
             Q15(32767.6 / 32768.0));
}

static void case_abs(void)
{
    for (int32_t a = -32767; a <= 32767; a++) {
        TK_CHECK(foc_abs_q15((q15_t)a) == (a < 0 ? -a : a), "a=%ld", (long)a);
    }
    TK_CHECK(foc_abs_q15(Q15_MIN) == Q15_MAX, "|-1|=%d",
             foc_abs_q15(Q15_MIN));
}

/* a x mant / 2^rshift against the exactly rounded value (half up), for
 * every a and a spread of mantissas and shifts, extremes included. */
static void case_mul_norm32(void)
{
    static const q15_t mants[] = { 16384, 20560, 24577, 32767 };
    static const uint8_t shifts[] = { 1, 4, 15, 30 };
    for (size_t m = 0; m < sizeof mants / sizeof mants[0]; m++) {
        for (size_t s = 0; s < sizeof shifts / sizeof shifts[0]; s++) {
            for (int32_t a = -32768; a <= 32767; a++) {
                const double x = (double)a * mants[m] / (double)(1L << shifts[s]);
                const int32_t want = (int32_t)floor(x + 0.5);
                const int32_t got = foc_mul_norm32((q15_t)a, mants[m], shifts[s]);
                TK_CHECK(got == want, "a=%ld mant=%d rshift=%u: %ld != %ld", (long)a, mants[m],
                         shifts[s], (long)got, (long)want);
            }
        }
    }
}

/* Q31 -> Q15: round half up, saturate at the top. */
static void case_q31_to_q15(void)
{
    static const int32_t xs[] = { 0, 32767, 32768, 65535, 65536, -32768, -32769, -65536,
                                  INT32_MAX, INT32_MIN, 0x7FFF7FFF, 0x7FFF8000 };
    for (size_t i = 0; i < sizeof xs / sizeof xs[0]; i++) {
        double want = floor((double)xs[i] / 65536.0 + 0.5);
        want = want > 32767.0 ? 32767.0 : want;
        TK_CHECK(foc_q31_to_q15(xs[i]) == (q15_t)want, "x=%ld: %d != %.0f", (long)xs[i],
                 foc_q31_to_q15(xs[i]), want);
    }
}

TK_CASES(TK_CASE(case_sat), TK_CASE(case_add_sub), TK_CASE(case_mul),
         TK_CASE(case_mul_shift), TK_CASE(case_add_q31),
         TK_CASE(case_q15_macro), TK_CASE(case_abs), TK_CASE(case_mul_norm32),
         TK_CASE(case_q31_to_q15))
