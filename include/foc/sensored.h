/*
 * Angle and speed from a rotor position sensor (the model's true angle on
 * the host; an encoder or resolver on a board that has one).  The reference
 * the sensorless estimators are measured against.
 *
 * Speed: angle difference per PWM period (counts, wraps correctly as int16)
 * times FOC_DTHETA_TO_SPEED, through a first-order filter
 * (SPEED_FILTER_TIME_S).  Q15 of SPEED_BASE_RPM.
 */
#ifndef FOC_SENSORED_H
#define FOC_SENSORED_H

#include <stdint.h>
#include "foc/lpf.h"

typedef struct {
    uint16_t theta;       /* electrical angle, 65536 = 360 deg */
    foc_lpf_q15_t speed;  /* filtered speed, Q15 */
} foc_sensored_t;

/* Starts from the present sensor angle with zero speed. */
void foc_sensored_reset(foc_sensored_t *s, uint16_t theta_sensor);

/* One PWM period. */
void foc_sensored_step(foc_sensored_t *s, uint16_t theta_sensor);

#endif /* FOC_SENSORED_H */
