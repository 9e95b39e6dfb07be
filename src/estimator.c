#include "foc/estimator.h"
#include "foc/config.h"
#include "foc/lpf.h"

int foc_est_select(foc_estimator_t *est, foc_est_kind_t kind)
{
    if ((unsigned)kind > (unsigned)FOC_EST_FLUX || !FOC_EST_BUILT(kind)) {
        return -1;
    }
    est->kind = (uint8_t)kind;
    return 0;
}

void foc_est_gains_init(foc_est_gains_t *g)
{
    g->luen_kp = FOC_LUEN_PLL_KP_MANT;
    g->luen_ki = FOC_LUEN_PLL_KI;
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    g->pll_track = (q15_t)FOC_PLL_TRACK_GAIN_Q14;
    g->flux_corr_min = FOC_FLUX_CORR_MIN;
    g->flux_corr_speed = FOC_FLUX_CORR_SPEED;
}

/* The sensorless estimator restarted at `theta` and `speed` (every
 * restart is made with no current in the windings), with the gains
 * `est->gains`. */
static void restart_at(foc_estimator_t *est, uint16_t theta, q15_t speed)
{
    static const foc_ab_t no_current = { 0, 0 };
    switch (est->kind) {
    case FOC_EST_PLL:
        if (FOC_EST_BUILT(FOC_EST_PLL)) {
            foc_pll_reset(&est->u.pll, theta, speed, no_current);
            est->u.pll.track_gain = est->gains.pll_track;
        }
        break;
    case FOC_EST_FLUX:
        if (FOC_EST_BUILT(FOC_EST_FLUX)) {
            foc_flux_reset(&est->u.flux, theta, speed, no_current);
            est->u.flux.corr_min = est->gains.flux_corr_min;
            est->u.flux.corr_speed = est->gains.flux_corr_speed;
        }
        break;
    case FOC_EST_LUENBERGER:
        if (FOC_EST_BUILT(FOC_EST_LUENBERGER)) {
            foc_luen_reset(&est->u.luenberger, theta, speed, no_current);
            est->u.luenberger.pll_kp = est->gains.luen_kp;
            est->u.luenberger.pll_ki = est->gains.luen_ki;
        }
        break;
    default:
        break;
    }
    foc_est_set_rs(est, est->rs_ratio);
    foc_est_set_ls(est, est->ls_ratio);
    foc_est_publish(est);
}

void foc_est_reset(foc_estimator_t *est, uint16_t theta_sensor, uint8_t use_sensor)
{
    est->use_sensor = (uint8_t)(use_sensor != 0u || est->kind == (uint8_t)FOC_EST_SENSORED);
    foc_sensored_reset(&est->sensored, theta_sensor);
    if (FOC_EST_BUILT(FOC_EST_PLL) && est->kind == (uint8_t)FOC_EST_PLL) {
        foc_pll_init(&est->u.pll);
    }
    restart_at(est, 0, 0);
}

void foc_est_preset(foc_estimator_t *est, uint16_t theta, q15_t speed)
{
    restart_at(est, theta, speed);
}

void foc_est_set_rs(foc_estimator_t *est, q15_t ratio_q14)
{
    est->rs_ratio = ratio_q14;
    if (FOC_EST_BUILT(FOC_EST_PLL) && est->kind == (uint8_t)FOC_EST_PLL) {
        foc_pll_set_rs(&est->u.pll, ratio_q14);
    } else if (FOC_EST_BUILT(FOC_EST_FLUX) && est->kind == (uint8_t)FOC_EST_FLUX) {
        foc_flux_set_rs(&est->u.flux, ratio_q14);
    } else if (FOC_EST_BUILT(FOC_EST_LUENBERGER) && est->kind == (uint8_t)FOC_EST_LUENBERGER) {
        foc_luen_set_winding(&est->u.luenberger, ratio_q14, est->ls_ratio);
    } else {
        /* sensored: no model to set */
    }
}

void foc_est_set_ls(foc_estimator_t *est, q15_t ratio_q14)
{
    est->ls_ratio = ratio_q14;
    if (FOC_EST_BUILT(FOC_EST_PLL) && est->kind == (uint8_t)FOC_EST_PLL) {
        /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
        foc_pll_set_ls_scale(&est->u.pll, Q15(0.5), ratio_q14);
    } else if (FOC_EST_BUILT(FOC_EST_FLUX) && est->kind == (uint8_t)FOC_EST_FLUX) {
        foc_flux_set_ls(&est->u.flux, ratio_q14);
    } else if (FOC_EST_BUILT(FOC_EST_LUENBERGER) && est->kind == (uint8_t)FOC_EST_LUENBERGER) {
        foc_luen_set_winding(&est->u.luenberger, est->rs_ratio, ratio_q14);
    } else {
        /* sensored: no model to set */
    }
}

void foc_est_track_flux(foc_estimator_t *est)
{
    if (FOC_EST_BUILT(FOC_EST_PLL) && est->kind == (uint8_t)FOC_EST_PLL) {
        foc_pll_track_flux(&est->u.pll);
    }
}

void foc_est_track_reset(foc_estimator_t *est)
{
    if (FOC_EST_BUILT(FOC_EST_PLL) && est->kind == (uint8_t)FOC_EST_PLL) {
        foc_pll_track_reset(&est->u.pll);
    }
}

void foc_est_set_fw(foc_estimator_t *est, q15_t inv_kfi, q15_t ls_scale)
{
    if (FOC_EST_BUILT(FOC_EST_PLL) && est->kind == (uint8_t)FOC_EST_PLL) {
        foc_pll_set_inv_kfi(&est->u.pll, inv_kfi);
        foc_pll_set_ls_scale(&est->u.pll, ls_scale, est->ls_ratio);
    }
}

uint8_t foc_est_emf_consistent(const foc_estimator_t *est, q15_t ratio)
{
    if (!FOC_EST_BUILT(est->kind)) {
        return 1;
    }
    switch (est->kind) {
    case FOC_EST_PLL: {
        const q15_t expected = foc_mul_q15_shift(foc_abs_q15(foc_pll_speed(&est->u.pll)),
                                                 FOC_PLL_KFI_MANT, FOC_PLL_KFI_SHIFT);
        return (uint8_t)(foc_abs_q15(foc_lpf_out(&est->u.pll.eq)) >= foc_mul_q15(ratio, expected));
    }
    case FOC_EST_LUENBERGER:
        /* e_q is Q15 of the EMF at SPEED_BASE_RPM: the speed it implies. */
        return (uint8_t)(foc_abs_q15(est->u.luenberger.emf_speed) >=
                         foc_mul_q15(ratio, foc_abs_q15(foc_luen_speed(&est->u.luenberger))));
    case FOC_EST_FLUX:
        return foc_flux_consistent(&est->u.flux);
    default:
        return 1; /* the sensor needs no such check */
    }
}

const char *foc_est_name(foc_est_kind_t kind)
{
    static const char *const names[] = { "sensored", "pll", "luenberger", "flux" };
    return ((unsigned)kind < sizeof names / sizeof names[0]) ? names[kind] : "?";
}
