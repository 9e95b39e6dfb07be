/* Online winding-resistance adaptation: see rs_adapt.h. */
#include "foc/rs_adapt.h"
#include "foc/config.h"

/* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
FOC_STATIC_ASSERT(FOC_RSA_STEP_DIV >= 1 && FOC_RSA_STEP_DIV < 16384,
                  "rs_adapt: Rs per unit out of the step's range");

/* The largest step per tick, Q14 of the ratio (1/256: a noisy tick moves
 * Rs by 0.4 % at most). */
#define STEP_MAX_Q14 64

void foc_rs_adapt_reset(foc_rs_adapt_t *a, foc_dq_t v, foc_dq_t i, q15_t speed, q15_t rs_q14)
{
    const int32_t r = rs_q14;
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    a->rs_min_q14 = (q15_t)(r - (r >> 3));
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t hi = r + (r >> 1);
    a->rs_max_q14 = (hi > Q15_MAX) ? Q15_MAX : (q15_t)hi;
    foc_lpf_init(&a->vd, v.d);
    foc_lpf_init(&a->vq, v.q);
    foc_lpf_init(&a->id, i.d);
    foc_lpf_init(&a->iq, i.q);
    foc_lpf_init(&a->speed, speed);
}

/* x (Q15) times a Q14 ratio (< 2), saturated Q15. */
static q15_t times_ratio(q15_t x, q15_t ratio_q14)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return foc_sat_q15(((int32_t)x * ratio_q14) >> 14);
}

q15_t foc_rs_adapt_tick(foc_rs_adapt_t *a, foc_dq_t v, foc_dq_t i, q15_t speed, q15_t rs_q14,
                        q15_t ls_q14)
{
    const q15_t vd = foc_lpf_step(&a->vd, v.d, FOC_RSA_FILTER_K);
    const q15_t vq = foc_lpf_step(&a->vq, v.q, FOC_RSA_FILTER_K);
    const q15_t id = foc_lpf_step(&a->id, i.d, FOC_RSA_FILTER_K);
    const q15_t iq = foc_lpf_step(&a->iq, i.q, FOC_RSA_FILTER_K);
    const q15_t w = foc_lpf_step(&a->speed, speed, FOC_RSA_FILTER_K);

    /* the gate: a d current of at least a quarter of the q current (where
     * Rs matters to the angle), and a nominal ohmic drop |iq| Rs of at
     * least 1/4 of the EMF w psi (where it shows) */
    const q15_t emf = foc_abs_q15(foc_mul_q15_shift(w, FOC_EMF_PER_SPEED_MANT, FOC_EMF_PER_SPEED_SHIFT));
    const q15_t drop = foc_mul_q15_shift(foc_abs_q15(iq), FOC_RS_MANT, FOC_RS_SHIFT);
    if (emf == 0 || ((int32_t)drop * 4) < (int32_t)emf ||
        ((int32_t)foc_abs_q15(id) * 4) < (int32_t)foc_abs_q15(iq)) {
        return rs_q14;
    }
    /* the EMF with the present Rs and the estimator's inductance, Q15 */
    const q15_t rs_id = times_ratio(foc_mul_q15_shift(id, FOC_RS_MANT, FOC_RS_SHIFT), rs_q14);
    const q15_t rs_iq = times_ratio(foc_mul_q15_shift(iq, FOC_RS_MANT, FOC_RS_SHIFT), rs_q14);
    const q15_t wld_id =
        times_ratio(foc_mul_q15_shift(foc_mul_q15(w, id), FOC_XD_MANT, FOC_XD_SHIFT), ls_q14);
    const q15_t wlq_iq =
        times_ratio(foc_mul_q15_shift(foc_mul_q15(w, iq), FOC_XQ_MANT, FOC_XQ_SHIFT), ls_q14);
    const q15_t eq = foc_sat_q15((int32_t)vq - rs_iq - wld_id);
    const q15_t ed = foc_sat_q15((int32_t)vd - rs_id + wlq_iq);

    /* Q30: each square or product is below 2^30 in magnitude, so the sum
     * of two is below 2^31 */
    const int32_t eps = ((int32_t)eq * eq) + ((int32_t)ed * ed) - ((int32_t)emf * emf);
    const int32_t g = ((int32_t)eq * iq) + ((int32_t)ed * id);
    /* eps / (2 g) in per unit of Rs, over Rs per unit, 1/64 of it, Q14:
     * (eps / 2^15) 2^14 / ((g / 2^15) Rs_pu 2^7); |g / 2^15| < 2^16 */
    /* cppcheck-suppress [misra-c2012-10.1, misra-c2012-10.8] ; D1 Q-format shift, D2 compile-time constant */
    const int32_t den = (g >> 15) * FOC_RSA_STEP_DIV;
    if (den > -STEP_MAX_Q14 && den < STEP_MAX_Q14) {
        return rs_q14; /* no slope to follow */
    }
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    int32_t step = ((eps >> 15) * 16384) / den;
    step = (step > STEP_MAX_Q14) ? STEP_MAX_Q14 : (step < -STEP_MAX_Q14) ? -STEP_MAX_Q14 : step;
    const int32_t ratio = (int32_t)rs_q14 + step;
    return (ratio < a->rs_min_q14) ? a->rs_min_q14 : (ratio > a->rs_max_q14) ? a->rs_max_q14 : (q15_t)ratio;
}
