#include "foc/estimator.h"
#include "foc/lpf.h"

int foc_est_select(foc_estimator_t *est, foc_est_kind_t kind)
{
    switch (kind) {
    case FOC_EST_SENSORED:
    case FOC_EST_PLL:
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

const char *foc_est_name(foc_est_kind_t kind)
{
    static const char *const names[] = { "sensored", "pll", "luenberger", "flux" };
    return ((unsigned)kind < sizeof names / sizeof names[0]) ? names[kind] : "?";
}
