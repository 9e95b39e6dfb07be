#include "foc/mtpa.h"
#include "foc/sqrt.h"

#define X_ONE_Q12 ((int32_t)4096)
#define X_MAX_Q12 ((int32_t)32767) /* 8.0 */

q15_t foc_mtpa_id_q15(q15_t iq, q15_t k_q12)
{
    const int32_t iq_abs = foc_abs_q15(iq);
    /* x = k |iq|: Q15 x Q12 >> 15, <= 2^27 before the hold */
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    int32_t x = (iq_abs * (int32_t)k_q12) >> 15;
    if (x > X_MAX_Q12) {
        x = X_MAX_Q12;
    }
    if (x <= 0) {
        return 0;
    }
    /* 1 + x^2 in Q24: <= 2^24 + 2^30; its root Q12, <= 33026 */
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    const uint32_t one_x2 = (uint32_t)(X_ONE_Q12 * X_ONE_Q12) + (uint32_t)(x * x);
    const int32_t den = X_ONE_Q12 + (int32_t)foc_isqrt32(one_x2); /* Q12, > x */
    const int32_t r = (x * 32768) / den;                          /* Q15, < 32768 */
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return (q15_t)(-((iq_abs * r) >> 15));
}
