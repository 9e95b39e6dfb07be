/*
 * focsim's `plant` options reach the motor model: `plant realistic` sets
 * exactly the documented realistic set (README.md, "Plant options"), and
 * the drive still starts and holds 1000 rpm on it; the Luenberger
 * observer's start to 500 rpm on the switched bridge; a winding that warms
 * up in a run.
 */
#include <math.h>
#include <stdio.h>

#include "foc/config.h"
#include "estimator_metrics.h"
#include "scenario_run.h"
#include "testkit.h"

/* After the first period of "0 plant realistic", the model's parameters
 * are the realistic set: switched bridge, the build's sampling instant
 * (this build, userparms.h.in, keeps SAMPLE_DELAY_PERIODS at its 1.5: the
 * sample at the period start, not mid-period), 2 codes of noise, the
 * board's dead time PWM_DEADTIME_S, gains +2/-2/0 %, 3 % 5th and 1 % 7th
 * EMF harmonics; everything else as userparms.h. */
FOC_STATIC_ASSERT(SAMPLE_DELAY_PERIODS == 1.5, "test_plant_options expects the default 1.5-period build");
static void case_realistic_sets_the_set(void)
{
    scn_t scn;
    char err[256];
    TK_CHECK(scn_parse_text("0 plant deadtime 0\n0 plant realistic\n0.001 end\n", "t", &scn,
                            err, sizeof err) == 0,
             "%s", err);
    sim_options_t opt;
    sim_default_options(&opt);
    static sim_t sim;
    TK_CHECK(sim_init(&sim, &opt, &scn, err, sizeof err) == 0, "sim_init: %s", err);
    TK_CHECK(sim_step(&sim, NULL) == 1, "first period");
    const pmsm_params_t *p = &sim.model.p;
    TK_CHECK(p->switched == 1 && p->sample_mid_period == 0, "switched %d midsample %d",
             p->switched, p->sample_mid_period);
    TK_CHECK(p->noise_codes == 2.0, "noise %g", p->noise_codes);
    TK_CHECK(p->deadtime_s == PWM_DEADTIME_S, "dead time %g s", p->deadtime_s);
    TK_CHECK(p->gain_error[0] == 0.02 && p->gain_error[1] == -0.02 && p->gain_error[2] == 0.0,
             "gains %g %g %g", p->gain_error[0], p->gain_error[1], p->gain_error[2]);
    TK_CHECK(p->emf_h5 == 0.03 && p->emf_h7 == 0.01, "harmonics %g %g", p->emf_h5, p->emf_h7);
    TK_CHECK(p->rs_ohm == MOTOR_RS_OHM && p->cogging_nm == 0.0 && p->thermal_r_k_per_w == 0.0 &&
                 p->ld_sat_a == 0.0 && p->lq_sat_a == 0.0,
             "options outside the set changed");
    scn_free(&scn);
}

/* On the realistic plant the default estimator starts from standstill and
 * holds 1000 rpm without a fault: mean speed over 0.8-1.0 s within
 * `tol` rpm; and on the realistic plant whose motor is also off the
 * controller's parameters (scenario_run.h's mismatch: Rs +30 %, L -20 %,
 * flux +10 %). */
static void realistic_runs(int mm, double tol)
{
    char text[512];
    run_t r;
    run_scenario(run_text(text, sizeof text, mm,
                          "0 plant realistic\n0 start\n0 speed 1000\n1.0 end\n"),
                 FOC_ESTIMATOR, &r);
    const double speed = run_mean_speed(&r, 0.8, 1.0);
    printf("  realistic plant%s: RUN at %.3f s, final %s %s, mean speed %.2f rpm (limit +-%.1f)\n",
           mm ? " with the mismatch" : "", run_first_state(&r, 0.0, "RUN"),
           foc_state_name(r.final_state), foc_fault_name(r.fault), speed, tol);
    TK_CHECK(r.final_state == FOC_STATE_RUN && r.fault == 0, "final %s %s",
             foc_state_name(r.final_state), foc_fault_name(r.fault));
    TK_CHECK(fabs(speed - 1000.0) < tol, "speed %.1f rpm", speed);
    run_free(&r);
}

/* Measured: 0.16 rpm off (seed 1; 0.40 when the limit 2 rpm was set);
 * 0.08 rpm on the mismatch. */
static void case_realistic_runs(void) { realistic_runs(0, 0.6); }
static void case_realistic_runs_mismatch(void) { realistic_runs(1, 0.3); }

/* The Luenberger observer's start to 500 rpm on the switched bridge
 * (estimator_metrics.h); limits about 3.5-4 x what is measured (seed 1):
 * angle RMS 1.25 / 1.88 / 1.72 deg, speed error RMS 17.5 / 26.2 / 36.4
 * rpm (over seeds 1-8 2.8 / 3.1-3.8 / 1.6-2.7 deg and 44 / 45-54 / 32-43
 * rpm when the limits were 10 / 12 / 8 deg and 150 / 160 / 130 rpm,
 * before the switched bridge took a pulse shorter than the dead time
 * right). */
