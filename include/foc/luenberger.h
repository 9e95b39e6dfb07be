/*
 * Luenberger back-EMF observer + PLL (ST's sensorless scheme: docs/references.md
 * [ST-FOC]).
 *
 * Motor model in the stator frame, L = Lq and e the extended back-EMF,
 * which rotates with the rotor:
 *
 *   L di/dt = v - Rs i - e          de/dt = w J e,   J = [0 -1; 1 0]
 *
 *   e = ((Ld - Lq)(w id - d iq/dt) + w psi) (-sin theta, cos theta)
 *
 * exact for a salient rotor too (a round one has e = w psi (...)): written
 * on Lq, the stator-frame model loses its 2-theta terms and keeps them as
 * an EMF along q.  It turns at w (the model's de/dt) while id and iq are
 * steady; its amplitude over w, psi + (Ld - Lq) id, is the "active flux",
 * which the PLL's integrator takes as a flux error (field weakening of the
 * interior-magnet motor: +8 %).  Modelled on the mean inductance instead,
 * the 2-theta terms stay in the current equation as an error the
 * observer turns into an angle error: 1.7 deg at rated current on the
 * torture's interior-magnet motor (Ld/Lq = 0.85; 0.2 deg on Lq).
 *
 * Observer, once per PWM period k, with i(k) just sampled and v(k-1) the
 * voltage applied during the period that ended at that sample:
 *
 *   i^- = i^ + (-C1 i^ - C3 e^ + C5 v(k-1)) / F1   prediction of i(k)
 *   err = i^- - i(k)                               innovation, Q15
 *   i^  = i^- + C2 err / F1                        (C2 = F1 K1 / fs < 0)
 *   e^  = e^  + C4 err / F2                        e^: EMF over the period
 *                                                  that ended, centre t - T/2
 *   PLL on e^ (below), then e^ = e^ + h J e^, h = w T, the EMF predicted
 *   for the coming period.
 *
 * PLL (ST's: the angle without atan).  With the rotor angle ahead of the
 * PLL's by d, e^ projected on the PLL's axes (half a period back, where
 * e^ belongs) is e_d = -|e| sgn(w) sin d, e_q = |e| sgn(w) cos d, so
 *   w^ = e_q + Kp g s + Ki sum(g g_w s),   s = c sin d,   sin d = -sgn(w) e_d / |e|
 * with c = min(1, |w^ filtered| / (1/64 of the speed base)),
 * g = min(1, |e| / e_max) and g_w = min(1, |w^ filtered| / e_max), e_max
 * the EMF at maximum speed (below), and the angle integrates w^.  Kp and Ki are ST's.  The speed output is
 * w^ through a first-order filter (LUENBERGER_SPEED_FILTER_TIME_S).
 *
 * Differences from ST, and why:
 * - the innovation is formed against the prediction of the sample just
 *   taken and applied at once (predictor-corrector), instead of one period
 *   later: the estimate uses i(k) in the period it is sampled, with the same
 *   constants and the same cost;
 * - C1, C3 and C5 are the exact (zero-order-hold) discretisation of the
 *   winding, C1 = F1 (1 - exp(-Rs T/Ls)) and T/Ls replaced by
 *   (1 - exp(-Rs T/Ls))/Rs, rather than forward Euler: Euler's error acts
 *   like Rs (i(k) - i(k-1))/2, a voltage 90 degrees from the current that
 *   turns the estimated EMF by up to 0.4 degrees under load;
 * - the phase detector is divided by max(|e^|, e_max) (the inverse
 *   tracked by one Newton step per period, no division; e_max =
 *   FOC_LUEN_PLL_FULL_AMP, the EMF at LUENBERGER_PLL_FULL_SPEED_RPM,
 *   default the maximum speed, where ST's Kp and Ki are designed), and
 *   the integrator's input is multiplied by g_w, the filtered speed over
 *   e_max: Kp acts as Kp g, Ki as Ki g g_w, and in a lock at nominal
 *   flux g_w = g, so the PLL's natural frequency follows the speed (a
 *   fixed fraction of the electrical frequency: 0.61 on the Hurst075) at
 *   ST's maximum-speed damping (0.79) at every speed.  g_w rather than g
 *   a second time: where the PLL runs ahead of its EMF (a held rotor
 *   whose unmodelled resistance drop turns with the current, which the
 *   PLL turns: regress/24) its integrator speeds up with it, to its
 *   bound, where the stall check's EMF test trips (0.12 s; 0.29 s with
 *   g^2, 0.175 s before the scaling).  In
 *   ST's loop the gain is proportional to |e| in both terms: natural
 *   frequency and damping fall as sqrt(speed) (600 rad/s and 0.42 at
 *   1000 rpm on the Hurst075), no faster than our 600 rad/s speed loop,
 *   and the two oscillated together below 2000 rpm.  Divided by |e^|
 *   alone (ST's maximum-speed dynamics, 1124 rad/s, at every speed, as
 *   this observer had before issue 13), an error in the EMF's angle
 *   reaches w^, relative to the speed, with the gain Kp / |e|: 6.8 per
 *   radian at 500 rpm on the Hurst075, against 0.97 in ST's loop and 1 in
 *   the AN1292 PLL's.  The dead time's voltage error near zero
 *   current, which no bridge model resolves from a 10-bit sample, made
 *   w^ swing by +-300 rpm at 500 rpm on the switched bridge and the
 *   speed loop drive iq through zero into more of it (a limit cycle near
 *   3 f_e; docs/estimators.md, "The Luenberger observer on the switched
 *   bridge");
 * - the speed has e_q as a feed-forward (the EMF base makes it the speed
 *   at nominal flux), so the PI only turns the angle and its integrator
 *   holds the flux error.  Without it the speed lagged the rotor by the
 *   PLL's dynamics (52 degrees at 700 rad/s against 31 with it) and, with
 *   a motor whose inductance differs from the model (the angle error is
 *   then proportional to Iq, so a PLL speed carries a d(Iq)/dt term), the
 *   speed loop oscillated and lost the rotor;
 * - the integrator is bounded to |e_q|/2 + 1/64 of the speed base (flux
 *   errors up to 50 %): the PLL cannot claim a speed its EMF does not
 *   show.  Unbounded, it held any speed when the only "EMF" was the
 *   dead-time voltage error, which follows the current and so turns with
 *   the estimate (ST's reported false convergence with a held rotor);
 * - the phase detector is multiplied by the direction of rotation, so the
 *   correct lock, not the one 180 degrees off, is the stable one in both
 *   directions.  The direction is the sign of the filtered speed with a
 *   hysteresis of 1/64 of the speed base (noise near standstill does not
 *   flip it), and the phase detector is weighted by |filtered speed| over
 *   that hysteresis (capped at 1): near zero speed e_q, which changes sign
 *   with the rotation, carries the PLL through a reversal, instead of a
 *   full-gain push based on a direction not yet updated (which ran the
 *   motor away when a stop braked it slightly through zero);
 * - the filtered speed also turns the EMF model (ST uses the PLL's
 *   output: the filter keeps the PI's noise out of the model, and the
 *   model turns at the estimated speed even while the proportional term
 *   carries it).
 *
 * Units: states in 32 bits with extra resolution, current Q15 of the
 * current base x F1, EMF Q15 of the EMF base x F2 (EMF base = the back-EMF
 * at SPEED_BASE_RPM, so |e^| in Q15 equals |speed| in Q15 at nominal flux);
 * v Q15 of the voltage base; speed Q15 of SPEED_BASE_RPM; angle uint16
 * (theta32: uint32, 2^32 = 360 deg).  Every state is saturated to +-1.0 of
 * its base each period (a current or EMF beyond full scale is a fault, not
 * a state to track), the innovation and the speed to +-1.0, so the state
 * is bounded whatever the inputs; config.h checks at compile time that no
 * 32-bit sum can overflow and that the observer error dynamics are stable.
 *
 * No division per period.  The open-loop angle atan2(e^) is computed on
 * request (foc_luen_theta_atan), as a diagnostic, so its division stays
 * out of the period.
 */
