/*
 * d/q current controllers with the voltage-limit circle, d-axis priority
 * (AN1292 figure 9): Vd is limited to +-Vmax, then Vq to
 * +-sqrt(Vmax^2 - Vd^2), so the flux-producing (field-weakening) component
 * always gets the voltage it asks for and |Vdq| <= Vmax.
 *
 * Units: currents Q15 of the current base, voltages Q15 of the voltage
 * base (Vdc_nominal / sqrt(3)); Vmax comes from the bus block.
 */
#ifndef FOC_CURRENT_CTRL_H
#define FOC_CURRENT_CTRL_H

#include "foc/config.h"
#include "foc/pi.h"
#include "foc/sqrt.h"
#include "foc/transforms.h"

typedef struct {
    foc_pi_q15_t pi_d;
    foc_pi_q15_t pi_q;
    q31_t pull_integ; /* forced frame: integral of the q current beyond its */
                      /* band (foc_cc_q_forced), Q30 of the voltage base */
    q15_t ff_speed;   /* the feedforward's filtered speed, Q15 of */
                      /* SPEED_BASE_RPM */
    foc_pi_tune_t gains; /* [init] both axes' kp (0..65535) and ki */
                         /* (0..32767) mantissas at the build's exponents */
                         /* (FOC_CURRENT_KP_SHIFT, 0); the monitor's */
} foc_current_ctrl_t;

/* Both axes' gains as built (config.h): their exponents and Kc are
 * constants the inline steps fold; kp and ki are read from `gains`. */
static const foc_pi_gains_t foc_cc_gains =
    FOC_PI_GAINS(FOC_CURRENT_KP_MANT, FOC_CURRENT_KP_SHIFT, FOC_CURRENT_KI, 0, FOC_CURRENT_KC);

/* Inside its band the pull's integral leaks away in 2^FOC_CC_PULL_LEAK_BITS
 * periods (3.2 ms at 20 kHz): once the rotor is back in step the forced
 * voltage acts alone again. */
#define FOC_CC_PULL_LEAK_BITS 6

/* Gains from userparms.h; integrators cleared. */
void foc_cc_init(foc_current_ctrl_t *cc);

/* Clears both integrators (outputs start from zero voltage, the rotor
 * taken at rest). */
void foc_cc_reset(foc_current_ctrl_t *cc);

/* The q-axis limit left by vd inside the circle of radius v_max:
 * sqrt(v_max^2 - vd^2), 0 <= |vd| <= v_max (Q15; squares Q30).  Callers
 * take it only once a candidate vq is found outside the circle. */
static inline q15_t foc_cc_circle_q(q15_t v_max, q15_t vd)
{
    const int32_t rest = (int32_t)v_max * v_max - (int32_t)vd * vd;
    return (rest > 0) ? (q15_t)foc_isqrt32((uint32_t)rest) : 0;
}

/* 1 if (vd, vq) lies outside the circle of radius v_max (|vq| <= 32767). */
static inline uint8_t foc_cc_outside(q15_t v_max, q15_t vd, q15_t vq)
{
    return (uint8_t)((int32_t)vd * vd + (int32_t)vq * vq > (int32_t)v_max * v_max);
}

/* Both axes: the reference's proportional gain is Kp - Kref, the
 * feedback's Kp (config.h): the integrator takes -Kref x the reference's
 * step of this period (`step`, Q15, |step| <= 2^(FOC_IREF_STEP_BITS - 1)),
 * so that at a steady reference it is the voltage (presets and the
 * feedforward keep their meaning).  The product is within 2^28 and the
 * step's Ki e within 2^29 (config.h): an integrator within 2^30 + 2^15
 * before cannot overflow before the PI's step clamps it.
 *
 * The d axis, first: its PI limited to +-Vmax. */
static inline q15_t foc_cc_d_axis(foc_current_ctrl_t *cc, q15_t id_ref, q15_t id_meas,
                                  q15_t v_max, q15_t step)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    cc->pi_d.integ -= (int32_t)step * FOC_CURRENT_KREF_Q30;
    foc_pi_limit_next(&cc->pi_d, v_max);
    const foc_pi_gains_t g = foc_pi_gains_with(&cc->gains, &foc_cc_gains);
    return foc_pi_step(&cc->pi_d, &g, foc_sub_q15(id_ref, id_meas));
}

/* The q axis of one PWM period, after the d axis gave vd: the PI on the
 * q current error.  Its limit is +-Vmax while its output lies inside the
 * circle; the root is taken only when it does not. */
static inline q15_t foc_cc_q_axis(foc_current_ctrl_t *cc, q15_t iq_ref, q15_t iq_meas,
                                  q15_t vd, q15_t v_max, q15_t step)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    cc->pi_q.integ -= (int32_t)step * FOC_CURRENT_KREF_Q30;
    const q15_t e_q = foc_sub_q15(iq_ref, iq_meas);
    const foc_pi_gains_t g = foc_pi_gains_with(&cc->gains, &foc_cc_gains);
    const int32_t u_q = foc_pi_unsat(&cc->pi_q, &g, e_q);
    const q15_t candidate = (u_q > v_max) ? v_max : (u_q < -v_max) ? (q15_t)-v_max : (q15_t)u_q;
    const q15_t vq_max = foc_cc_outside(v_max, vd, candidate) ? foc_cc_circle_q(v_max, vd)
                                                               : v_max;
    foc_pi_limit_next(&cc->pi_q, vq_max);
    return foc_pi_finish(&cc->pi_q, &g, e_q, u_q);
}

