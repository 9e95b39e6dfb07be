#include "foc/pll_est.h"
#include "foc/config.h"
#include "foc/trig.h"

/* Leave the 8-period average 12.5 % above the threshold (hysteresis). */
#define LOW_SPEED_EXIT ((q15_t)(FOC_PLL_LOW_SPEED + (FOC_PLL_LOW_SPEED >> 3)))

static const foc_ab_t zero_ab = { 0, 0 };

void foc_pll_init(foc_pll_t *p)
{
    p->inv_kfi = FOC_PLL_INVKFI;
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    foc_pll_set_ls_scale(p, Q15(0.5), FOC_RATIO_ONE_Q14);
    foc_pll_set_rs(p, FOC_RATIO_ONE_Q14);
    foc_pll_reset(p, 0, 0, zero_ab);
}

void foc_pll_set_rs(foc_pll_t *p, q15_t ratio_q14)
{
    p->rs = foc_mul_q15(FOC_RS2_MANT, ratio_q14);
}

void foc_pll_set_inv_kfi(foc_pll_t *p, q15_t inv_kfi)
{
    p->inv_kfi = inv_kfi;
}

void foc_pll_set_ls_scale(foc_pll_t *p, q15_t ls_over_2ls0, q15_t ratio_q14)
{
    /* nominal mantissa x 2 x scale x ratio: 0.5 and 1.0 give the nominal Ls */
    p->ls_dt = foc_mul_q15_shift(foc_mul_q15_shift(FOC_PLL_LSDT_MANT, ls_over_2ls0, 1), ratio_q14, 1);
}

void foc_pll_reset(foc_pll_t *p, uint16_t theta, q15_t speed, foc_ab_t i_now)
{
    /* The EMF the speed implies lies on the q axis: E = (0, KFi w). */
    const q15_t eq0 = foc_mul_q15_shift(speed, FOC_PLL_KFI_MANT, FOC_PLL_KFI_SHIFT);
    const foc_dq_t e_dq = { 0, eq0 };
    const foc_ab_t e_ab = foc_ipark_q15(e_dq, foc_sincos_q15(theta));

    /* theta32 holds the angle of the next sample (as after a step). */
    /* cppcheck-suppress misra-c2012-10.8 ; D3 modular angle */
    p->theta32 = ((uint32_t)theta << 16) + (uint32_t)((int32_t)speed * FOC_THETA32_PER_SPEED);
    p->theta = theta;
    p->omega = speed;
    foc_lpf_init(&p->ed, 0);
    foc_lpf_init(&p->eq, eq0);
    foc_lpf_init(&p->speed, speed);
    p->i_prev = i_now;
    for (unsigned k = 0; k < FOC_PLL_AVG_N; k++) {
        p->e_ring[k] = e_ab;
    }
    p->e_sum_alpha = (int32_t)e_ab.alpha * (int32_t)FOC_PLL_AVG_N;
    p->e_sum_beta = (int32_t)e_ab.beta * (int32_t)FOC_PLL_AVG_N;
    p->e_next = 0;
    p->low_speed = (uint8_t)(foc_abs_q15(speed) < FOC_PLL_LOW_SPEED);
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    p->track_gain = (q15_t)FOC_PLL_TRACK_GAIN_Q14;
}

/* Current change over one period, limited to what the winding allows
 * (a larger step is measurement noise or a sampling glitch). */
static q15_t limited_di(q15_t now, q15_t prev)
{
    int32_t di = (int32_t)now - (int32_t)prev;
    if (di > FOC_DI_MAX) {
        di = FOC_DI_MAX;
    } else if (di < -(int32_t)FOC_DI_MAX) {
        di = -(int32_t)FOC_DI_MAX;
    } else {
        /* within the limits */
    }
    return (q15_t)di;
}

/* One component of eq. 4, v - Rs (i + i_prev)/2 - Ls di/Ts, at half
 * scale (Q15 of 2 x the voltage base), rounded and saturated. */
static q15_t emf_component(const foc_pll_t *p, q15_t v, q15_t i, q15_t i_prev)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const q15_t i_mid = (q15_t)(((int32_t)i + (int32_t)i_prev) >> 1);
    const q15_t r_drop = foc_mul_q15_shift(i_mid, p->rs, FOC_RS2_SHIFT);
    const q15_t l_drop = foc_mul_q15_shift(limited_di(i, i_prev), p->ls_dt, FOC_PLL_LSDT_SHIFT);
    const int32_t e = (int32_t)v - (int32_t)r_drop - (int32_t)l_drop; /* |e| < 3 x 2^15 */
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return foc_sat_q15((e + 1) >> 1);
}

