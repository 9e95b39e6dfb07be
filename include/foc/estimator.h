/*
 * Rotor angle and speed source behind one interface: the position sensor
 * (reference for tests) or a sensorless estimator.  The controller calls
 * foc_est_step() once per PWM period with the currents just measured and
 * the voltage applied during the period that just ended.
 */
#ifndef FOC_ESTIMATOR_H
#define FOC_ESTIMATOR_H

#include <stdint.h>
#include "foc/sensored.h"
#include "foc/transforms.h"

typedef enum {
    FOC_EST_SENSORED = 0,
    FOC_EST_PLL = 1,        /* AN1292 back-EMF PLL estimator */
    FOC_EST_LUENBERGER = 2, /* ST-style Luenberger observer + PLL */
    FOC_EST_FLUX = 3        /* flux-linkage estimator + speed observer */
} foc_est_kind_t;

typedef struct {
    foc_ab_t v_ab;          /* voltage applied in the last period, Q15 */
    foc_ab_t i_ab;          /* current measured now, Q15 */
    uint16_t theta_sensor;  /* position sensor, if any */
} foc_est_input_t;

typedef struct {
    foc_est_kind_t kind;
    uint16_t theta;         /* electrical angle, 65536 = 360 deg */
    q15_t speed;            /* Q15 of SPEED_BASE_RPM, signed */
    foc_sensored_t sensored;
} foc_estimator_t;

/* Chooses the source; returns 0, or -1 if that kind is not available
 * (the kind is then left unchanged). */
int foc_est_select(foc_estimator_t *est, foc_est_kind_t kind);

/* Restarts the selected source (before closing the loop on it). */
void foc_est_reset(foc_estimator_t *est, const foc_est_input_t *in);

/* One PWM period; updates theta and speed. */
void foc_est_step(foc_estimator_t *est, const foc_est_input_t *in);

/* "sensored", "pll", "luenberger", "flux". */
const char *foc_est_name(foc_est_kind_t kind);

#endif /* FOC_ESTIMATOR_H */
