/*
 * The 32-bit angle accumulators (2^32 counts = 360 electrical degrees) of
 * the estimators, the speed observer and the start-up's forced angle: the
 * angle a Q15 speed turns in one PWM period, speed x 2 FOC_DTHETA_AT_BASE
 * counts, as speed x FOC_THETA32_MANT >> FOC_THETA32_RSHIFT (config.h).
 */
#ifndef FOC_THETA32_H
#define FOC_THETA32_H

#include "foc/config.h"
#include "foc/q15.h"

/* |speed x FOC_THETA32_MANT| < 2^30; the arithmetic shift floors, less
 * than one count of 2^32 per period. */
static inline int32_t foc_theta32_step(q15_t speed)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return ((int32_t)speed * FOC_THETA32_MANT) >> FOC_THETA32_RSHIFT;
}

#endif /* FOC_THETA32_H */