#ifndef FOC_LUENBERGER_H
#define FOC_LUENBERGER_H

#include <stdint.h>
#include "foc/lpf.h"
#include "foc/transforms.h"

typedef struct {
    int32_t alpha; /* Q15 x F (F1 for currents, F2 for EMFs) */
    int32_t beta;
} foc_luen_ab32_t;

typedef struct {
    foc_luen_ab32_t i_est; /* estimated current at the last sample, Q15 x F1 */
    foc_luen_ab32_t e_est; /* estimated EMF for the coming period, Q15 x F2 */
    int32_t integ;         /* PLL integrator, Q30 speed: the flux error, */
                           /* |.| <= (|emf_speed|/2 + 512) x 2^15 */
    q15_t emf_speed;       /* e_q: speed at nominal flux, Q15 */
    uint8_t forward;       /* direction of rotation, 1 = positive */
    int32_t inv_amp;       /* 1/max(|e^|, FOC_LUEN_PLL_FULL_AMP), Q9 of */
                           /* 1/(EMF base), 1..32767 */
    uint32_t theta32;      /* PLL angle at the next sample */
    uint16_t theta;        /* output: angle at the last sample */
    q15_t omega;           /* PLL speed (unfiltered), Q15 */
    foc_lpf_q15_t speed;   /* output: filtered speed, Q15 */
    q15_t c1, c2, c3, c4, c5; /* [slow] the model's constants for the */
                           /* measured Rs, Ls (FOC_LUEN_C1..C5 nominal) */
    q15_t pll_kp;          /* the PLL's kp mantissa (FOC_LUEN_PLL_KP_SHIFT) */
    q15_t pll_ki;          /* and ki, Q15, 0..32767: the build's at reset */
} foc_luenberger_t;

