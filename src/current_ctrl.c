#include "foc/current_ctrl.h"
#include "foc/config.h"
#include "foc/sqrt.h"

void foc_cc_init(foc_current_ctrl_t *cc)
{
    foc_pi_init(&cc->pi_d, FOC_CURRENT_KP_MANT, FOC_CURRENT_KP_SHIFT,
                FOC_CURRENT_KI, 0, FOC_CURRENT_KC, (q15_t)-FOC_VOLTAGE_LIMIT,
                FOC_VOLTAGE_LIMIT);
    foc_pi_init(&cc->pi_q, FOC_CURRENT_KP_MANT, FOC_CURRENT_KP_SHIFT,
                FOC_CURRENT_KI, 0, FOC_CURRENT_KC, (q15_t)-FOC_VOLTAGE_LIMIT,
                FOC_VOLTAGE_LIMIT);
}

void foc_cc_reset(foc_current_ctrl_t *cc)
{
    const foc_dq_t zero = { 0, 0 };
    foc_cc_preset(cc, zero);
}

void foc_cc_preset(foc_current_ctrl_t *cc, foc_dq_t v)
{
    foc_pi_preset(&cc->pi_d, v.d);
    foc_pi_preset(&cc->pi_q, v.q);
}

/* sqrt(a^2 - b^2) for 0 <= |b|, a <= 1 in Q15; 0 when |b| >= a.
 * The squares are Q30 and non-negative, the difference fits uint32_t. */
static q15_t circle_remainder(q15_t a, q15_t b)
{
    const int32_t a2 = (int32_t)a * a;
    const int32_t b2 = (int32_t)b * b;
    if (b2 >= a2) {
        return 0;
    }
    return (q15_t)foc_isqrt32((uint32_t)(a2 - b2));
}

/* The d axis, first: its PI limited to +-Vmax. */
static q15_t d_axis(foc_current_ctrl_t *cc, q15_t id_ref, q15_t id_meas, q15_t v_max)
{
    foc_pi_set_limits(&cc->pi_d, (q15_t)-v_max, v_max);
    return foc_pi_step(&cc->pi_d, foc_sub_q15(id_ref, id_meas));
}

foc_dq_t foc_cc_step(foc_current_ctrl_t *cc, foc_dq_t i_ref, foc_dq_t i_meas,
                     q15_t v_max)
{
    foc_dq_t v;
    v.d = d_axis(cc, i_ref.d, i_meas.d, v_max);
    const q15_t vq_max = circle_remainder(v_max, v.d);
    foc_pi_set_limits(&cc->pi_q, (q15_t)-vq_max, vq_max);
    v.q = foc_pi_step(&cc->pi_q, foc_sub_q15(i_ref.q, i_meas.q));
    return v;
}

foc_dq_t foc_cc_step_vq(foc_current_ctrl_t *cc, q15_t id_ref, q15_t id_meas, q15_t vq,
                        q15_t iq_meas, q15_t iq_max, q15_t v_max)
{
    foc_dq_t v;
    v.d = d_axis(cc, id_ref, id_meas, v_max);
    /* Free within +-iq_max; beyond it the proportional gain pulls Iq back
     * (a low-resistance winding would otherwise carry a large swing
     * current). */
    const q15_t iq_free = (iq_meas > iq_max) ? iq_max : (iq_meas < -iq_max) ? (q15_t)-iq_max : iq_meas;
    const q15_t pull = foc_mul_q15_shift(foc_sub_q15(iq_free, iq_meas), FOC_CURRENT_KP_MANT,
                                         FOC_CURRENT_KP_SHIFT);
    vq = foc_add_q15(vq, pull);
    const q15_t vq_max = circle_remainder(v_max, v.d);
    v.q = (vq > vq_max) ? vq_max : (vq < -vq_max) ? (q15_t)-vq_max : vq;
    foc_pi_set_limits(&cc->pi_q, (q15_t)-vq_max, vq_max);
    foc_pi_preset(&cc->pi_q, v.q);
    return v;
}
