/*
 * Speed loop (slow tick): reference ramp, PI from speed error to q-axis
 * current, and the current-limit circle: |Iq| <= sqrt(Ilim^2 - Id^2), so the
 * phase current stays within CURRENT_LIMIT_A once Id has taken its share.
 *
 * Units: speeds Q15 of SPEED_BASE_RPM (signed: negative = reverse),
 * currents Q15 of the current base.
 */
#ifndef FOC_SPEED_CTRL_H
#define FOC_SPEED_CTRL_H

#include "foc/pi.h"

typedef struct {
    q15_t target;     /* commanded speed, Q15 */
    q15_t ramped;     /* reference after the slew limit, Q15 */
    int32_t ramped15; /* the same, Q15.15: the ramp's exact accumulator */
    int32_t step15;   /* slew per slow tick, Q15.15 (SPEED_RAMP_RPM_PER_S, */
                      /* or TUNING_RAMP_RPM_PER_S in TUNING) */
    foc_pi_q15_t pi;
} foc_speed_ctrl_t;

/* Gains from userparms.h; target and ramp at zero. */
void foc_sc_init(foc_speed_ctrl_t *sc);

/* Bumpless start of the loop: the ramp starts from the measured speed and
 * the PI output from the present q current. */
void foc_sc_preset(foc_speed_ctrl_t *sc, q15_t speed_meas, q15_t iq_now);

/* One slow tick: advances the ramp toward `target`, returns Iq reference. */
q15_t foc_sc_step(foc_speed_ctrl_t *sc, q15_t speed_meas, q15_t id_ref);

/* The ramp held at the measured speed where it has run beyond it (the
 * voltage cannot take the motor faster): the speed settles at what is
 * reachable instead of the speed loop winding up. */
void foc_sc_hold(foc_speed_ctrl_t *sc, q15_t speed_meas);

/* Iq available inside the current limit once Id has taken its share. */
q15_t foc_sc_iq_limit(q15_t id_ref);

#endif /* FOC_SPEED_CTRL_H */
