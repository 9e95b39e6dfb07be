/*
 * Ideal-machine signals for the estimator unit tests (tests/unit): what an
 * ideal PMSM fed by an ideal inverter shows the estimators, computed in
 * double precision from the machine equations.  No saturation, harmonics,
 * dead time, ADC or PWM ripple: for those the tests use the plant
 * (tools/plant).  The rotor's speed and the currents are imposed (no
 * mechanics, no current loop), so the estimator runs open loop.
 *
 * Conventions (those of the core and of the plant):
 *   - alpha/beta: amplitude-invariant Clarke (alpha = phase a; a phase
 *     amplitude of 1 gives a vector of magnitude 1);
 *   - theta: electrical angle from alpha to the rotor's d axis (the magnet's
 *     flux), rad, counter-clockwise positive; we = dtheta/dt, electrical
 *     rad/s (mechanical x pole pairs), signed;
 *   - rotor-frame currents id, iq (A): i_ab = (id + j iq) e^(j theta);
 *   - stator flux linkage (Wb):
 *       psi_ab = ((Ld id + psi_m) + j Lq iq) e^(j theta),
 *     and the winding voltage v = Rs i + d psi / dt (V).
 *
 * Timing, as the estimators take their inputs: sample k is the instant at
 * which the current i(k) is read; v_last is the voltage applied between
 * samples k-1 and k, its mean over that PWM period (what the PWM's average
 * applies).  The mean is exact for the flux term, (psi(k) - psi(k-1)) / Ts,
 * and the midpoint rule over IDEAL_PMSM_SUBSTEPS points for Rs i (relative
 * error of the order of (we Ts / IDEAL_PMSM_SUBSTEPS)^2 / 24).
 *
 * Q15: x / base rounded to nearest, ties up (floor(32768 x + 0.5)), and
 * saturated to [-32768, 32767].
 */
#ifndef IDEAL_PMSM_H
#define IDEAL_PMSM_H

#include <stdint.h>
#include "foc/transforms.h" /* foc_ab_t, q15_t */

#define IDEAL_PMSM_SUBSTEPS 16 /* midpoints per period for the mean Rs i */

typedef struct {
    double rs_ohm;         /* winding resistance, ohm */
    double ld_h, lq_h;     /* d and q inductance, H */
    double flux_wb;        /* magnet flux linkage psi_m, Wb (peak, per phase) */
    double ts_s;           /* PWM period, s */
    double v_base_v;       /* voltage of Q15 1.0, V */
    double i_base_a;       /* current of Q15 1.0, A */
} ideal_pmsm_params_t;

/* The motor and bases of the build's userparms.h (include foc/config.h
 * first): an initialiser for ideal_pmsm_params_t. */
#define IDEAL_PMSM_USERPARMS                                                   \
    { MOTOR_RS_OHM, MOTOR_LD_H, MOTOR_LQ_H, FOC_FLUX_WB, FOC_TS_S, FOC_V_BASE_V, \
      FOC_I_BASE_A }

/* The state at the present sample.  theta_rad, we_rad_s, id_a, iq_a and
 * the offsets may be set directly between periods (a step at the sample
 * instant); ideal_pmsm_sample() then refreshes i_now. */
typedef struct {
    ideal_pmsm_params_t p;
    double t_s;            /* time of the present sample, s (0 at init) */
    double theta_rad;      /* electrical angle, rad, within (-2 pi, 2 pi) */
    double we_rad_s;       /* electrical speed, rad/s */
    double id_a, iq_a;     /* rotor-frame currents, A */
    double i_off_a[2];     /* added to the alpha/beta current the estimator sees, A */
    double v_off_v[2];     /* added to the alpha/beta voltage the estimator sees, V */
    double v_ab_v[2];      /* mean alpha/beta voltage over the last period, V (no offset) */
    double i_ab_a[2];      /* alpha/beta current at the present sample, A (no offset) */
    foc_ab_t v_last;       /* (v_ab_v + v_off_v) / v_base_v, Q15 */
    foc_ab_t i_now;        /* (i_ab_a + i_off_a) / i_base_a, Q15 */
} ideal_pmsm_t;

/* Rotor at electrical angle `theta_rad` turning at `we_rad_s`, currents
 * id, iq; t = 0, no offsets, v_last zero (no period has passed), i_now
 * sampled. */
void ideal_pmsm_init(ideal_pmsm_t *m, const ideal_pmsm_params_t *p, double theta_rad,
                     double we_rad_s, double id_a, double iq_a);

/* One PWM period: the rotor turns at constant electrical acceleration
 * `accel_rad_s2` (speed and angle exact), iq moves linearly from its
 * present value to `iq_end_a` (id constant); then v_last holds the mean
 * voltage over the period and i_now the new sample. */
void ideal_pmsm_period(ideal_pmsm_t *m, double accel_rad_s2, double iq_end_a);

/* i_ab_a and i_now from the present state (after setting it directly). */
void ideal_pmsm_sample(ideal_pmsm_t *m);

/* x (already divided by its base) in Q15: rounded, saturated. */
q15_t ideal_q15(double x);

/* Estimated angle (uint16, 2^16 = 360 deg) minus the true one, deg, in
 * [-180, 180]. */
double ideal_pmsm_angle_err_deg(uint16_t estimate, const ideal_pmsm_t *m);

#endif /* IDEAL_PMSM_H */
