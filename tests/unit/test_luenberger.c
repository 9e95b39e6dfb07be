/*
 * Luenberger observer + PLL (foc/luenberger.h) on ideal motor signals
 * (tests/common/ideal_pmsm.h): a rotor turning at a given (or ramping)
 * speed with constant dq currents, the winding voltage averaged over each
 * period exactly as the PWM applies it, computed in double precision from
 * the motor of the build's userparms.h.  The estimator runs open loop (its
 * angle drives nothing).
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "foc/config.h"
#include "foc/luenberger.h"
#include "ideal_pmsm.h"
#include "testkit.h"

#define PI_D 3.14159265358979323846

static const ideal_pmsm_params_t motor = IDEAL_PMSM_USERPARMS;

static double rpm_to_we(double rpm) { return rpm * MOTOR_POLE_PAIRS * 2.0 * PI_D / 60.0; }

/* One period at electrical acceleration `accel` (rad/s^2), the currents
 * constant: the voltage applied during it and the current at its end. */
static void motor_period(ideal_pmsm_t *m, double accel, foc_ab_t *v_last, foc_ab_t *i_now)
{
    ideal_pmsm_period(m, accel, m->iq_a);
    const double v = hypot(m->v_ab_v[0], m->v_ab_v[1]);
    /* a voltage beyond the base cannot be applied: the case is wrong */
    TK_CHECK(v < FOC_V_BASE_V, "test voltage %.2f V beyond the base", v);
    *v_last = m->v_last;
    *i_now = m->i_now;
}

static double speed_rpm(q15_t s) { return s * SPEED_BASE_RPM / 32768.0; }

typedef struct {
    double rms_deg, peak_deg;  /* angle error over the window */
    double speed_err_pct;      /* mean speed error over the window, % */
    double settle_s;           /* last time the error exceeded 2 deg */
} result_t;

/* Runs `seconds` at electrical acceleration `accel` (rad/s^2), measuring
 * over the last `window_s`. */
static void run(foc_luenberger_t *l, ideal_pmsm_t *m, double accel, double seconds,
                double window_s, result_t *r)
{
    const long n = (long)(seconds / FOC_TS_S + 0.5);
    const long from = n - (long)(window_s / FOC_TS_S + 0.5);
    double sum2 = 0.0, sum_speed = 0.0, sum_true = 0.0;
    const double t0 = m->t_s;
    r->peak_deg = 0.0;
    r->settle_s = 0.0;
    for (long k = 0; k < n; k++) {
        foc_ab_t v, i;
        motor_period(m, accel, &v, &i);
        foc_luen_step(l, v, i);
        const double e = ideal_pmsm_angle_err_deg(l->theta, m);
        if (fabs(e) > 2.0) {
            r->settle_s = m->t_s - t0;
        }
        if (k >= from) {
            sum2 += e * e;
            r->peak_deg = fmax(r->peak_deg, fabs(e));
            sum_speed += speed_rpm(foc_luen_speed(l));
            sum_true += m->we_rad_s * 60.0 / (2.0 * PI_D * MOTOR_POLE_PAIRS);
        }
    }
    r->rms_deg = sqrt(sum2 / (double)(n - from));
    r->speed_err_pct = 100.0 * (sum_speed - sum_true) / fabs(sum_true);
}

static void start(foc_luenberger_t *l, ideal_pmsm_t *m, double rpm, double iq_a,
                  double theta_deg)
{
    const foc_ab_t zero = { 0, 0 };
    ideal_pmsm_init(m, &motor, theta_deg * PI_D / 180.0, rpm_to_we(rpm), 0.0, iq_a);
    foc_luen_reset(l, 0, 0, zero); /* rotor position and speed unknown */
}

/* From an unknown angle at standstill of the estimate, with the rotor
 * already turning: locks in both directions, with and without load
 * current (motoring and braking), within 0.1 s; then angle error RMS
 * <= 0.2 deg, peak <= 0.5 deg, mean speed error <= 0.1 %.  Speeds up to
 * 70 % of the maximum, where 0.8 A still fits the voltage base. */
