/*
 * First-order low-pass filter y(n) = y(n-1) + K (x(n) - y(n-1))
 * (AN1292 equation 7).
 *
 * K: Q15 in (0, 1]; K = 1 - exp(-Ts/tau) for a time constant tau.  Every
 * filter of the core has a constant K (config.h), passed to each step
 * rather than kept beside the state: no RAM, and an immediate operand.
 * State: Q30 in an int32_t (15 extra fraction bits) so that a small K does
 * not stall the output short of the input.  |state| <= 2^30 and the update
 * lies between the old output and the input, so it cannot overflow.
 */
#ifndef FOC_LPF_H
#define FOC_LPF_H

#include "foc/q15.h"

typedef struct {
    int32_t state; /* output, Q30 */
} foc_lpf_q15_t;

static inline void foc_lpf_init(foc_lpf_q15_t *f, q15_t y0)
{
    f->state = (int32_t)y0 * (int32_t)32768;
}

/* Current output, Q15. */
static inline q15_t foc_lpf_out(const foc_lpf_q15_t *f)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return (q15_t)(f->state >> 15);
}

/* One update toward x with the constant k; returns the new output, Q15. */
static inline q15_t foc_lpf_step(foc_lpf_q15_t *f, q15_t x, q15_t k)
{
    const int32_t err = (int32_t)x - (int32_t)foc_lpf_out(f); /* 17 bits */
    f->state += (int32_t)k * err; /* |k * err| < 2^31 */
    return foc_lpf_out(f);
}

#endif /* FOC_LPF_H */
