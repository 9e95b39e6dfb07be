/*
 * Flux-linkage estimator and speed observer (foc/flux_est.h,
 * foc/speed_obs.h) on the signals of an ideal motor generated in double
 * precision from the build's userparms.h (tests/common/ideal_pmsm.h): the
 * currents at each sample and the exact average voltage over each period
 * (R times the mean current plus the flux change), optionally with DC
 * offsets on what the estimator sees.
 */
#include <math.h>
#include <stdint.h>

#include "foc/config.h"
#include "foc/flux_est.h"
#include "ideal_pmsm.h"
#include "testkit.h"

#define RPM_TO_WE (MOTOR_POLE_PAIRS * 2.0 * FOC_PI_D / 60.0)

static const ideal_pmsm_params_t motor = IDEAL_PMSM_USERPARMS;

static void motor_init(ideal_pmsm_t *m, double theta_deg, double rpm, double iq)
{
    ideal_pmsm_init(m, &motor, theta_deg * FOC_PI_D / 180.0, rpm * RPM_TO_WE, 0.0, iq);
}

static double angle_err_deg(const foc_flux_est_t *f, const ideal_pmsm_t *m)
{
    return ideal_pmsm_angle_err_deg(f->theta, m);
}

static double speed_rpm(const foc_flux_est_t *f)
{
    return foc_flux_speed(f) * (SPEED_BASE_RPM / 32768.0);
}

static void step(foc_flux_est_t *f, ideal_pmsm_t *m, double accel, double iq_end)
{
    ideal_pmsm_period(m, accel, iq_end);
    foc_flux_step(f, m->v_last, m->i_now, ideal_q15(iq_end / FOC_I_BASE_A));
}

typedef struct {
    double rms_deg, peak_deg, speed_peak_rpm;
} errs_t;

/* Runs n periods at constant speed and measures the last `window`. */
static errs_t run_steady(foc_flux_est_t *f, ideal_pmsm_t *m, long n, long window)
{
    errs_t e = { 0.0, 0.0, 0.0 };
    double sum = 0.0;
    for (long k = 0; k < n; k++) {
        step(f, m, 0.0, m->iq_a);
        if (k >= n - window) {
            const double a = angle_err_deg(f, m);
            sum += a * a;
            e.peak_deg = fmax(e.peak_deg, fabs(a));
            e.speed_peak_rpm =
                fmax(e.speed_peak_rpm, fabs(speed_rpm(f) - m->we_rad_s / RPM_TO_WE));
        }
    }
    e.rms_deg = sqrt(sum / (double)window);
    return e;
}

/* From an unknown position (estimator reset at angle 0 and standstill)
 * the angle and speed converge, in both directions, with and without a
 * q current (a load the observer has to learn); 2500 rpm keeps the
 * voltage within the linear range at 0.8 A. */
static void case_converges_both_directions(void)
{
    static const double rpms[] = { 1000.0, -1000.0, 300.0, -300.0, 2500.0, -2500.0 };
    static const double iqs[] = { 0.0, 0.8, -0.8 };
    const foc_ab_t zero = { 0, 0 };
    for (size_t i = 0; i < sizeof rpms / sizeof rpms[0]; i++) {
        for (size_t j = 0; j < sizeof iqs / sizeof iqs[0]; j++) {
            ideal_pmsm_t m;
            foc_flux_est_t f;
            motor_init(&m, 77.0 + 40.0 * (double)i, rpms[i], iqs[j]);
            foc_flux_reset(&f, 0, 0, zero);
            const errs_t e = run_steady(&f, &m, (long)(0.3 / FOC_TS_S), (long)(0.05 / FOC_TS_S));
            printf("%6.0f rpm iq %4.1f A: angle rms %.4f peak %.4f deg, speed peak err %.3f rpm\n",
                   rpms[i], iqs[j], e.rms_deg, e.peak_deg, e.speed_peak_rpm);
            TK_CHECK(e.peak_deg < 0.3, "%.0f rpm %.1f A: peak %.3f deg", rpms[i], iqs[j],
                     e.peak_deg);
            TK_CHECK(e.speed_peak_rpm < 0.002 * fabs(rpms[i]) + 0.5,
                     "%.0f rpm %.1f A: speed err %.3f rpm", rpms[i], iqs[j], e.speed_peak_rpm);
        }
    }
}

/* From an unknown position the flux is an offset that only rotation
 * reveals: within 5 deg for good after at most two electrical turns, from
 * any initial error, at low and medium speed in both directions. */
