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
 * nominal bus; `v_dt`, the phase voltage a dead time loses (Vdc t_dead
 * f_pwm: FOC_DT_VOLTAGE, or commissioning's measure, controller.h).
 */
#ifndef FOC_DEADTIME_H
#define FOC_DEADTIME_H

#include "foc/config.h"
#include "foc/transforms.h"

/* One phase: v x clamp(i / band, -1, 1), the band's inverse as a gain
 * (mantissa, shift); v = -V_dt gives the bridge's error, +V_dt the
 * correction. */
static inline q15_t foc_deadtime_phase(q15_t i, q15_t inv_band, uint8_t shift, q15_t v)
{
    return foc_mul_q15(foc_mul_q15_shift(i, inv_band, shift), v);
}

/* The error the bridge makes: soft band = the PWM-ripple band of the
 * motor (FOC_DT_RIPPLE_BAND_A, from Vdc, L and f_pwm).  For the estimator.
 * The common mode never reaches the windings: Clarke drops it. */
static inline foc_ab_t foc_deadtime_error_ab(foc_abc_t i, q15_t v_dt)
{
    const q15_t k = FOC_DT_INV_RIPPLE_MANT;
    const uint8_t sh = FOC_DT_INV_RIPPLE_SHIFT;
    const q15_t v = (q15_t)-v_dt;
    const foc_abc_t e = { foc_deadtime_phase(i.a, k, sh, v), foc_deadtime_phase(i.b, k, sh, v),
                          foc_deadtime_phase(i.c, k, sh, v) };
    return foc_clarke3_q15(e);
}

/* The correction to command: the opposite of the same error with the
 * wider soft band DEADTIME_COMP_CURRENT_A, so that near zero current,
 * where the bridge's error follows the actual current and the correction
 * the reference, the correction's slope stays small (the current loop
 * absorbs the rest). */
static inline foc_ab_t foc_deadtime_correction_ab(foc_abc_t i_ref, q15_t v_dt)
{
    const q15_t k = FOC_DT_INV_SOFT_MANT;
    const uint8_t sh = FOC_DT_INV_SOFT_SHIFT;
    const foc_abc_t e = { foc_deadtime_phase(i_ref.a, k, sh, v_dt),
                          foc_deadtime_phase(i_ref.b, k, sh, v_dt),
                          foc_deadtime_phase(i_ref.c, k, sh, v_dt) };
    return foc_clarke3_q15(e);
}

#endif /* FOC_DEADTIME_H */
