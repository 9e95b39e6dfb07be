/*
 * Integer square root and vector magnitude.
 */
#include "foc/sqrt.h"

unsigned foc_bit_length(uint32_t x)
{
#if defined(__GNUC__) && (UINT32_MAX == 0xFFFFFFFFuL) && (__SIZEOF_INT__ == 4)
    return 32u - (unsigned)__builtin_clz(x);   /* CLZ on Cortex-M3 */
#elif defined(__GNUC__) && (__SIZEOF_LONG__ == 4)
    return 32u - (unsigned)__builtin_clzl(x);  /* 16-bit int, 32-bit long */
#else
    unsigned n = 0u;
    while (x != 0u) {
        x >>= 1;
        n++;
    }
    return n;
#endif
}

uint16_t foc_isqrt32(uint32_t x)
{
    if (x == 0u) {
        return 0u;
    }
    /* a = 2^h >= sqrt(x) with h = ceil(bits / 2); its Newton step
     * (a + x / a) / 2 costs only a shift and is still >= floor(sqrt(x))
     * (arithmetic-geometric mean), within 25 % of it. */
    const unsigned h = (foc_bit_length(x) + 1u) >> 1; /* 1..16 */
    uint32_t y = (((uint32_t)1 << h) + (x >> h)) >> 1;
    /* From above, integer Newton decreases strictly until it reaches
     * floor(sqrt(x)), where the next step would not decrease. */
    for (;;) {
        const uint32_t next = (y + x / y) >> 1;
        if (next >= y) {
            return (uint16_t)y;
        }
        y = next;
    }
}

q15_t foc_mag_q15(q15_t x, q15_t y)
{
    /* Sum of squares, Q30, at most 2 * 2^30 = 2^31: fits uint32_t. */
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    const uint32_t sq = (uint32_t)((int32_t)x * (int32_t)x)
                      /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
                      + (uint32_t)((int32_t)y * (int32_t)y);
    const uint16_t m = foc_isqrt32(sq); /* Q15, rounded down, <= 46341 */
    return (m > 32767u) ? Q15_MAX : (q15_t)m;
}
