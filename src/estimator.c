#include "foc/estimator.h"
#include "foc/config.h"
#include "foc/lpf.h"

int foc_est_select(foc_estimator_t *est, foc_est_kind_t kind)
{
    switch (kind) {
    case FOC_EST_SENSORED:
    case FOC_EST_PLL:
        est->kind = kind;
        return 0;
    case FOC_EST_FLUX:
        est->kind = kind;
        return 0;
    case FOC_EST_LUENBERGER:
        est->kind = kind;
        return 0;
    default:
        return -1; /* not built */
    }
}

/* The selected estimator's own angle and speed. */
static void read_estimate(foc_estimator_t *est)
{
    switch (est->kind) {
    case FOC_EST_PLL:
        est->est_theta = est->pll.theta;
        est->est_speed = foc_pll_speed(&est->pll);
        break;
    case FOC_EST_FLUX:
        est->est_theta = est->flux.theta;
        est->est_speed = foc_flux_speed(&est->flux);
        break;
    case FOC_EST_LUENBERGER:
        est->est_theta = est->luenberger.theta;
        est->est_speed = foc_luen_speed(&est->luenberger);
        break;
    default:
        est->est_theta = est->sensored.theta;
        est->est_speed = foc_lpf_out(&est->sensored.speed);
        break;
    }
}

static void publish(foc_estimator_t *est)
{
    read_estimate(est);
    if (est->use_sensor != 0u) {
        est->theta = est->sensored.theta;
        est->speed = foc_lpf_out(&est->sensored.speed);
    } else {
        est->theta = est->est_theta;
        est->speed = est->est_speed;
    }
}

void foc_est_reset(foc_estimator_t *est, const foc_est_input_t *in, uint8_t use_sensor)
{
    est->use_sensor = (uint8_t)(use_sensor != 0u || est->kind == FOC_EST_SENSORED);
    foc_sensored_reset(&est->sensored, in->theta_sensor);
    switch (est->kind) {
    case FOC_EST_PLL:
        foc_pll_init(&est->pll);
        foc_pll_reset(&est->pll, 0, 0, in->i_ab);
        break;
    case FOC_EST_FLUX:
        foc_flux_reset(&est->flux, 0, 0, in->i_ab);
        break;
    case FOC_EST_LUENBERGER:
        foc_luen_reset(&est->luenberger, 0, 0, in->i_ab);
        break;
    default:
        break;
    }
    publish(est);
}

void foc_est_step(foc_estimator_t *est, const foc_est_input_t *in)
{
    if (est->use_sensor != 0u) {
        foc_sensored_step(&est->sensored, in->theta_sensor);
    }
    switch (est->kind) {
    case FOC_EST_PLL:
        foc_pll_step(&est->pll, in->v_ab, in->i_ab);
        break;
    case FOC_EST_FLUX:
        foc_flux_step(&est->flux, in->v_ab, in->i_ab, in->iq_ref);
        break;
    case FOC_EST_LUENBERGER:
        foc_luen_step(&est->luenberger, in->v_ab, in->i_ab);
        break;
    default:
        break;
    }
    publish(est);
}

void foc_est_set_fw(foc_estimator_t *est, q15_t inv_kfi, q15_t ls_scale)
{
    foc_pll_set_inv_kfi(&est->pll, inv_kfi);
    foc_pll_set_ls_scale(&est->pll, ls_scale);
}

uint8_t foc_est_emf_consistent(const foc_estimator_t *est, q15_t ratio)
{
    switch (est->kind) {
    case FOC_EST_PLL: {
        const q15_t expected = foc_mul_q15_shift(foc_abs_q15(foc_pll_speed(&est->pll)),
                                                 FOC_PLL_KFI_MANT, FOC_PLL_KFI_SHIFT);
        return (uint8_t)(foc_abs_q15(foc_lpf_out(&est->pll.eq)) >= foc_mul_q15(ratio, expected));
    }
    case FOC_EST_LUENBERGER:
        /* e_q is Q15 of the EMF at SPEED_BASE_RPM: the speed it implies. */
        return (uint8_t)(foc_abs_q15(est->luenberger.emf_speed) >=
                         foc_mul_q15(ratio, foc_abs_q15(foc_luen_speed(&est->luenberger))));
    default:
        return 1; /* the sensor needs no such check */
    }
}

const char *foc_est_name(foc_est_kind_t kind)
{
    static const char *const names[] = { "sensored", "pll", "luenberger", "flux" };
    return ((unsigned)kind < sizeof names / sizeof names[0]) ? names[kind] : "?";
}