/* The q axis with the q voltage given instead of regulated: `vq` limited
 * to the circle.  In the forced frame of the start-up this lets the
 * back-EMF of a rotor swinging about the forced angle drive currents
 * through Rs: electrical damping, which a q current loop would cancel.
 * Only while |Iq| <= iq_max: beyond, the q PI's gains pull it back, the
 * integral too: a rotor slipping behind the forced frame has less EMF
 * than `vq` assumes, and the proportional pull alone left 5 % above the
 * current limit (torture campaign: heavy rotors in OPENLOOP).  The q
 * integrator follows Vq, so switching back to foc_cc_q_axis() is
 * bumpless; the feedforward's speed follows `speed`, the estimate's. */
static inline q15_t foc_cc_q_forced(foc_current_ctrl_t *cc, q15_t vq, q15_t iq_meas,
                                    q15_t iq_max, q15_t vd, q15_t v_max, q15_t speed)
{
    cc->ff_speed = speed;
    const q15_t iq_free = (iq_meas > iq_max)    ? iq_max
                          : (iq_meas < -iq_max) ? (q15_t)-iq_max
                                                : iq_meas;
    const q15_t excess = foc_sub_q15(iq_free, iq_meas); /* 0 inside the band */
    const foc_pi_gains_t g = foc_pi_gains_with(&cc->gains, &foc_cc_gains);
    if (excess != 0) {
        /* |pull_integ| <= 2^30 before, |Ki e| <= 2^30: no overflow */
        cc->pull_integ += foc_pi_ki_term(&g, excess);
        const q31_t lim = FOC_PI_Q15_TO_Q30(v_max);
        cc->pull_integ = (cc->pull_integ > lim) ? lim : (cc->pull_integ < -lim) ? -lim : cc->pull_integ;
    } else {
        /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
        cc->pull_integ -= cc->pull_integ >> FOC_CC_PULL_LEAK_BITS;
    }
    const q15_t pull = foc_add_q15(foc_sat_q15(foc_pi_kp_term(&g, excess)),
                                   /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
                                   (q15_t)(cc->pull_integ >> 15));
    vq = foc_add_q15(vq, pull);
    vq = (vq > v_max) ? v_max : (vq < -v_max) ? (q15_t)-v_max : vq;
    const q15_t vq_max = foc_cc_outside(v_max, vd, vq) ? foc_cc_circle_q(v_max, vd) : v_max;
    vq = (vq > vq_max) ? vq_max : (vq < -vq_max) ? (q15_t)-vq_max : vq;
    foc_pi_limit_next(&cc->pi_q, vq_max); /* the preset sets the integrator */
    foc_pi_preset(&cc->pi_q, vq);
    return vq;
}

/* The feedforward's speed follows the estimate through a first-order
 * filter of 2^FOC_CC_FF_FILTER_BITS periods (0.4 ms at 20 kHz): fast
 * against a jam, slow against the estimate's per-period noise. */
#define FOC_CC_FF_FILTER_BITS 3

/* Back-EMF feedforward of a slowing rotor, once per period before the q
 * axis: as |speed| falls, the q integrator drops the EMF it no longer
 * needs at once.  The PI's zero cancels the winding pole, so an EMF that
 * vanishes faster than the current loop (a jammed rotor stops in a few
 * milliseconds) otherwise leaves a current error that decays only at
 * Rs / L.  Only a slowing rotor, and never below the EMF of the new speed
 * less Rs x the current limit (`r_ilim`, Q15 voltage): an estimate that
 * jumps up and falls back (the Luenberger observer losing a slow rotor)
 * then cannot take the integrator's voltage with it.  A rotor that speeds
 * up is the PI's to follow.  `speed` Q15 of SPEED_BASE_RPM; emf_mant /
 * emf_shift the EMF per speed (config.h FOC_EMF_PER_SPEED_*). */
static inline void foc_cc_emf_feedforward(foc_current_ctrl_t *cc, q15_t speed, q15_t emf_mant,
                                          uint8_t emf_shift, q15_t r_ilim)
{
    const q15_t old = cc->ff_speed;
    /* |speed - old| < 2^16: the step is a Q15 value */
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const q15_t step = (q15_t)(((int32_t)speed - old) >> FOC_CC_FF_FILTER_BITS);
    const q15_t now = (q15_t)(old + step);
    cc->ff_speed = now;
    const int32_t integ = cc->pi_q.integ; /* within +-2^30 (the PI's clamp) */
    /* each product within +-2^30: the sums below fit int32_t */
    if (old > 0 && step < 0) {
        const int32_t lo = foc_mul_q30_shift(now, emf_mant, emf_shift) - FOC_PI_Q15_TO_Q30(r_ilim);
        const int32_t cand = integ + foc_mul_q30_shift(step, emf_mant, emf_shift);
        cc->pi_q.integ = (cand >= lo) ? cand : (integ < lo) ? integ : lo;
    } else if (old < 0 && step > 0) {
        const int32_t hi = foc_mul_q30_shift(now, emf_mant, emf_shift) + FOC_PI_Q15_TO_Q30(r_ilim);
        const int32_t cand = integ + foc_mul_q30_shift(step, emf_mant, emf_shift);
        cc->pi_q.integ = (cand <= hi) ? cand : (integ > hi) ? integ : hi;
    } else {
        /* speeding up, or no step: the PI follows on its own */
    }
}

/* Presets both integrators to a voltage (hand-over to another frame), the
 * feedforward's speed to `speed`. */
void foc_cc_preset(foc_current_ctrl_t *cc, foc_dq_t v, q15_t speed);

#endif /* FOC_CURRENT_CTRL_H */
