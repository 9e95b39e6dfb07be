/*
 * Supervision of the motor from the controller's own measurements, beside
 * the stall statistics of the start-up and run states (docs/safety.md):
 *
 * - I2t: the winding's heating, (I / I_rated)^2 through a first-order
 *   thermal model (MOTOR_THERMAL_TIME_S), in every state; a motor held at
 *   the current limit is switched off before it overheats even where no
 *   stall can be seen (MOTOR_OVERLOAD).
 * - Overspeed: the speed above (1 + OVERSPEED_MARGIN) x the maximum.
 * - A rotor that does not follow at any commanded speed: the speed loop at
 *   its current limit with the speed below 7/8 of the command and not
 *   gaining on it (SPEED_FEEDBACK) -- a locked rotor at 100 rpm, where the
 *   estimator's statistics are blind, or a load the motor cannot carry.
 *   Gaining is judged on the mean speed over two consecutive windows,
 *   toward the command's direction, so a heavy load accelerating slowly
 *   at the limit (a fan) is not taken for a stall, one noisy estimate is
 *   not taken for progress, and a new command farther away is not taken
 *   for ground lost.
 *
 * Units: currents Q15 of the current base, speeds Q15 of SPEED_BASE_RPM.
 * Called from the slow step; each check returns the fault bits to raise.
 */
#ifndef FOC_SUPERVISION_H
#define FOC_SUPERVISION_H

#include <stdint.h>
#include "foc/transforms.h"

typedef struct {
    int32_t heat;            /* (I / I_rated)^2 filtered, Q20 (1.0 = rated) */
    int32_t follow_sum;      /* sum of the speed over the window */
    int32_t follow_last;     /* the previous window's mean, */
                             /* FOC_SUP_FOLLOW_NONE if none */
    uint16_t follow_ticks;   /* slow ticks of the present window at the */
                             /* limit and behind */
    uint8_t overspeed_ticks; /* consecutive slow ticks above the overspeed */
} foc_supervision_t;

/* follow_last with no window before the present one (a mean lies within
 * +-2^15). */
#define FOC_SUP_FOLLOW_NONE INT32_MIN

/* Cold motor, counters clear (power-up). */
void foc_sup_init(foc_supervision_t *s);

/* Counters of one run clear (the heat stays: the winding remembers). */
void foc_sup_run_reset(foc_supervision_t *s);

/* One slow tick of the thermal model with the dq current flowing (zero
 * with the outputs off); MOTOR_OVERLOAD once the heat reaches 1.0. */
uint16_t foc_sup_thermal(foc_supervision_t *s, foc_dq_t i_dq);

/* 1 once the winding has cooled enough to acknowledge an overload. */
uint8_t foc_sup_cooled(const foc_supervision_t *s);

/* OVERSPEED when |speed| stays above the overspeed limit. */
uint16_t foc_sup_overspeed(foc_supervision_t *s, q15_t speed);

/* SPEED_FEEDBACK when, commanded `command`, the speed loop's output
 * `iq_ref` sits at the current limit toward the command's direction (the
 * whole FOC_CURRENT_LIMIT, not what field weakening leaves of it) while
 * `speed` stays below 7/8 of the command without gaining on it for the
 * window of that command. */
uint16_t foc_sup_follow(foc_supervision_t *s, q15_t command, q15_t speed, q15_t iq_ref);

#endif /* FOC_SUPERVISION_H */
