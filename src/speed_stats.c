#include "foc/speed_stats.h"

/* round(x^2 / 64): x^2 <= 2^30, the result <= 2^24 (non-negative, so the
 * shift is of a non-negative value). */
static int32_t square_64(q15_t x)
{
    const int32_t sq = (int32_t)x * (int32_t)x;
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return (sq + ((int32_t)1 << (FOC_SPEED_STATS_LOG2 - 1u))) >> FOC_SPEED_STATS_LOG2;
}

void foc_speed_stats_reset(foc_speed_stats_t *s)
{
    for (unsigned k = 0; k < FOC_SPEED_STATS_N; k++) {
        s->fifo[k] = 0;
    }
    s->next = 0;
    s->count = 0;
    s->sum = 0;
    s->sum_sq = 0;
}

void foc_speed_stats_push(foc_speed_stats_t *s, q15_t x)
{
    const q15_t old = s->fifo[s->next];
    /* Each sum stays within its documented range after the swap. */
    s->sum += (int32_t)x - (int32_t)old;
    s->sum_sq += square_64(x) - square_64(old);
    s->fifo[s->next] = x;
    s->next = (uint8_t)((s->next + 1u) & (FOC_SPEED_STATS_N - 1u));
    if (s->count < FOC_SPEED_STATS_N) {
        s->count++;
    }
}

q15_t foc_speed_stats_mean(const foc_speed_stats_t *s)
{
    /* sum in [-2^21, 64 x 32767]: the rounded mean fits Q15. */
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return (q15_t)((s->sum + ((int32_t)1 << (FOC_SPEED_STATS_LOG2 - 1u))) >>
                   FOC_SPEED_STATS_LOG2);
}

int32_t foc_speed_stats_mean_sq(const foc_speed_stats_t *s)
{
    /* mu = q + r/64 with q = floor(sum/64), 0 <= r < 64:
     * mu^2 = q^2 + (128 q r + r^2) / 4096, the second term rounded
     * (|128 q r| < 2^29).  |q| <= 2^15 so q^2 <= 2^30; at the extremes of
     * sum r = 0, so the total stays <= 2^30. */
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t q = s->sum >> FOC_SPEED_STATS_LOG2;
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const int32_t r = s->sum - q * (int32_t)FOC_SPEED_STATS_N;
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t mu2 = q * q + ((128 * q * r + r * r + 2048) >> 12);
    return (mu2 > 0) ? mu2 : 0;
}

int32_t foc_speed_stats_variance(const foc_speed_stats_t *s)
{
    const int32_t v = s->sum_sq - foc_speed_stats_mean_sq(s);
    return (v > 0) ? v : 0;
}

uint8_t foc_speed_stats_reliable(const foc_speed_stats_t *s, q15_t threshold)
{
    if (s->count < FOC_SPEED_STATS_N || threshold < 0) {
        return 0;
    }
    /* mu^2 x threshold, Q30: mu^2 split at bit 15 so each product < 2^30. */
    const int32_t mu2 = foc_speed_stats_mean_sq(s);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t hi = mu2 >> 15;
    const int32_t lo = mu2 & 0x7FFF;
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t limit = hi * (int32_t)threshold + ((lo * (int32_t)threshold) >> 15);
    return (uint8_t)(foc_speed_stats_variance(s) <= limit);
}
