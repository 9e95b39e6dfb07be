#include "foc/estimator.h"

int foc_est_select(foc_estimator_t *est, foc_est_kind_t kind)
{
    if (kind != FOC_EST_SENSORED) {
        return -1; /* the sensorless estimators are not built yet */
    }
    est->kind = kind;
    return 0;
}

void foc_est_reset(foc_estimator_t *est, const foc_est_input_t *in)
{
    foc_sensored_reset(&est->sensored, in->theta_sensor);
    est->theta = est->sensored.theta;
    est->speed = 0;
}

void foc_est_step(foc_estimator_t *est, const foc_est_input_t *in)
{
    foc_sensored_step(&est->sensored, in->theta_sensor);
    est->theta = est->sensored.theta;
    est->speed = foc_lpf_out(&est->sensored.speed);
}

const char *foc_est_name(foc_est_kind_t kind)
{
    static const char *const names[] = { "sensored", "pll", "luenberger", "flux" };
    return names[kind];
}
