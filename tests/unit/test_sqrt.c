/*
 * Integer square root and vector magnitude against exact integer checks.
 */
#include <math.h>
#include <stdint.h>

#include "foc/sqrt.h"
#include "testkit.h"

/* r == floor(sqrt(x)) exactly: r^2 <= x < (r + 1)^2, in 64 bits. */
static int is_floor_sqrt(uint32_t x, uint32_t r)
{
    const uint64_t lo = (uint64_t)r * r;
    const uint64_t hi = (uint64_t)(r + 1u) * (r + 1u);
    return lo <= x && x < hi;
}

static int isqrt_errors;

static void check_isqrt(uint32_t x)
{
    const uint16_t r = foc_isqrt32(x);
    if (!is_floor_sqrt(x, r) && isqrt_errors++ < 5) {
        TK_CHECK(0, "isqrt(%lu) = %u", (unsigned long)x, r);
    }
}

/* Every x below 2^20, then the whole range on a prime stride. */
static void case_isqrt_stride(void)
{
    isqrt_errors = 0;
    for (uint32_t x = 0; x < (1u << 20); x++) {
        check_isqrt(x);
    }
    for (uint64_t x = 1u << 20; x <= UINT32_MAX; x += 1021u) {
        check_isqrt((uint32_t)x);
    }
    check_isqrt(UINT32_MAX);
    TK_CHECK(foc_isqrt32(UINT32_MAX) == 65535u, "isqrt(2^32-1) = %u",
             foc_isqrt32(UINT32_MAX));
    TK_CHECK(isqrt_errors == 0, "%d errors", isqrt_errors);
}

/* All perfect squares and their neighbours, where floor() changes. */
static void case_isqrt_squares(void)
{
    isqrt_errors = 0;
    for (uint32_t n = 0; n <= 65535u; n++) {
        const uint32_t sq = n * n;
        TK_CHECK(foc_isqrt32(sq) == n, "isqrt(%lu^2) = %u", (unsigned long)n,
                 foc_isqrt32(sq));
        if (n > 0u) {
            TK_CHECK(foc_isqrt32(sq - 1u) == n - 1u, "isqrt(%lu^2 - 1)",
                     (unsigned long)n);
        }
        check_isqrt(sq + 1u);
    }
    TK_CHECK(isqrt_errors == 0, "%d errors", isqrt_errors);
}

/* floor(|v|) on a grid over the whole Q15 square (saturated at 32767),
 * with the -32768 corners. */
static void case_mag(void)
{
    int errors = 0;
    for (int32_t x = -32768; x <= 32767; x += 37) {
        for (int32_t y = -32768; y <= 32767; y += 41) {
            const double m = floor(sqrt((double)x * x + (double)y * y));
            const q15_t want = (q15_t)fmin(m, 32767.0);
            const q15_t got = foc_mag_q15((q15_t)x, (q15_t)y);
            if (got != want && errors++ < 5) {
                TK_CHECK(0, "|(%ld, %ld)| = %d, want %d", (long)x, (long)y,
                         got, want);
            }
        }
    }
    TK_CHECK(errors == 0, "%d errors", errors);
    TK_CHECK(foc_mag_q15(-32768, -32768) == 32767, "corner");
    TK_CHECK(foc_mag_q15(-32768, 0) == 32767, "-1 saturates");
    TK_CHECK(foc_mag_q15(0, 0) == 0, "zero");
    TK_CHECK(foc_mag_q15(-3, 4) == 5, "3-4-5");
    TK_CHECK(foc_mag_q15(23170, 23170) == 32767, "45 deg full scale: %d",
             foc_mag_q15(23170, 23170));
}

TK_CASES(TK_CASE(case_isqrt_stride), TK_CASE(case_isqrt_squares),
         TK_CASE(case_mag))
