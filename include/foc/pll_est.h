/*
 * Back-EMF PLL estimator (Microchip AN1292, equations 1-7: docs/references.md
 * [AN1292]).
 *
 * Per PWM period k, with the current i(k) just sampled, i(k-1) the previous
 * sample and v(k-1) the voltage applied between them:
 *
 *   E = v(k-1) - Rs (i(k) + i(k-1))/2 - Ls (i(k) - i(k-1)) / Ts     (eq. 4)
 *
 * with the current change limited to what the winding allows (FOC_DI_MAX).
 * E belongs to the middle of the last period, so it is turned into the
 * rotor frame with the estimated angle half a period back (eq. 3); below
 * PLL_LOW_SPEED_RPM it is first averaged over 8 periods (making the
 * L di/dt term a difference over 8 samples, as Microchip's code does at
 * low speed) and the angle goes back 4 periods instead.  Ed and Eq are
 * filtered (eq. 7), and
 *
 *   w = (Eqf - sgn(Eqf) Edf) / KFi                                  (eq. 2)
 *
 * is integrated to the angle (eq. 1) and filtered for the speed output.
 * With the rotor ahead of the estimate by d, Ed = -|E| sin d and
 * Eq = |E| cos d, so w = w_true cos d + |w_true| sin d: the estimate speeds
 * up when it lags, in both directions of rotation.
 *
 * Eq. 2 alone holds the angle only where the flux equals KFi: with a
 * magnet k x nominal it settles where cos d + sin d = 1/k (26 deg off at
 * k = 0.75, no lock at all below k = 0.71), and with sgn(Eqf) as in
 * AN1292 it has a second stable point near 100 deg above k = 1
 * (test_estimators case_*_flux_mismatch).  So the sign is the filtered
 * speed output's (the unfiltered w depends on this very term and would
 * chatter), and the numerator gets a flux-tracking term: an integral of
 * -sgn(w) Edf that drives Edf to zero, leaving d = 0 for any k.  It is
 * bounded by |Eqf| (the correction for k down to 0.5), which also empties
 * it as the speed passes through zero.  Slow (a few Hz), it runs in the
 * slow step (foc_pll_track_flux, track_gain per slow tick),
 * which owns flux_track and flux_corr; the step only adds flux_corr.
 *
 * Units: voltages Q15 of the voltage base, EMF Q15 of twice the voltage
 * base (it exceeds the voltage base above base speed), currents Q15 of the
 * current base, speed Q15 of SPEED_BASE_RPM (electrical = mechanical x p),
 * angle uint16 (theta32: uint32, 2^32 = 360 deg, for sub-count
 * resolution).  All products 32-bit; every result saturated to Q15.
 *
 * 1/KFi and Ls are run-time variables so the field-weakening tables can
 * adjust them: inv_kfi is a Q15 mantissa over FOC_PLL_INVKFI_SHIFT (per
 * unit of the half-scale EMF), and
 * ls_scale is Ls/(2 Ls0) in Q15 (0.5 = nominal), AN1292's convention.
 */
#ifndef FOC_PLL_EST_H
#define FOC_PLL_EST_H

#include <stdint.h>
#include "foc/lpf.h"
#include "foc/transforms.h"

#define FOC_PLL_AVG_LOG2 3 /* 8-period average at low speed */
#define FOC_PLL_AVG_N (1u << FOC_PLL_AVG_LOG2)

typedef struct {
    uint32_t theta32;      /* angle at the present sample */
    q15_t omega;           /* unfiltered speed (integrated to the angle) */
    foc_lpf_q15_t ed, eq;  /* filtered rotor-frame EMF */
    foc_lpf_q15_t speed;   /* filtered speed (output) */
    foc_ab_t i_prev;       /* last period's current */
    foc_ab_t e_ring[FOC_PLL_AVG_N]; /* last 8 stator-frame EMFs */
    int32_t e_sum_alpha, e_sum_beta; /* their sums */
    uint8_t e_next;        /* ring index of the oldest */
    uint8_t low_speed;     /* 1: 8-period average in use */
    q15_t inv_kfi;         /* 1/KFi mantissa (shift FOC_PLL_INVKFI_SHIFT) */
    q15_t ls_dt;           /* Ls/Ts mantissa (shift FOC_PLL_LSDT_SHIFT) */
    q15_t rs;              /* [slow] Rs mantissa (FOC_RS2_SHIFT) */
    int32_t flux_track;    /* [slow] flux tracking, half-scale EMF Q15 << 14, |.| <= |Eqf| << 14 */
    q15_t flux_corr;       /* [slow] flux_track >> 14, added to eq. 2's numerator */
    q15_t track_gain;      /* [slow] the flux tracking's gain per slow tick, */
                           /* Q14, 0..16383 (FOC_PLL_TRACK_GAIN_Q14 at reset) */
    uint16_t theta;        /* output angle */
} foc_pll_t;

/* Nominal 1/KFi and Ls; then foc_pll_reset(). */
void foc_pll_init(foc_pll_t *p);

/* Restarts from angle `theta` and speed `speed` with the present current
 * `i_now` (the EMF history is set to what that speed implies). */
void foc_pll_reset(foc_pll_t *p, uint16_t theta, q15_t speed, foc_ab_t i_now);

/* One PWM period; `v_last` is the voltage applied during the period that
 * ended at this sample. */
void foc_pll_step(foc_pll_t *p, foc_ab_t v_last, foc_ab_t i_now);

/* Rs as a ratio to MOTOR_RS_OHM, Q14 (the alignment's measure). */
void foc_pll_set_rs(foc_pll_t *p, q15_t ratio_q14);
/* Slow step: one step of the flux tracking, in every state whose fast
 * step runs the estimator; its reset at each restart. */
void foc_pll_track_flux(foc_pll_t *p);
void foc_pll_track_reset(foc_pll_t *p);
/* Field weakening: 1/KFi as a Q15 mantissa of FOC_PLL_INVKFI_SHIFT
 * (FOC_PLL_INVKFI is nominal) and Ls/(2 Ls0) in Q15 (0.5 nominal, up to
 * 1.0 = twice nominal), times the alignment's Ls ratio (Q14; the product
 * saturates at twice nominal). */
void foc_pll_set_inv_kfi(foc_pll_t *p, q15_t inv_kfi);
void foc_pll_set_ls_scale(foc_pll_t *p, q15_t ls_over_2ls0, q15_t ratio_q14);

static inline q15_t foc_pll_speed(const foc_pll_t *p)
{
    return foc_lpf_out(&p->speed);
}

#endif /* FOC_PLL_EST_H */
