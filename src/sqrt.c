/*
 * Integer square root and vector magnitude.
 */
#include "foc/sqrt.h"

uint16_t foc_isqrt32(uint32_t x)
{
    /* Restoring bit-by-bit method, one result bit per iteration from the
     * top: `bit` is the square of the trial bit (4^15 down to 4^0); `root`
     * holds the result found so far, scaled by the trial bit; `rem` is x
     * minus the square of the result so far. */
    uint32_t rem = x;
    uint32_t root = 0u;
    uint32_t bit = 1uL << 30;

    while (bit != 0u) {
        if (rem >= root + bit) {
            rem -= root + bit;
            root = (root >> 1) + bit;
        } else {
            root >>= 1;
        }
        bit >>= 2;
    }
    return (uint16_t)root; /* floor(sqrt(x)) <= 65535 */
}

q15_t foc_mag_q15(q15_t x, q15_t y)
{
    /* Sum of squares, Q30, at most 2 * 2^30 = 2^31: fits uint32_t. */
    const uint32_t sq = (uint32_t)((int32_t)x * (int32_t)x)
                      + (uint32_t)((int32_t)y * (int32_t)y);
    const uint16_t m = foc_isqrt32(sq); /* Q15, rounded down, <= 46341 */
    return (m > 32767u) ? Q15_MAX : (q15_t)m;
}