static void case_unknown_start_rotation(void)
{
    static const double rpms[] = { 100.0, 300.0, -300.0, 1000.0 };
    const foc_ab_t zero = { 0, 0 };
    for (size_t i = 0; i < sizeof rpms / sizeof rpms[0]; i++) {
        double worst_rad = 0.0;
        for (double a = -165.0; a < 180.0; a += 30.0) {
            ideal_pmsm_t m;
            foc_flux_est_t f;
            motor_init(&m, a, rpms[i], 0.0);
            foc_flux_reset(&f, 0, 0, zero);
            const long n = (long)(8.0 * 2.0 * FOC_PI_D / fabs(m.we_rad_s) / FOC_TS_S);
            long last_out = 0;
            for (long k = 1; k <= n; k++) {
                step(&f, &m, 0.0, 0.0);
                if (fabs(angle_err_deg(&f, &m)) > 5.0) {
                    last_out = k;
                }
            }
            worst_rad = fmax(worst_rad, fabs(m.we_rad_s) * (double)last_out * FOC_TS_S);
        }
        printf("%5.0f rpm: within 5 deg after %.1f electrical rad (worst initial angle)\n",
               rpms[i], worst_rad);
        TK_CHECK(worst_rad < 4.0 * FOC_PI_D, "%.0f rpm: %.1f rad", rpms[i], worst_rad);
    }
}

/* Reset from the true angle and speed (hand-over): no transient. */
static void case_reset_handover(void)
{
    static const double rpms[] = { 500.0, -2000.0 };
    for (size_t i = 0; i < 2; i++) {
        ideal_pmsm_t m;
        foc_flux_est_t f;
        motor_init(&m, 200.0, rpms[i], 0.8);
        foc_flux_reset(&f, (uint16_t)(200.0 / 360.0 * 65536.0),
                       ideal_q15(rpms[i] / SPEED_BASE_RPM), m.i_now);
        const errs_t e = run_steady(&f, &m, 2000, 2000);
        printf("hand-over %6.0f rpm: angle peak %.4f deg, speed peak err %.3f rpm\n", rpms[i],
               e.peak_deg, e.speed_peak_rpm);
        TK_CHECK(e.peak_deg < 0.3, "peak %.3f deg", e.peak_deg);
        TK_CHECK(e.speed_peak_rpm < 2.0, "speed err %.3f rpm", e.speed_peak_rpm);
    }
}

/* DC offsets on the measured currents (1 % of full scale, several ADC
 * codes more than a calibration leaves) and on the voltages (0.1 V): the
 * estimator integrates the offset voltage e = Rs i_off + v_off, so a pure
 * integrator would drift without bound.  Here the flux stays near the
 * magnet-flux circle and the angle error stays within about |e| / back-EMF
 * (checked with 25 % + 1 deg margin), no larger after 20 s than after 2 s.
 * At standstill nothing tells the flux from its offset: the angle is lost
 * but the state stays bounded, |psi_r| <= psi_m + |e| / k_min. */
static void case_drift_bounded_with_offsets(void)
{
    static const double rpms[] = { 500.0, -200.0, 0.0 };
    const double i_off[2] = { 0.01 * FOC_I_BASE_A, -0.007 * FOC_I_BASE_A };
    const double v_off[2] = { 0.1, 0.07 };
    const double e_off =
        hypot(MOTOR_RS_OHM * i_off[0] + v_off[0], MOTOR_RS_OHM * i_off[1] + v_off[1]);
    const long n = (long)(20.0 / FOC_TS_S);
    const long early = (long)(2.0 / FOC_TS_S);
    const long window = (long)(0.5 / FOC_TS_S);
    for (size_t i = 0; i < 3; i++) {
        ideal_pmsm_t m;
        foc_flux_est_t f;
        motor_init(&m, 30.0, rpms[i], 0.5);
        foc_flux_reset(&f, (uint16_t)(30.0 / 360.0 * 65536.0), ideal_q15(rpms[i] / SPEED_BASE_RPM),
                       m.i_now);
        for (int a = 0; a < 2; a++) {
            m.i_off_a[a] = i_off[a];
            m.v_off_v[a] = v_off[a];
        }
        double peak_early = 0.0, peak_late = 0.0, flux_min = 1e9, flux_max = 0.0;
        for (long k = 0; k < n; k++) {
            step(&f, &m, 0.0, m.iq_a);
            const double a = fabs(angle_err_deg(&f, &m));
            if (k >= early - window && k < early) {
                peak_early = fmax(peak_early, a);
            }
            if (k >= n - window) {
                peak_late = fmax(peak_late, a);
            }
            const double mag = hypot(f.psi_r.alpha, f.psi_r.beta) / FOC_FLUX_PSI_M;
            if (k >= early) {
                flux_min = fmin(flux_min, mag);
                flux_max = fmax(flux_max, mag);
            }
        }
        const double emf = fabs(rpms[i]) * RPM_TO_WE * FOC_FLUX_WB;
        printf("offsets (%.3f V) at %4.0f rpm: angle peak %.2f deg (2 s) %.2f deg (20 s), "
               "|psi_r| / psi_m %.3f..%.3f\n",
               e_off, rpms[i], peak_early, peak_late, flux_min, flux_max);
        if (rpms[i] != 0.0) {
            const double bound = 1.25 * e_off / emf * 180.0 / FOC_PI_D + 1.0;
            TK_CHECK(peak_late < bound && peak_late < peak_early + 0.5,
                     "angle peak %.2f deg at 20 s, %.2f at 2 s (bound %.2f)", peak_late,
                     peak_early, bound);
            TK_CHECK(flux_min > 0.7 && flux_max < 1.3, "|psi_r| %.3f..%.3f", flux_min, flux_max);
        } else {
            const double bound = 1.0 + e_off / (FLUX_CORR_MIN_RAD_S * FOC_FLUX_WB) + 0.1;
            TK_CHECK(flux_max < bound, "|psi_r| %.3f psi_m (bound %.3f)", flux_max, bound);
        }
    }
}

