/*
 * Speed loop (slow tick): reference ramp, PI from speed error to q-axis
 * current, and the current-limit circle: |Iq| <= sqrt(Ilim^2 - Id^2), so the
 * phase current stays within CURRENT_LIMIT_A once Id has taken its share.
 * A loop that hunts has its gains halved (foc_sc_step).
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
    foc_pi_tune_t gains; /* [init] kp (0..65535), ki (0..32767) mantissas */
                         /* at the build's exponents (FOC_SPEED_KP/KI_SHIFT); */
                         /* the monitor writes them, a start keeps them */
    uint8_t gain_shift; /* the PI's gains / 2^gain_shift, 0..FOC_SPEED_HUNT_ */
                        /* SHIFT_MAX: one more each time the loop hunts */
    int8_t hunt_side;   /* the q reference's last side beyond half its */
                        /* limit: +1, -1, or 0 (none yet in this run) */
    uint8_t hunt_count; /* swings from side to side, leaky, in slow ticks: */
                        /* 0..FOC_SPEED_HUNT_TRIP_TICKS + _SWING_TICKS */
} foc_speed_ctrl_t;

/* Gains from userparms.h; target and ramp at zero. */
void foc_sc_init(foc_speed_ctrl_t *sc);

/* Bumpless start of the loop: the ramp starts from the measured speed and
 * the PI output from the present q current; the gains are the design's
 * again. */
void foc_sc_preset(foc_speed_ctrl_t *sc, q15_t speed_meas, q15_t iq_now);

/* One slow tick: advances the ramp toward `target`, returns Iq reference.
 * A loop that hunts (the reference from beyond half its limit one way to
 * beyond half the other, again and again: a rotor much lighter than
 * MOTOR_INERTIA_KGM2 makes its gain too high for its delays) has its
 * gains halved, to a quarter at most, for the rest of the run. */
q15_t foc_sc_step(foc_speed_ctrl_t *sc, q15_t speed_meas, q15_t id_ref);

/* The ramp held at the measured speed where it has run beyond it (the
 * voltage cannot take the motor faster): the speed settles at what is
 * reachable instead of the speed loop winding up. */
void foc_sc_hold(foc_speed_ctrl_t *sc, q15_t speed_meas);

/* Iq available inside the current limit once Id has taken its share. */
q15_t foc_sc_iq_limit(q15_t id_ref);

#endif /* FOC_SPEED_CTRL_H */
