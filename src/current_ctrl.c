#include "foc/current_ctrl.h"
#include "foc/config.h"

void foc_cc_init(foc_current_ctrl_t *cc)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    foc_pi_init(&cc->pi_d, (q15_t)-FOC_VOLTAGE_LIMIT, FOC_VOLTAGE_LIMIT);
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    foc_pi_init(&cc->pi_q, (q15_t)-FOC_VOLTAGE_LIMIT, FOC_VOLTAGE_LIMIT);
    cc->pull_integ = 0;
    cc->ff_speed = 0;
    cc->gains = foc_pi_tune_of(&foc_cc_gains);
}

void foc_cc_reset(foc_current_ctrl_t *cc)
{
    const foc_dq_t zero = { 0, 0 };
    foc_cc_preset(cc, zero, 0);
}

void foc_cc_preset(foc_current_ctrl_t *cc, foc_dq_t v, q15_t speed)
{
    cc->ff_speed = speed;
    foc_pi_preset(&cc->pi_d, v.d);
    foc_pi_preset(&cc->pi_q, v.q);
    cc->pull_integ = 0;
}
