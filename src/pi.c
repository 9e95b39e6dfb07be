/*
 * PI controller with back-calculation anti-windup; see foc/pi.h (the
 * per-period parts are inline there).
 */
#include "foc/pi.h"

void foc_pi_init(foc_pi_q15_t *pi, q15_t kp, uint8_t kp_shift, q15_t ki,
                 uint8_t ki_shift, q15_t kc, q15_t out_min, q15_t out_max)
{
    pi->kp = kp;
    pi->kp_rshift = (uint8_t)(15u - kp_shift);
    pi->ki = ki;
    pi->ki_shift = ki_shift;
    pi->kc = kc;
    pi->out_min = out_min;
    pi->out_max = out_max;
    pi->integ = 0;
    foc_pi_clamp_integ(pi); /* for limits that exclude 0 */
}
