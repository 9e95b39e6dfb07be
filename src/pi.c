/*
 * PI controller with back-calculation anti-windup; see foc/pi.h (the
 * per-period parts are inline there).
 */
#include "foc/pi.h"

void foc_pi_init(foc_pi_q15_t *pi, q15_t out_min, q15_t out_max)
{
    pi->out_min = out_min;
    pi->out_max = out_max;
    pi->integ = 0;
    foc_pi_clamp_integ(pi); /* for limits that exclude 0 */
}