static void case_converges_both_directions(void)
{
    const double top = 0.7 * MOTOR_MAX_SPEED_RPM;
    const double rpms[] = { 500.0, 1000.0, top, -500.0, -1000.0, -top };
    const double iqs[] = { 0.0, 0.8, -0.8 };
    double worst_rms = 0.0, worst_peak = 0.0, worst_speed = 0.0, worst_settle = 0.0;
    for (size_t i = 0; i < sizeof rpms / sizeof rpms[0]; i++) {
        for (size_t j = 0; j < sizeof iqs / sizeof iqs[0]; j++) {
            foc_luenberger_t l;
            ideal_pmsm_t m;
            result_t r;
            start(&l, &m, rpms[i], iqs[j], 123.0 + 50.0 * (double)i);
            run(&l, &m, 0.0, 0.3, 0.1, &r);
            TK_CHECK(r.rms_deg <= 0.2 && r.peak_deg <= 0.5, "%.0f rpm iq %.1f A: angle rms %.3f "
                     "peak %.3f deg", rpms[i], iqs[j], r.rms_deg, r.peak_deg);
            TK_CHECK(fabs(r.speed_err_pct) <= 0.1, "%.0f rpm iq %.1f A: speed error %.3f %%",
                     rpms[i], iqs[j], r.speed_err_pct);
            TK_CHECK(r.settle_s <= 0.1, "%.0f rpm iq %.1f A: settles in %.3f s", rpms[i], iqs[j],
                     r.settle_s);
            worst_rms = fmax(worst_rms, r.rms_deg);
            worst_peak = fmax(worst_peak, r.peak_deg);
            worst_speed = fmax(worst_speed, fabs(r.speed_err_pct));
            worst_settle = fmax(worst_settle, r.settle_s);
        }
    }
    printf("luenberger: worst angle rms %.3f deg, peak %.3f deg, speed %.4f %%, "
           "settling %.1f ms\n", worst_rms, worst_peak, worst_speed, 1000.0 * worst_settle);
}

/* Low speed (2 % of the maximum, both directions): angle RMS <= 1 deg. */
static void case_low_speed(void)
{
    const double rpm = 0.02 * MOTOR_MAX_SPEED_RPM;
    for (int dir = -1; dir <= 1; dir += 2) {
        foc_luenberger_t l;
        ideal_pmsm_t m;
        result_t r;
        start(&l, &m, dir * rpm, 0.3, 40.0);
        run(&l, &m, 0.0, 1.0, 0.3, &r);
        printf("luenberger %.0f rpm: angle rms %.3f deg, peak %.3f deg, speed %.3f %%\n",
               dir * rpm, r.rms_deg, r.peak_deg, r.speed_err_pct);
        TK_CHECK(r.rms_deg <= 1.0 && fabs(r.speed_err_pct) <= 1.0, "%.0f rpm: rms %.3f deg, "
                 "speed %.3f %%", dir * rpm, r.rms_deg, r.speed_err_pct);
    }
}

/* Hand-over: reset with the true angle, speed and current, the estimate
 * stays within 0.5 deg from the first period on. */
static void case_reset_is_bumpless(void)
{
    const double rpms[] = { 1000.0, -2000.0 };
    for (size_t i = 0; i < 2; i++) {
        foc_luenberger_t l;
        ideal_pmsm_t m;
        result_t r;
        start(&l, &m, rpms[i], 0.8, 200.0);
        foc_luen_reset(&l, (uint16_t)lround(200.0 / 360.0 * 65536.0),
                       FOC_SPEED_Q15(rpms[i]), m.i_now);
        run(&l, &m, 0.0, 0.05, 0.05, &r);
        printf("luenberger hand-over %.0f rpm: peak %.3f deg\n", rpms[i], r.peak_deg);
        TK_CHECK(r.peak_deg <= 0.5, "%.0f rpm: peak %.3f deg after reset", rpms[i], r.peak_deg);
    }
}

/* Acceleration 300 -> 2400 rpm in 0.3 s (7000 rpm/s) with 0.5 A after
 * locking: peak error during the ramp <= 2 deg, both directions. */
static void case_follows_ramp(void)
{
    for (int dir = -1; dir <= 1; dir += 2) {
        foc_luenberger_t l;
        ideal_pmsm_t m;
        result_t r;
        start(&l, &m, dir * 300.0, 0.5 * dir, 10.0);
        run(&l, &m, 0.0, 0.2, 0.05, &r);
        /* from here the rotor accelerates, from 300 rpm to 2400 rpm */
        run(&l, &m, rpm_to_we(dir * 7000.0), 0.3, 0.3, &r);
        printf("luenberger ramp %+.0f rpm/s: peak %.3f deg, rms %.3f deg\n", dir * 7000.0,
               r.peak_deg, r.rms_deg);
        TK_CHECK(r.peak_deg <= 2.0, "ramp: peak %.3f deg", r.peak_deg);
    }
}

/* The open-loop atan2 diagnostic agrees with the rotor within 0.5 deg
 * once locked, and the EMF amplitude equals the speed (EMF base). */
