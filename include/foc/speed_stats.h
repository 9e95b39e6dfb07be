/*
 * Speed FIFO statistics (ST's start-up convergence and stall tests, seed
 * 002): mean and variance of the last 64 speed samples, and the
 * "reliability" test sigma^2 <= mu^2 x threshold.  Fed at the slow tick
 * with any estimator's speed.
 *
 * Running sums, so a push costs two multiplications whatever the window:
 *   sum    = sum of x                    |sum| <= 64 x 32768 = 2^21
 *   sum_sq = sum of round(x^2 / 64)      0 <= sum_sq <= 64 x 2^24 = 2^30
 * x is Q15, so x^2 is Q30 and sum_sq is the mean of x^2 in Q30 (N = 64
 * and the /64 cancel), within 32 LSB of Q30 (64 roundings of at most 1/2).
 * The same rounded square leaves the sum when its sample does, so the sums
 * stay exact over any number of pushes (no drift).
 *
 * Mean: Q15, rounded.  mu^2: Q30 from the exact sum (no rounding of the
 * mean first), within 1/2 LSB of Q30.  Variance = mean(x^2) - mu^2, Q30,
 * clamped at 0, within 33 LSB of Q30 of the exact one (2^30 = 1.0).
 * No overflow for any input, including full-scale and alternating signs.
 *
 * Until 64 samples have been pushed since the reset, the missing ones
 * count as 0 and foc_speed_stats_reliable() answers 0.
 */
#ifndef FOC_SPEED_STATS_H
#define FOC_SPEED_STATS_H

#include <stdint.h>
#include "foc/q15.h"

#define FOC_SPEED_STATS_LOG2 6u
#define FOC_SPEED_STATS_N (1u << FOC_SPEED_STATS_LOG2) /* 64 samples */

typedef struct {
    q15_t fifo[FOC_SPEED_STATS_N]; /* last 64 samples, Q15 */
    uint8_t next;                  /* slot of the oldest sample */
    uint8_t count;                 /* samples since reset, up to 64 */
    int32_t sum;                   /* sum of x, Q15, |.| <= 2^21 */
    int32_t sum_sq;                /* sum of round(x^2/64), Q30 mean of x^2 */
} foc_speed_stats_t;

/* Empties the FIFO (all samples 0, not reliable until 64 pushes). */
void foc_speed_stats_reset(foc_speed_stats_t *s);

/* Adds one speed sample (Q15), dropping the oldest. */
void foc_speed_stats_push(foc_speed_stats_t *s, q15_t x);

/* Mean of the window, Q15, rounded to nearest. */
q15_t foc_speed_stats_mean(const foc_speed_stats_t *s);

/* mu^2, Q30 (0 .. 2^30). */
int32_t foc_speed_stats_mean_sq(const foc_speed_stats_t *s);

/* sigma^2 = mean(x^2) - mu^2, Q30 (0 .. 2^30). */
int32_t foc_speed_stats_variance(const foc_speed_stats_t *s);

/* 1 if 64 samples are in and sigma^2 <= mu^2 x threshold (threshold Q15,
 * >= 0; ST's VARIANCE_THRESHOLD 0.0625 is Q15(0.0625)); else 0.  A window
 * of equal samples, zeros included, is reliable: callers check the mean. */
uint8_t foc_speed_stats_reliable(const foc_speed_stats_t *s, q15_t threshold);

#endif /* FOC_SPEED_STATS_H */