static void case_luenberger_500rpm_switched(void)
{
    static const est_switched_limits_t lim[3] = { { 5.0, 70.0 }, { 7.5, 105.0 }, { 7.0, 130.0 } };
    TK_CHECK(est_luenberger_500rpm_switched("hurst075", lim), "see the lines above");
}

/* The winding warming up in a run: on the realistic plant with 0.1 Nm
 * (the Hurst075's rated torque, applied in four steps so that the light
 * rotor is not stopped by the step), the model's Rs rises by 40 % in 4 %
 * steps every 0.2 s from 2.0 s.  The drive stays in RUN without a fault
 * and the angle error RMS stays within `limit_deg` in each 0.5 s window
 * from 2.5 s.
 *
 * At 500 and 1000 rpm (the build's options: RS_ADAPTATION off) the d
 * current is about 0, the Rs error only scales the EMF and the controller
 * keeps the Rs it measured at the alignment; the 3 deg holds.  Measured (seed
 * 1), largest window, deg: PLL 2.05 (500 rpm), 1.43 (1000); Luenberger
 * 2.02, 1.21; flux 1.64 at 1000 rpm.  The flux estimator at 500 rpm is
 * not held (a false SPEED_FEEDBACK at 3.2 s; docs/estimators.md,
 * "Resistance drift").
 *
 * At 2000 rpm field weakening drives id to -1.47 A, the Rs error times id
 * lies across the EMF (10.6 / 10.7 / 12.4 deg without adaptation): with
 * RS_ADAPTATION on (focsim --rs-adapt on) rs_adapt.c follows Rs, within
 * the 3 deg.  Measured: PLL 2.19, Luenberger 2.53, flux 2.33 deg
 * (2.59 / 2.76 / 2.76 until the switched bridge took a pulse shorter than
 * the dead time right; 3.56 / 3.64 / 3.66 with the one-probe Ld that came
 * out 9 % low). */
static void rs_drift(foc_est_kind_t kind, double speed_rpm, int rs_adapt, double limit_deg)
{
    char text[1024];
    int len = snprintf(text, sizeof text,
                       "0 plant realistic\n0 start\n0.1 speed %g\n1.0 load 0.025\n1.1 load 0.05\n"
                       "1.2 load 0.075\n1.3 load 0.1\n",
                       speed_rpm);
    for (int k = 1; k <= 10; k++) {
        len += snprintf(text + len, sizeof text - (size_t)len, "%.1f plant rs %.9g\n",
                        2.0 + 0.2 * k, MOTOR_RS_OHM * (1.0 + 0.04 * k));
    }
    snprintf(text + len, sizeof text - (size_t)len, "4.5 end\n");
    sim_options_t opt;
    sim_default_options(&opt);
    opt.estimator = kind;
    opt.rs_adapt = rs_adapt;
    run_t r;
    run_scenario_with(text, &opt, &r);
    TK_CHECK(r.final_state == FOC_STATE_RUN && r.fault == 0, "%s %g rpm: final %s %s",
             foc_est_name(kind), speed_rpm, foc_state_name(r.final_state), foc_fault_name(r.fault));
    for (double t = 2.5; t < 4.4; t += 0.5) {
        run_est_errors_t e;
        run_est_errors(&r, t, t + 0.5, &e);
        const size_t n = run_index_at(&r, t + 0.5) - run_index_at(&r, t);
        printf("  %s %g rpm, Rs drift, %.1f-%.1f s: angle rms %.2f deg (limit %.1f), %zu of %zu rows in RUN\n",
               foc_est_name(kind), speed_rpm, t, t + 0.5, e.angle_rms_deg, limit_deg, e.n_run, n);
        TK_CHECK(e.n_run == n && e.angle_rms_deg <= limit_deg, "%s %g rpm %.1f s: angle rms %.2f deg",
                 foc_est_name(kind), speed_rpm, t, e.angle_rms_deg);
    }
    run_free(&r);
}

static void case_rs_drift(void)
{
    rs_drift(FOC_EST_PLL, 500.0, -1, 3.0);
    rs_drift(FOC_EST_PLL, 1000.0, -1, 3.0);
    rs_drift(FOC_EST_LUENBERGER, 500.0, -1, 3.0);
    rs_drift(FOC_EST_LUENBERGER, 1000.0, -1, 3.0);
    rs_drift(FOC_EST_FLUX, 1000.0, -1, 3.0);
}

static void case_rs_drift_field_weakening(void)
{
    rs_drift(FOC_EST_PLL, 2000.0, 1, 3.0);
    rs_drift(FOC_EST_LUENBERGER, 2000.0, 1, 3.0);
    rs_drift(FOC_EST_FLUX, 2000.0, 1, 3.0);
}

TK_CASES(TK_CASE(case_realistic_sets_the_set), TK_CASE(case_realistic_runs),
         TK_CASE(case_realistic_runs_mismatch),
         TK_CASE(case_luenberger_500rpm_switched), TK_CASE(case_rs_drift),
         TK_CASE(case_rs_drift_field_weakening))