static void case_atan_and_emf(void)
{
    const double rpms[] = { 1000.0, -1500.0 };
    for (size_t i = 0; i < 2; i++) {
        foc_luenberger_t l;
        ideal_pmsm_t m;
        result_t r;
        start(&l, &m, rpms[i], 0.8, 300.0);
        run(&l, &m, 0.0, 0.2, 0.05, &r);
        double worst = 0.0;
        for (int k = 0; k < 400; k++) {
            foc_ab_t v, cur;
            motor_period(&m, 0.0, &v, &cur);
            foc_luen_step(&l, v, cur);
            worst = fmax(worst, fabs(ideal_pmsm_angle_err_deg(foc_luen_theta_atan(&l), &m)));
        }
        const foc_ab_t e = foc_luen_emf(&l);
        const double amp = hypot(e.alpha, e.beta);
        const double want = fabs((double)FOC_SPEED_Q15(rpms[i]));
        printf("luenberger atan %.0f rpm: angle off by %.3f deg, |e| / want - 1 = %.5f\n",
               rpms[i], worst, amp / want - 1.0);
        TK_CHECK(worst <= 0.5, "%.0f rpm: atan angle off by %.3f deg", rpms[i], worst);
        TK_CHECK(fabs(amp / want - 1.0) <= 0.01, "%.0f rpm: |e| %.0f want %.0f", rpms[i], amp,
                 want);
    }
}

/* Absurd inputs (random full-scale voltages and currents, constant
 * extremes): every state stays within its documented range each period,
 * and consistent signals afterwards bring the estimate back. */
static void case_bounded_with_absurd_inputs(void)
{
    foc_luenberger_t l;
    ideal_pmsm_t m;
    result_t r;
    const int32_t i_max = 32767 * (int32_t)LUENBERGER_F1;
    const int32_t e_max = 32767 * (int32_t)LUENBERGER_F2;
    uint32_t seed = 1u;
    start(&l, &m, 1000.0, 0.5, 0.0);
    int bad = 0;
    for (long k = 0; k < 400000L; k++) {
        foc_ab_t v, i;
        seed = seed * 1664525u + 1013904223u;
        const int mode = (int)((k / 20000) % 4);
        if (mode == 0) {
            v.alpha = (q15_t)((int32_t)(seed >> 16) - 32768);
            v.beta = (q15_t)((int32_t)(seed & 0xFFFFu) - 32768);
            i.alpha = (q15_t)((int32_t)((seed >> 8) & 0xFFFFu) - 32768);
            i.beta = (q15_t)(-i.alpha - 1);
        } else if (mode == 1) {
            v.alpha = v.beta = Q15_MIN;
            i.alpha = i.beta = Q15_MAX;
        } else if (mode == 2) {
            v.alpha = v.beta = Q15_MAX;
            i.alpha = i.beta = Q15_MIN;
        } else {
            v.alpha = (k & 1) ? Q15_MAX : Q15_MIN;
            v.beta = (k & 2) ? Q15_MAX : Q15_MIN;
            i.alpha = (k & 4) ? Q15_MAX : Q15_MIN;
            i.beta = (k & 8) ? Q15_MAX : Q15_MIN;
        }
        foc_luen_step(&l, v, i);
        const int ok = labs((long)l.i_est.alpha) <= i_max && labs((long)l.i_est.beta) <= i_max &&
                       labs((long)l.e_est.alpha) <= e_max && labs((long)l.e_est.beta) <= e_max &&
                       l.inv_amp >= 1 && l.inv_amp <= 32767 && l.forward <= 1u;
        if (!ok && bad++ < 5) {
            TK_CHECK(ok, "k=%ld: state out of range i %ld %ld e %ld %ld inv %ld", k,
                     (long)l.i_est.alpha, (long)l.i_est.beta, (long)l.e_est.alpha,
                     (long)l.e_est.beta, (long)l.inv_amp);
        }
    }
    /* back to a real motor: relocks without a reset */
    run(&l, &m, 0.0, 0.5, 0.1, &r);
    printf("luenberger after absurd inputs: angle rms %.3f deg, settled after %.1f ms\n",
           r.rms_deg, 1000.0 * r.settle_s);
    TK_CHECK(r.rms_deg <= 0.2 && r.settle_s <= 0.3, "relock: rms %.3f deg, settle %.3f s",
             r.rms_deg, r.settle_s);
}

TK_CASES(TK_CASE(case_converges_both_directions), TK_CASE(case_low_speed),
         TK_CASE(case_reset_is_bumpless), TK_CASE(case_follows_ramp),
         TK_CASE(case_atan_and_emf), TK_CASE(case_bounded_with_absurd_inputs))
