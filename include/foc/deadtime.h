/*
 * Dead-time voltage error.
 *
 * During each dead time a phase follows its free-wheeling diode: high for
 * a current out of the motor, low for a current into it, so the phase
 * voltage loses Vdc x t_dead x f_pwm in the direction of its current.  The
 * phase current ripples at the PWM rate, so within about the ripple of
 * zero (DEADTIME_COMP_CURRENT_A) it crosses zero during the period and the
 * average loss is proportional to the current: a soft sign.
 *
 * foc_deadtime_error_ab() gives that error as a stator-frame vector for
 * three phase currents.  The controller uses it twice: it commands the
 * opposite of the error for the current expected in the next period
 * (compensation), and it tells the estimator the voltage really applied in
 * the last period (command plus the error for the current that flowed).
 *
 * Currents Q15 of the current base; voltage Q15 of the voltage base at the
 * nominal bus.
 */
#ifndef FOC_DEADTIME_H
#define FOC_DEADTIME_H

#include "foc/transforms.h"

foc_ab_t foc_deadtime_error_ab(foc_abc_t i);

#endif /* FOC_DEADTIME_H */