/* The observer follows a speed ramp with the torque command fed forward,
 * with a small lag: 200 -> 2000 rpm at 20000 rpm/s (q current from
 * J dw/dt = Te), then back down, in both directions. */
static void case_speed_ramp_feedforward(void)
{
    const double ramp_rpm_s = 20000.0;
    const double accel_m = ramp_rpm_s * 2.0 * FOC_PI_D / 60.0; /* mechanical */
    const double iq_acc = MOTOR_INERTIA_KGM2 * accel_m / (1.5 * MOTOR_POLE_PAIRS * FOC_FLUX_WB);
    static const double dirs[] = { 1.0, -1.0 };
    for (size_t d = 0; d < 2; d++) {
        const double s = dirs[d];
        ideal_pmsm_t m;
        foc_flux_est_t f;
        motor_init(&m, 10.0, s * 200.0, 0.0);
        foc_flux_reset(&f, (uint16_t)(10.0 / 360.0 * 65536.0),
                       ideal_q15(s * 200.0 / SPEED_BASE_RPM), m.i_now);
        (void)run_steady(&f, &m, 2000, 1);
        double lag_peak = 0.0, angle_peak = 0.0;
        const long n_ramp = (long)(1800.0 / ramp_rpm_s / FOC_TS_S);
        for (int leg = 0; leg < 2; leg++) {
            const double a = (leg == 0 ? s : -s) * accel_m * MOTOR_POLE_PAIRS;
            const double iq = (leg == 0 ? s : -s) * iq_acc;
            for (long k = 0; k < n_ramp; k++) {
                step(&f, &m, a, iq);
                if (k > 200) { /* after the current step's first periods */
                    lag_peak = fmax(lag_peak, fabs(speed_rpm(&f) - m.we_rad_s / RPM_TO_WE));
                    angle_peak = fmax(angle_peak, fabs(angle_err_deg(&f, &m)));
                }
            }
        }
        printf("ramp %+.0f rpm/s (iq %.3f A): speed error peak %.3f rpm, angle peak %.3f deg\n",
               s * ramp_rpm_s, iq_acc, lag_peak, angle_peak);
        TK_CHECK(lag_peak < 3.0, "speed lag %.3f rpm", lag_peak);
        TK_CHECK(angle_peak < 0.5, "angle %.3f deg", angle_peak);
    }
}

/* A load the feed-forward does not know (the q current holds the speed
 * against it): the observer's load state takes it up and the speed error
 * returns to zero. */
static void case_observer_learns_load(void)
{
    ideal_pmsm_t m;
    foc_flux_est_t f;
    motor_init(&m, 0.0, 800.0, 0.0);
    foc_flux_reset(&f, 0, ideal_q15(800.0 / SPEED_BASE_RPM), m.i_now);
    (void)run_steady(&f, &m, 1000, 1);
    m.iq_a = 1.2; /* balances a load: no acceleration */
    const errs_t e = run_steady(&f, &m, (long)(0.1 / FOC_TS_S), (long)(0.02 / FOC_TS_S));
    const double load_a = f.obs.load / 134217728.0 * FOC_I_BASE_A;
    printf("unknown load: speed err peak %.3f rpm, load estimate %.3f A (1.2)\n",
           e.speed_peak_rpm, load_a);
    TK_CHECK(e.speed_peak_rpm < 1.0, "speed err %.3f rpm", e.speed_peak_rpm);
    TK_CHECK(fabs(load_a - 1.2) < 0.01, "load %.3f A", load_a);
}

TK_CASES(TK_CASE(case_converges_both_directions), TK_CASE(case_unknown_start_rotation),
         TK_CASE(case_reset_handover),
         TK_CASE(case_drift_bounded_with_offsets), TK_CASE(case_speed_ramp_feedforward),
         TK_CASE(case_observer_learns_load))