/* Pushes this period's EMF into the 8-period ring, keeping the sums. */
static void ring_push(foc_pll_t *p, foc_ab_t e)
{
    const foc_ab_t old = p->e_ring[p->e_next];
    p->e_sum_alpha += (int32_t)e.alpha - (int32_t)old.alpha;
    p->e_sum_beta += (int32_t)e.beta - (int32_t)old.beta;
    p->e_ring[p->e_next] = e;
    p->e_next = (uint8_t)((p->e_next + 1u) & (FOC_PLL_AVG_N - 1u));
}

/* -sgn(w) Edf, w the filtered speed: eq. 2's correction (the estimate
 * speeds up in the direction in which it lags) and the flux tracking's
 * input. */
static inline int32_t lead_of(const foc_pll_t *p, q15_t edf)
{
    return (foc_lpf_out(&p->speed) >= 0) ? -(int32_t)edf : (int32_t)edf;
}

static void update_speed_range(foc_pll_t *p)
{
    const q15_t w = foc_abs_q15(p->omega);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    if (p->low_speed != 0u && w > LOW_SPEED_EXIT) {
        p->low_speed = 0;
    } else if (p->low_speed == 0u && w < FOC_PLL_LOW_SPEED) {
        p->low_speed = 1;
    } else {
        /* within the hysteresis: the range stays */
    }
}

void foc_pll_step(foc_pll_t *p, foc_ab_t v_last, foc_ab_t i_now)
{
    foc_ab_t e;
    e.alpha = emf_component(p, v_last.alpha, i_now.alpha, p->i_prev.alpha);
    e.beta = emf_component(p, v_last.beta, i_now.beta, p->i_prev.beta);
    p->i_prev = i_now;
    ring_push(p, e);
    update_speed_range(p);

    /* The EMF used and how many half periods back its centre lies. */
    int32_t half_periods = 1;
    if (p->low_speed != 0u) {
        /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
        e.alpha = (q15_t)(p->e_sum_alpha >> FOC_PLL_AVG_LOG2);
        /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
        e.beta = (q15_t)(p->e_sum_beta >> FOC_PLL_AVG_LOG2);
        half_periods = (int32_t)FOC_PLL_AVG_N;
    }
    const int32_t back = (int32_t)foc_mul_q15(p->omega, FOC_HALF_PERIOD_ANGLE) * half_periods;
    p->theta = (uint16_t)(p->theta32 >> 16);
    const uint16_t theta_e = (uint16_t)(p->theta - (uint16_t)back);

    const foc_dq_t e_dq = foc_park_q15(e, foc_sincos_q15(theta_e));
    const q15_t edf = foc_lpf_step(&p->ed, e_dq.d, FOC_PLL_EMF_FILTER_K);
    const q15_t eqf = foc_lpf_step(&p->eq, e_dq.q, FOC_PLL_EMF_FILTER_K);
    /* eq. 2 (lead_of) and the slow step's flux tracking */
    const int32_t lead = lead_of(p, edf);
    const int32_t num = (int32_t)eqf + lead + p->flux_corr;
    p->omega = foc_mul_q15_shift(foc_sat_q15(num), p->inv_kfi, FOC_PLL_INVKFI_SHIFT);

    /* Angle for the next sample; the conversion to uint32_t wraps. */
    /* cppcheck-suppress misra-c2012-10.8 ; D3 modular angle */
    p->theta32 += (uint32_t)((int32_t)p->omega * FOC_THETA32_PER_SPEED);
    (void)foc_lpf_step(&p->speed, p->omega, FOC_PLL_SPEED_FILTER_K);
}

void foc_pll_track_reset(foc_pll_t *p)
{
    p->flux_track = 0;
    p->flux_corr = 0;
}

void foc_pll_track_flux(foc_pll_t *p)
{
    /* 16-bit reads of what the step writes; |lead| x gain < 2^29 (gain
     * < 2^14), the sum < 2^30 */
    const q15_t edf = foc_lpf_out(&p->ed);
    const q15_t eqf = foc_lpf_out(&p->eq);
    const int32_t lead = lead_of(p, edf);
    const int32_t track_max = (int32_t)foc_abs_q15(eqf) * 16384; /* << 14 */
    int32_t track = p->flux_track + lead * (int32_t)p->track_gain;
    if (track > track_max) {
        track = track_max;
    } else if (track < -track_max) {
        track = -track_max;
    } else {
        /* within the limits */
    }
    p->flux_track = track;
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    p->flux_corr = (q15_t)(track >> 14);
}