/* Restarts from angle `theta` and speed `speed` with the present current
 * `i_now`: the EMF is set to what that speed implies (on the q axis, half a
 * period ahead), the direction to the sign of `speed`.  Also initialises
 * (the nominal Ls). */
void foc_luen_reset(foc_luenberger_t *l, uint16_t theta, q15_t speed, foc_ab_t i_now);

/* Rs and Ls as ratios to MOTOR_RS_OHM and MOTOR_LQ_H, Q14
 * (the alignment's measures), held within the constants' formats
 * (config.h FOC_LUEN_RATIO_MIN/MAX, FOC_LUEN_X_RATIO_MIN/MAX).  An Rs
 * the model does not know shows its extra drop as a back-EMF: a stalled
 * rotor's current would look like a turning one's. */
void foc_luen_set_winding(foc_luenberger_t *l, q15_t rs_ratio_q14, q15_t ls_ratio_q14);

/* One PWM period; `v_last` is the voltage applied during the period that
 * ended at this sample, `i_now` the current just sampled. */
void foc_luen_step(foc_luenberger_t *l, foc_ab_t v_last, foc_ab_t i_now);

/* Filtered speed, Q15. */
static inline q15_t foc_luen_speed(const foc_luenberger_t *l)
{
    return foc_lpf_out(&l->speed);
}

/* Estimated EMF for the coming period, Q15 of the EMF base (the back-EMF
 * at SPEED_BASE_RPM). */
foc_ab_t foc_luen_emf(const foc_luenberger_t *l);

/* Diagnostic: the open-loop angle atan2 of the estimated EMF at the last
 * sample (no PLL; one division), same scaling as `theta`. */
uint16_t foc_luen_theta_atan(const foc_luenberger_t *l);

#endif /* FOC_LUENBERGER_H */
