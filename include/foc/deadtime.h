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
 * The controller uses it twice: it commands the opposite of the error for
 * the current reference of the next period (compensation, with a wider
 * soft band), and it tells the estimator the voltage really applied in the
 * last period (command plus the error for the current that flowed).
 *
 * Currents Q15 of the current base; voltage Q15 of the voltage base at the
 * nominal bus.
 */
#ifndef FOC_DEADTIME_H
#define FOC_DEADTIME_H

#include "foc/transforms.h"

/* The error the bridge makes: soft band = the PWM-ripple band of the
 * motor (FOC_DT_RIPPLE_BAND_A, from Vdc, L and f_pwm).  For the estimator. */
foc_ab_t foc_deadtime_error_ab(foc_abc_t i);

/* The correction to command: the same error with the wider soft band
 * DEADTIME_COMP_CURRENT_A, so that near zero current, where the bridge's
 * error follows the actual current and the correction the reference, the
 * correction's slope stays small (the current loop absorbs the rest). */
foc_ab_t foc_deadtime_correction_ab(foc_abc_t i_ref);

#endif /* FOC_DEADTIME_H */
