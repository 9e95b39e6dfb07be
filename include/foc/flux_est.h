/*
 * Flux-linkage position estimator (docs/references.md [WLG]) with the
 * closed-loop speed observer of speed_obs.h.
 *
 * Per PWM period k, with v(k-1) the voltage applied between the samples
 * i(k-1) and i(k):
 *
 * 1. Stator flux by integration (eq. 4), trapezoidal in the current:
 *      psi_s(k) = psi_s(k-1) + Ts (v(k-1) - Rs (i(k) + i(k-1)) / 2)
 * 2. Rotor position predicted by the second-order fit (eq. 16):
 *      theta_p(k) = 3 theta(k-1) - 3 theta(k-2) + theta(k-3)
 * 3. Flux correction (eq. 15, 17): the current the model expects at the
 *    predicted angle is i^ = (psi_s - psi_m e^(j theta_p)) / Ls, and the
 *    flux error Ls (i - i^) = psi_m e^(j theta_p) - psi_r, with
 *    psi_r = psi_s - Ls i the rotor flux, is added with a gain
 *    g = (k_min + c |w|) Ts (FLUX_CORR_MIN_RAD_S, FLUX_CORR_PER_SPEED):
 *      psi_s += g (R e^(j theta_p) - psi_r)
 *    Its radial part pulls the rotor flux onto a circle of radius R, which
 *    bounds the drift of the integrator: a flux offset (unknown initial
 *    flux) is shed within one to two electrical turns, and a constant
 *    offset voltage e (current or voltage offsets) leaves an angle error of
 *    about |e| / back-EMF instead of a ramp.  Its tangential part pulls
 *    toward the extrapolated angle; exact for constant acceleration, it
 *    adds no lag.
 * 4. Position from the current error (eq. 9-13): solved exactly, it is
 *    the angle of psi_r, theta(k) = atan2(psi_r).
 * 5. Speed: the speed observer driven by theta(k) and the torque command.
 *
 * The radius R is learned: the component of psi_r along e^(j theta_p),
 * low-passed at FLUX_MAG_PER_SPEED |w| (well below the rotor frequency),
 * starting from and held within [0.5, 1.5] psi_m.  An offset makes that
 * component swing at the rotor frequency and is still corrected, but a
 * steady radial error -- the q-axis voltage error e_q of an Rs error or of
 * dead time, divided by w; a magnet flux changed by temperature, the
 * disturbance the paper names as the largest -- is not fought: fighting
 * it with the fixed psi_m turns it into an angle error of about
 * c e_q / back-EMF.  What remains is the d-axis voltage error / back-EMF
 * and the Ls error times iq / psi_m.
 *
 * Departures from the paper (whose eq. 6-17 are partly garbled in the
 * OCR; read as above): the per-phase current errors divided by
 * sin(theta + n 120 deg) and averaged (eq. 11, 13) are replaced by the
 * exact alpha-beta solution, since the per-phase division is singular at
 * each zero crossing; the correction (eq. 17) is added with the gain g < 1
 * rather than in full (in full it would replace the integrated flux by the
 * extrapolation and discard the measurement), toward the learned radius
 * rather than psi_m; and psi_r uses Lq, so it is the "active flux",
 * aligned with the d axis also for a salient rotor (its magnitude is then
 * psi_m + (Ld - Lq) id, which the learned radius follows slowly).  The
 * paper obtains the initial flux by aligning the rotor; here an unknown
 * initial flux is corrected as an offset, which takes rotation (a
 * hand-over with a known angle uses foc_flux_reset).
 *
 * Units: flux per unit of FOC_FLUX_BASE_WB (config.h): the integrator
 * state is Q31 (v Ts per period is a few Q15 counts at the lowest speeds:
 * 16 extra fraction bits), psi_r Q15.  Voltages Q15 of the voltage base,
 * currents Q15 of the current base, speed Q15 of SPEED_BASE_RPM, angle
 * uint16 (65536 = 360 deg).  No division other than the one in
 * foc_atan2_q15.
 */
#ifndef FOC_FLUX_EST_H
#define FOC_FLUX_EST_H

#include <stdint.h>
#include "foc/speed_obs.h"
#include "foc/transforms.h"

typedef struct {
    q31_t psi_alpha, psi_beta; /* stator flux, Q31 of the flux base */
    q31_t psi_m;               /* learned magnet flux (circle radius), Q31 */
    foc_ab_t psi_r;            /* rotor (active) flux at the sample, Q15 */
    foc_ab_t i_prev;           /* last sample's current, Q15 */
    int16_t dtheta1, dtheta2;  /* last two angle steps, counts per period */
    uint16_t theta;            /* rotor angle at the sample (output) */
    foc_speed_obs_t obs;       /* speed (output) */
    q15_t rs;                  /* [slow] Rs mantissa (FOC_RS2_SHIFT) */
    q15_t ls;                  /* [slow] Ls, Q15 of the flux base per */
                               /* current base (FOC_FLUX_LS nominal) */
    q15_t corr_min;            /* the correction's gain per period (k_min */
    q15_t corr_speed;          /* + c |w|) Ts: k_min Ts and c w_base Ts, */
                               /* Q15, 0..32767 (FOC_FLUX_CORR_* at reset) */
} foc_flux_est_t;

/* Restarts from angle `theta` and speed `speed` (Q15) with the present
 * current `i_now`: the flux is set to what they imply and the speed
 * observer's load to the present q current (hand-over from another angle
 * source at steady speed); Rs and Ls nominal (foc_flux_set_rs, _ls). */
void foc_flux_reset(foc_flux_est_t *f, uint16_t theta, q15_t speed, foc_ab_t i_now);

/* Rs as a ratio to MOTOR_RS_OHM, Q14 (the alignment's measure). */
void foc_flux_set_rs(foc_flux_est_t *f, q15_t ratio_q14);
/* Ls as a ratio to MOTOR_LQ_H, Q14 within [0.5, 2) (the alignment's). */
void foc_flux_set_ls(foc_flux_est_t *f, q15_t ratio_q14);

/* One PWM period: `v_last` applied during the period that ended at this
 * sample, `i_now` measured now, `iq_ref` the q-current command (torque
 * feed-forward of the speed observer). */
void foc_flux_step(foc_flux_est_t *f, foc_ab_t v_last, foc_ab_t i_now, q15_t iq_ref);

/* 1 while the learned magnet flux is inside its range: pinned at 0.5 or
 * 1.5 x psi_m, no magnet the model accepts explains the voltages (a
 * winding resistance far from the estimator's, a rotor pulled out of step
 * while the estimate turns on: issue 10 finding 2, regress/2b). */
uint8_t foc_flux_consistent(const foc_flux_est_t *f);

static inline q15_t foc_flux_speed(const foc_flux_est_t *f)
{
    return foc_speed_obs_speed(&f->obs);
}

#endif /* FOC_FLUX_EST_H */
