/*
 * The application on the build's motor (Hurst075 by default) with its
 * configured estimator (PLL): sensorless start-up, field weakening, stall
 * detection, fault classes and braking.  Every case runs on the nominal
 * plant and, as case_*_mismatch, on the stated controller-plant mismatch
 * (scenario_run.h: Rs +30 %, L -20 %, flux +10 %, 2 codes of ADC noise,
 * the board's dead time); and as case_*_realistic on issue 13's `plant
 * realistic`, on top of the mismatch as case_*_realistic_mismatch.
 * Limits: the application issue's where they are within about 5 x what
 * is measured, else about 3-5 x the measured figure or a closed form (in
 * the comments: nominal / mismatch).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "foc/config.h"
#include "scenario_run.h"
#include "testkit.h"

#define LIMIT_A (1.05 * CURRENT_LIMIT_A) /* limit + 5 % */

/* The scenario on the nominal plant, or after the mismatch's lines. */
static void run_est(const char *scenario, int mm, foc_est_kind_t est, run_t *r)
{
    char text[1024];
    run_scenario(run_text(text, sizeof text, mm, scenario), est, r);
}

static void run_default(const char *scenario, int mm, run_t *r)
{
    run_est(scenario, mm, FOC_ESTIMATOR, r);
}

static void run_opt(const char *scenario, int mm, const sim_options_t *opt, run_t *r)
{
    char text[1024];
    run_scenario_with(run_text(text, sizeof text, mm, scenario), opt, r);
}

static const char *plant_name(int mm)
{
    static const char *const names[] = { "", " [mismatch]", " [realistic]",
                                         " [realistic, mismatch]" };
    return names[mm & (RUN_MISMATCH | RUN_REALISTIC)];
}

/* 12 rotor angles x loads {0, 0.02, 0.05} Nm x inertia {1, 5} x default:
 * every start reaches RUN and then the commanded 1000 rpm (the mean over
 * 1.4-1.6 s within `speed_dev_max` rpm), within `t_run_max` s, with
 * estimator `est`; on `plant realistic` (issue 13's set: the switched
 * bridge, the board's sampling instant, noise, sensor gains, EMF
 * harmonics) where `realistic`, on top of the mismatch where both. */
static void startup_matrix_on(foc_est_kind_t est, int mm, int realistic, double speed_dev_max,
                              double t_run_max)
{
    const double loads[] = { 0.0, 0.02, 0.05 };
    const double inertias[] = { 1.0, 5.0 };
    int ok = 0, total = 0;
    double worst = 0.0, worst_dev = 0.0;
    char worst_case[96] = "";
    for (size_t j = 0; j < 2; j++) {
        for (size_t l = 0; l < 3; l++) {
            for (int a = 0; a < 360; a += 30) {
                char text[256];
                snprintf(text, sizeof text,
                         "%s0 plant j %g\n0 angle %d\n0 load %g\n0 start\n0 speed 1000\n1.6 end\n",
                         realistic ? "0 plant realistic\n" : "", inertias[j] * MOTOR_INERTIA_KGM2, a,
                         loads[l]);
                run_t r;
                run_est(text, mm, est, &r);
                const double t_run = run_first_state(&r, 0.0, "RUN");
                const double speed = run_mean_speed(&r, 1.4, 1.6);
                const int good = t_run >= 0.0 && r.final_state == FOC_STATE_RUN && r.fault == 0 &&
                                 fabs(speed - 1000.0) <= speed_dev_max;
                total++;
                ok += good;
                worst_dev = fmax(worst_dev, fabs(speed - 1000.0));
                if (!good) {
                    printf("start FAILED: angle %d load %.2f inertia %.0fx: RUN at %.3f s, "
                           "final %s %s, speed %.1f\n",
                           a, loads[l], inertias[j], t_run, foc_state_name(r.final_state),
                           foc_fault_name(r.fault), speed);
                }
                if (t_run > worst) {
                    worst = t_run;
                    snprintf(worst_case, sizeof worst_case, "angle %d deg, %.2f Nm, %.0fx J", a,
                             loads[l], inertias[j]);
                }
                run_free(&r);
            }
        }
    }
    printf("start-up (%s)%s%s: %d/%d reached RUN and 1000 rpm (worst mean %.2f rpm off, limit "
           "%.2f); worst start->RUN %.1f ms (%s; limit %.0f)\n",
           foc_est_name(est), realistic ? " [realistic]" : "", plant_name(mm), ok, total, worst_dev, speed_dev_max, worst * 1e3,
           worst_case, t_run_max * 1e3);
    TK_CHECK(ok == total, "%d of %d starts failed", total - ok, total);
    TK_CHECK(worst <= t_run_max, "worst start->RUN %.1f ms", worst * 1e3);
}

static void startup_matrix(foc_est_kind_t est, int mm, double speed_dev_max, double t_run_max)
{
    startup_matrix_on(est, mm, 0, speed_dev_max, t_run_max);
}

/* Measured, PLL / Luenberger / flux: the mean speed at most 0.12 / 0.06 /
 * 0.05 rpm off (0.19 / 0.22 / 0.18 on the mismatch; the limit was 20
 * rpm, then 1.0 and 1.5 on 0.22-0.49), start->RUN 391.0 / 393.5 / 399.5
 * ms at worst (389.5 / 391.5 / 391.0; the 500 ms kept: 1.3 x).
 * Limits about 4 x the speed figures. */
static void case_startup_matrix(void) { startup_matrix(FOC_ESTIMATOR, 0, 0.5, 0.5); }
static void case_startup_matrix_mismatch(void) { startup_matrix(FOC_ESTIMATOR, 1, 0.8, 0.5); }
static void case_startup_matrix_luenberger(void) { startup_matrix(FOC_EST_LUENBERGER, 0, 0.25, 0.5); }
static void case_startup_matrix_luenberger_mismatch(void)
{
    startup_matrix(FOC_EST_LUENBERGER, 1, 0.9, 0.5);
}
static void case_startup_matrix_flux(void) { startup_matrix(FOC_EST_FLUX, 0, 0.25, 0.5); }
static void case_startup_matrix_flux_mismatch(void) { startup_matrix(FOC_EST_FLUX, 1, 0.8, 0.5); }
/* On `plant realistic` (issue 13), measured PLL / Luenberger / flux: 72 of
 * 72 each, the mean speed at most 0.34 / 0.30 / 0.36 rpm off (the PLL on
 * the mismatch too: 0.34; 0.89 / 1.44 / 1.07 and 0.48 before the switched
 * bridge took a pulse shorter than the dead time right, when the limits
 * were 3.0 / 5.0 / 4.0 and 2.0), start->RUN 387.5 / 397.0 / 411.0 ms at
 * worst (396.5); limits about 4 x the speed figures, the 500 ms. */
static void case_startup_matrix_realistic(void)
{
    startup_matrix_on(FOC_ESTIMATOR, 0, 1, 1.4, 0.5);
}
static void case_startup_matrix_luenberger_realistic(void)
{
    startup_matrix_on(FOC_EST_LUENBERGER, 0, 1, 1.2, 0.5);
}
static void case_startup_matrix_flux_realistic(void)
{
    startup_matrix_on(FOC_EST_FLUX, 0, 1, 1.5, 0.5);
}
static void case_startup_matrix_realistic_mismatch(void)
{
    startup_matrix_on(FOC_ESTIMATOR, 1, 1, 1.4, 0.5);
}

/* A rotor locked before `start` never reaches RUN: STARTUP_FAILED when
 * the start-up times out, CALIB_TIME_S + STARTUP_TIMEOUT_S after the
 * start, within one slow tick (measured: exactly then; the limit was
 * that + 10 ms, with no lower bound), outputs off. */
static void locked_rotor_fails_startup(int mm)
{
    for (int a = 0; a < 360; a += 90) {
        char text[128];
        snprintf(text, sizeof text, "0 lock\n0 angle %d\n0 start\n0 speed 1000\n2.0 end\n", a);
        run_t r;
        run_default(text, mm, &r);
        const double t_fault = run_first_fault(&r, 0.0, "STARTUP_FAILED");
        const double expect = CALIB_TIME_S + STARTUP_TIMEOUT_S;
        const double i_after = run_max_phase_current(&r, t_fault + 0.005, 2.0);
        printf("locked rotor at %3d deg%s: STARTUP_FAILED at %.4f s (expected %.4f s +- %.4f s), "
               "RUN %s, then %.4f A\n",
               a, plant_name(mm), t_fault, expect, FOC_SLOW_TS_S,
               run_first_state(&r, 0.0, "RUN") < 0 ? "never" : "REACHED", i_after);
        TK_CHECK(run_first_state(&r, 0.0, "RUN") < 0.0, "angle %d: reached RUN", a);
        TK_CHECK(fabs(t_fault - expect) <= FOC_SLOW_TS_S,
                 "angle %d: fault at %.4f s", a, t_fault);
        const size_t k = run_index_at(&r, t_fault);
        TK_CHECK(k < r.n && r.rows[k].bridge == PMSM_BRIDGE_OFF, "angle %d: outputs on", a);
        TK_CHECK(i_after < 0.01, "angle %d: current %.4f A", a, i_after);
        run_free(&r);
    }
}

static void case_locked_rotor_fails_startup(void) { locked_rotor_fails_startup(0); }
static void case_locked_rotor_fails_startup_mismatch(void) { locked_rotor_fails_startup(1); }
static void case_locked_rotor_fails_startup_realistic(void)
{
    locked_rotor_fails_startup(RUN_REALISTIC);
}
static void case_locked_rotor_fails_startup_realistic_mismatch(void)
{
    locked_rotor_fails_startup(RUN_REALISTIC | RUN_MISMATCH);
}

/* The plant of a variant: magnet flux, Rs, Ld = Lq (round rotor), and
 * the back-EMF's 5th and 7th harmonics (`plant realistic`: 3 % and 1 %,
 * README.md "Plant options"). */
typedef struct {
    double psi, rs, l, h5, h7;
} plant_t;

static plant_t plant_of(int mm)
{
    const int m = (mm & RUN_MISMATCH) != 0;
    const int real = (mm & RUN_REALISTIC) != 0;
    const plant_t p = { (m ? 1.1 : 1.0) * FOC_FLUX_WB, (m ? 1.3 : 1.0) * MOTOR_RS_OHM,
                        (m ? 0.8 : 1.0) * MOTOR_LD_H, real ? 0.03 : 0.0, real ? 0.01 : 0.0 };
    return p;
}

/* Closed forms in double, steady state: the voltage amplitude the plant
 * needs at `rpm` with the load `load_nm` (plus userparms.h's friction)
 * and the d current `id`, where the magnet's EMF per speed is (kd, kq):
 * vd = Rs id - w L iq + w kd, vq = Rs iq + w (kq + L id), iq from the
 * mean torque 1.5 p psi iq. */
static double plant_voltage_at(const plant_t *p, double rpm, double load_nm, double id, double kd,
                               double kq)
{
    const double w = rpm * MOTOR_POLE_PAIRS * 2.0 * FOC_PI_D / 60.0;
    const double friction = MOTOR_VISCOUS_NM_PER_KRPM * rpm / 1000.0 + MOTOR_COULOMB_NM;
    const double iq = (load_nm + friction) / (1.5 * MOTOR_POLE_PAIRS * p->psi);
    const double vd = p->rs * id - w * p->l * iq + w * kd;
    const double vq = p->rs * iq + w * (kq + p->l * id);
    return sqrt(vd * vd + vq * vq);
}

/* The fundamental's (what field weakening's voltage mode regulates, a
 * mean over the slow ticks). */
static double plant_voltage(const plant_t *p, double rpm, double load_nm, double id)
{
    return plant_voltage_at(p, rpm, load_nm, id, 0.0, p->psi);
}

/* The largest over the EMF harmonics' turn (6 theta: kd = -psi (h5 + h7)
 * sin 6 theta, kq = psi (1 + (h7 - h5) cos 6 theta), the plant's
 * magnet_emf_per_speed), which the limit on each period's command must
 * hold for the currents to stay constant. */
static double plant_peak_voltage(const plant_t *p, double rpm, double load_nm, double id)
{
    double peak = 0.0;
    for (int k = 0; k < 360; k++) {
        const double a = (double)k * (2.0 * FOC_PI_D / 360.0);
        const double kd = -p->psi * (p->h5 + p->h7) * sin(a);
        const double kq = p->psi * (1.0 + (p->h7 - p->h5) * cos(a));
        peak = fmax(peak, plant_voltage_at(p, rpm, load_nm, id, kd, kq));
    }
    return peak;
}

/* The voltage limit VOLTAGE_LIMIT_FRACTION x Vdc / sqrt(3), and field
 * weakening's target, FW_VOLTAGE_MARGIN x that. */
#define V_MAX_V (VOLTAGE_LIMIT_FRACTION * BOARD_VDC_NOMINAL_V / 1.7320508075688772)
#define V_FW_V (FW_VOLTAGE_MARGIN * V_MAX_V)

/* The speed at which the plant needs `v` with d current `id`, at the
 * peak over the EMF harmonics' turn (`peak` 1) or for the fundamental
 * (bisection: the voltage rises with the speed). */
static double speed_at_voltage(const plant_t *p, double load_nm, double id, double v, int peak)
{
    double lo = 0.0, hi = 4.0 * MOTOR_MAX_SPEED_RPM;
    for (int k = 0; k < 60; k++) {
        const double rpm = 0.5 * (lo + hi);
        const double need = peak ? plant_peak_voltage(p, rpm, load_nm, id)
                                 : plant_voltage(p, rpm, load_nm, id);
        if (need > v) {
            hi = rpm;
        } else {
            lo = rpm;
        }
    }
    return 0.5 * (lo + hi);
}

/* The d current, within [-FW_ID_MAX_A, 0], that needs `v` at `rpm`
 * (bisection: the voltage falls as id goes negative). */
static double id_at_voltage(const plant_t *p, double rpm, double load_nm, double v)
{
    double lo = -FW_ID_MAX_A, hi = 0.0;
    for (int k = 0; k < 60; k++) {
        const double id = 0.5 * (lo + hi);
        if (plant_voltage(p, rpm, load_nm, id) > v) {
            hi = id;
        } else {
            lo = id;
        }
    }
    return 0.5 * (lo + hi);
}

/* The speed a command reaches with the load: the command, or, where the
 * voltage limit runs out with field weakening at -FW_ID_MAX_A, that speed
 * (`peak` as in speed_at_voltage). */
static double reachable_rpm_at(const plant_t *p, double command_rpm, double load_nm, int peak)
{
    const double limit = speed_at_voltage(p, load_nm, -FW_ID_MAX_A, V_MAX_V, peak);
    return fabs(command_rpm) < limit ? command_rpm : copysign(limit, command_rpm);
}

/* The same where the limit holds every period's voltage: at the peak. */
static double reachable_rpm(const plant_t *p, double command_rpm, double load_nm)
{
    return reachable_rpm_at(p, command_rpm, load_nm, 1);
}

/* 4000 rpm asked, above the motor's maximum: the command is clamped to
 * MOTOR_MAX_SPEED_RPM (3500 rpm, 1.75x nominal), which on 24 V needs field
 * weakening; held with 0.015 Nm, current within the limit, no fault.
 * Closed form: the speed reached (3500 rpm, or where the voltage runs out
 * with -FW_ID_MAX_A: the mismatch's flux +10 % and Rs +30 % with the
 * load) within `dev_max` rpm, and the d current the voltage mode settles
 * on, the one whose voltage is its target (or -FW_ID_MAX_A), within
 * `id_tol` A; where the speed is limited, the controller says so over
 * the last 0.1 s. */
static void field_weakening_max_speed(int mm, double dev_max, double id_tol)
{
    run_t r;
    run_default("0 start\n0 speed 4000\n1.2 load 0.015\n2.0 end\n", mm, &r);
    const double no_load = run_mean_speed(&r, 1.0, 1.2);
    const double loaded = run_mean_speed(&r, 1.8, 2.0);
    const double peak = run_max_phase_current(&r, 0.0, 2.0);
    double id = 0.0;
    const size_t k0 = run_index_at(&r, 1.9);
    for (size_t k = k0; k < r.n; k++) {
        id += r.rows[k].id_a / (double)(r.n - k0);
    }
    const plant_t p = plant_of(mm);
    const double want_free = reachable_rpm(&p, MOTOR_MAX_SPEED_RPM, 0.0);
    const double want_loaded = reachable_rpm(&p, MOTOR_MAX_SPEED_RPM, 0.015);
    const int limited = want_loaded < MOTOR_MAX_SPEED_RPM;
    const double id_expect = limited ? -FW_ID_MAX_A : id_at_voltage(&p, want_loaded, 0.015, V_FW_V);
    const double share = run_share_limited(&r, 1.9, 2.0);
    printf("field weakening%s: %.2f rpm no load (closed form %.2f), %.2f rpm with 0.015 Nm "
           "(closed form %.2f; limit +-%.1f), peak %.3f A, id %.4f A (closed form %.4f A, "
           "+-%.4f), speed_limited %.0f %% of the last 0.1 s\n",
           plant_name(mm), no_load, want_free, loaded, want_loaded, dev_max, peak, id, id_expect,
           id_tol, 100.0 * share);
    TK_CHECK(fabs(no_load - want_free) <= dev_max, "no load %.1f rpm", no_load);
    /* With the EMF harmonics (`plant realistic`) the limit on each
     * period's voltage clips their peaks: the speed may lie between the
     * closed form at the peak and the one for the fundamental. */
    const double upper = reachable_rpm_at(&p, MOTOR_MAX_SPEED_RPM, 0.015, 0);
    TK_CHECK(loaded >= want_loaded - dev_max && loaded <= fmin(upper + dev_max, MOTOR_MAX_SPEED_RPM + 1.0),
             "loaded %.1f rpm (closed forms %.1f at the EMF's peak, %.1f for the fundamental)", loaded,
             want_loaded, upper);
    TK_CHECK(fabs(id - id_expect) <= id_tol, "id %.4f A, closed form %.4f A", id, id_expect);
    TK_CHECK(!limited || share >= 0.5, "speed_limited %.0f %% of the time", 100.0 * share);
    TK_CHECK(peak <= LIMIT_A, "peak %.3f A", peak);
    TK_CHECK(r.fault == 0, "fault %s", foc_fault_name(r.fault));
    run_free(&r);
}

/* Measured: 0.27 and 0.29 rpm off 3500 rpm (the limit was 80 rpm), id
 * 1.7 mA off the closed form (it was only asked to be below -0.1 A; the
 * limit 10 mA until 1.7 was measured); on the mismatch 0.32 rpm off at no
 * load, 7.7 rpm (0.23 %) off the closed form's 3376 rpm with the load,
 * id 0.5 mA off -FW_ID_MAX_A. */
static void case_field_weakening_max_speed(void) { field_weakening_max_speed(0, 1.0, 0.007); }
static void case_field_weakening_max_speed_mismatch(void)
{
    field_weakening_max_speed(1, 35.0, 0.002);
}
/* On `plant realistic`: 0.17 and 0.13 rpm off (the limit 1.0 rpm until
 * these were measured), id 0.0 mA off the closed form's -0.9441 A (the
 * limit 7 mA as on the nominal plant); on top of the mismatch 0.08 rpm at no load and 3337
 * rpm with the load, between the closed forms at the EMF harmonics' peak
 * (3216 rpm) and for the fundamental (3376), id 1.1 mA off.  (Until the
 * switched bridge took a pulse shorter than the dead time right, it gave
 * the plant more voltage than the command near the limit: id was 0.106 A
 * off, and the loaded mismatch reached 3485 rpm; the limits were 0.2 A,
 * 100 rpm and 0.02 A.) */
static void case_field_weakening_max_speed_realistic(void)
{
    field_weakening_max_speed(RUN_REALISTIC, 0.7, 0.007);
}
static void case_field_weakening_max_speed_realistic_mismatch(void)
{
    field_weakening_max_speed(RUN_REALISTIC | RUN_MISMATCH, 35.0, 0.005);
}

/* A sensorless command below SENSORLESS_MIN_SPEED_RPM (by default
 * STARTUP_MIN_SPEED_RPM, 250 rpm) turns the rotor at that speed, its sign
 * kept: judged on the plant's speed, against the same command with the
 * floor set to 0 (the rotor then turns at the command), within `tol` of
 * the speed wanted. */
static void low_command_raised(int mm, double tol)
{
    const double asked[] = { 100.0, -100.0 };
    for (unsigned k = 0; k < 2u; k++) {
        char text[96];
        snprintf(text, sizeof text, "0 start\n0 speed %g\n2.5 end\n", asked[k]);
        const double floor = copysign(SENSORLESS_MIN_SPEED_RPM, asked[k]);
        for (int min_speed = -1; min_speed <= 0; min_speed++) {
            sim_options_t opt;
            sim_default_options(&opt);
            opt.min_speed_rpm = min_speed; /* -1: userparms.h's floor */
            run_t r;
            run_opt(text, mm, &opt, &r);
            const double want = (min_speed < 0) ? floor : asked[k];
            const double got = run_mean_speed(&r, 2.0, 2.5);
            printf("%+.0f rpm asked%s, floor %s: %.2f rpm (want %.0f, %.3f %% off, limit %.2f), "
                   "fault %s\n",
                   asked[k], plant_name(mm), min_speed < 0 ? "default" : "0", got, want,
                   100.0 * fabs(got - want) / fabs(want), 100.0 * tol, foc_fault_name(r.fault));
            TK_CHECK(fabs(got - want) <= tol * fabs(want), "%+.0f rpm asked: %.1f rpm",
                     asked[k], got);
            TK_CHECK(r.fault == 0, "fault %s", foc_fault_name(r.fault));
            run_free(&r);
        }
    }
}

/* Measured: 0.141 % off at worst, 0.382 % on the mismatch (the limit was
 * 5 %). */
static void case_low_command_raised(void) { low_command_raised(0, 0.005); }
static void case_low_command_raised_mismatch(void) { low_command_raised(1, 0.012); }
/* On `plant realistic`: 1.671 % off at worst (-100 rpm with no floor),
 * 2.189 % on top of the mismatch; at the default floor 0.101 % and
 * 0.079 %.  With the floor at STARTUP_MIN_SPEED_RPM, 250 rpm, both tripped
 * SPEED_FEEDBACK: config.h's FOC_DT_FLOOR_RPM. */
static void case_low_command_raised_realistic(void) { low_command_raised(RUN_REALISTIC, 0.05); }
static void case_low_command_raised_realistic_mismatch(void)
{
    low_command_raised(RUN_REALISTIC | RUN_MISMATCH, 0.07);
}

/* The maximum speed asked with field weakening off: 24 V cannot reach it.
 * The speed settles where the voltage runs out (measured from the plant,
 * and within `tol` of the closed form: where the plant needs the voltage
 * limit with id = 0), steady within 1 % over its last 0.3 s, current
 * within the limit, no fault; the controller says so (speed_limited over
 * at least half of the last 0.3 s). */
static void unreachable_speed_settles(int mm, double tol, double share_min)
{
    sim_options_t opt;
    sim_default_options(&opt);
    opt.fw_mode = FW_MODE_OFF;
    run_t r;
    run_opt("0 start\n0 speed 3500\n2.0 end\n", mm, &opt, &r);
    const double reached = run_mean_speed(&r, 1.7, 2.0);
    const double early = run_mean_speed(&r, 1.4, 1.7);
    const double peak = run_max_phase_current(&r, 0.0, 2.0);
    const plant_t p = plant_of(mm);
    const double expect = speed_at_voltage(&p, 0.0, 0.0, V_MAX_V, 1);
    const double share = run_share_limited(&r, 1.7, 2.0);
    printf("no field weakening%s: %.1f rpm (asked 3500; closed form %.1f rpm, %+.2f %%, limit "
           "+-%.1f %%), %.1f rpm 0.3 s before, peak %.3f A, speed_limited %.0f %% of the last "
           "0.3 s\n",
           plant_name(mm), reached, expect, 100.0 * (reached / expect - 1.0), 100.0 * tol, early,
           peak, 100.0 * share);
    TK_CHECK(reached < 3400.0 && reached > 2500.0, "%.1f rpm", reached);
    TK_CHECK(fabs(reached / expect - 1.0) <= tol, "%.1f rpm, closed form %.1f rpm", reached,
             expect);
    TK_CHECK(fabs(reached - early) <= 0.01 * reached, "not settled: %.1f then %.1f rpm", early,
             reached);
    TK_CHECK(peak <= LIMIT_A, "peak %.3f A", peak);
    TK_CHECK(r.fault == 0, "fault %s", foc_fault_name(r.fault));
    TK_CHECK(share >= share_min, "the controller reports it %.0f %% of the time", 100.0 * share);
    run_free(&r);
}

/* Measured: +3.02 % off the closed form (the dead-time compensation,
 * which follows the saturated q reference while the q current is almost
 * 0, adds voltage), speed_limited 100 % of the time (the final sample was
 * asked); on the mismatch -3.19 %, and speed_limited 59 %: with the noise
 * |Vdq| leaves the last 1/64 of the limit now and then. */
static void case_unreachable_speed_settles(void) { unreachable_speed_settles(0, 0.1, 0.9); }
static void case_unreachable_speed_settles_mismatch(void)
{
    unreachable_speed_settles(1, 0.1, 0.2);
}
/* On `plant realistic`: -4.16 % off the closed form (at the EMF
 * harmonics' peak), speed_limited 51 % of the time; on top of the
 * mismatch -4.12 %, 54 %.  (Before the switched bridge took a pulse
 * shorter than the dead time right, and against the fundamental's closed
 * form: -4.75 % and -3.94 %.) */
static void case_unreachable_speed_settles_realistic(void)
{
    unreachable_speed_settles(RUN_REALISTIC, 0.15, 0.12);
}
static void case_unreachable_speed_settles_realistic_mismatch(void)
{
    unreachable_speed_settles(RUN_REALISTIC | RUN_MISMATCH, 0.15, 0.12);
}

/* Rotor locked in RUN: SPEED_FEEDBACK once the stall check has counted
 * STALL_TICKS slow ticks of an estimate far below the estimator's range
 * (the PLL's falls to 0 within 5 ms; 30 ms on the Hurst075) and within
 * `extra` s after that (the limit was 200 ms), outputs off. */
static void stall_detected(int mm, double extra)
{
    const double speeds[] = { 500.0, 1000.0, 2000.0 };
    const double t_min = STALL_TICKS * FOC_SLOW_TS_S;
    for (size_t i = 0; i < 3; i++) {
        char text[128];
        snprintf(text, sizeof text, "0 start\n0 speed %g\n1.0 lock\n1.6 end\n", speeds[i]);
        run_t r;
        run_default(text, mm, &r);
        const double t = run_first_fault(&r, 1.0, "SPEED_FEEDBACK") - 1.0;
        printf("locked in RUN at %4.0f rpm%s: SPEED_FEEDBACK after %.1f ms (limits %.1f-%.1f)\n",
               speeds[i], plant_name(mm), t * 1e3, t_min * 1e3, (t_min + extra) * 1e3);
        TK_CHECK(t >= t_min && t <= t_min + extra, "%.0f rpm: %.1f ms", speeds[i], t * 1e3);
        TK_CHECK(r.rows[r.n - 1].bridge == PMSM_BRIDGE_OFF, "%.0f rpm: outputs on", speeds[i]);
        run_free(&r);
    }
}

/* Measured: 31.5-33.0 ms, on both plants (the limit was 200 ms,
 * one-sided): 30 ms of STALL_TICKS and 1.5-3 ms for the estimate to fall
 * below half the range's end; 10 ms allowed after the 30. */
static void case_stall_detected(void) { stall_detected(0, 0.010); }
static void case_stall_detected_mismatch(void) { stall_detected(1, 0.010); }
/* On `plant realistic`, with the mismatch too: 31.5-33.5 ms. */
static void case_stall_detected_realistic(void) { stall_detected(RUN_REALISTIC, 0.010); }
static void case_stall_detected_realistic_mismatch(void)
{
    stall_detected(RUN_REALISTIC | RUN_MISMATCH, 0.010);
}

/* 10 s of speed steps 500 <-> 3000 rpm, load steps 0 <-> 0.05 Nm and a
 * reversal 1000 -> -1000 rpm: no fault, and the speeds are reached (the
 * mean over the 150 ms before each check within `tol` of the command, or,
 * where the closed form says the voltage runs out first, within
 * `tol_limited` of that speed: the mismatch at 3000 rpm with 0.05 Nm).
 * 150 ms: on the board's dead time the unloaded rotor hunts at 500 rpm
 * (+-18 rpm, about 70 ms a cycle: docs/estimators.md), so a 50 ms mean
 * measured the hunt's phase (0.08 % to 0.24 % off as the start-up moved
 * it by a few ms), not the speed reached. */
static void no_false_trip(int mm, double tol, double tol_limited)
{
    run_t r;
    run_default("0 start\n0 speed 500\n1 speed 3000\n2 load 0.05\n3 speed 500\n4 load 0\n"
                "4.5 speed 3000\n5.5 speed 500\n5.6 load 0.05\n6.5 load 0\n7 speed 1000\n"
                "7.5 speed -1000\n8.7 speed 3000\n10 end\n",
                mm, &r);
    /* time, command, load */
    const double checks[][3] = { { 0.9, 500, 0 },     { 1.9, 3000, 0 },   { 2.9, 3000, 0.05 },
                                 { 3.9, 500, 0.05 },  { 5.4, 3000, 0 },   { 6.4, 500, 0.05 },
                                 { 7.4, 1000, 0 },    { 8.6, -1000, 0 },  { 9.9, 3000, 0 } };
    const plant_t p = plant_of(mm);
    double worst = 0.0, worst_limited = 0.0;
    for (size_t i = 0; i < sizeof checks / sizeof checks[0]; i++) {
        const double v = run_mean_speed(&r, checks[i][0] - 0.15, checks[i][0]);
        const double want = reachable_rpm(&p, checks[i][1], checks[i][2]);
        const int limited = want != checks[i][1];
        const double off = fabs(v - want) / fabs(want);
        if (limited) {
            worst_limited = fmax(worst_limited, off);
            printf("  at %.1f s: %.1f rpm, %.0f asked; the voltage runs out at %.1f rpm (closed "
                   "form): %.2f %% off\n",
                   checks[i][0], v, checks[i][1], want, 100.0 * off);
        } else {
            worst = fmax(worst, off);
        }
        TK_CHECK(off <= (limited ? tol_limited : tol), "at %.2f s: %.1f rpm, want %.1f rpm",
                 checks[i][0], v, want);
    }
    printf("10 s profile%s: final %s, fault %s, the speeds at most %.3f %% off (limit %.3f %%), "
           "the voltage-limited ones %.3f %% (limit %.1f %%)\n",
           plant_name(mm), foc_state_name(r.final_state), foc_fault_name(r.fault), 100.0 * worst,
           100.0 * tol, 100.0 * worst_limited, 100.0 * tol_limited);
    TK_CHECK(r.fault == 0 && r.final_state == FOC_STATE_RUN, "%s %s",
             foc_state_name(r.final_state), foc_fault_name(r.fault));
    run_free(&r);
}

/* Measured (150 ms means): 0.037 % at worst (the limit was 2 %); on the
 * mismatch 0.039 % (0.049 % when the limit 0.2 % was set), and 2.84 % off
 * the closed form where the voltage runs out. */
static void case_no_false_trip(void) { no_false_trip(0, 0.001, 0.001); }
static void case_no_false_trip_mismatch(void) { no_false_trip(1, 0.0015, 0.08); }
/* On `plant realistic`: 0.040 % at worst, none voltage-limited; on top
 * of the mismatch 0.063 %, and 0.47 % off the closed form at the EMF
 * harmonics' peak where the voltage runs out (5.2 % off the fundamental's).
 * Limits 4-5 x.  (Until the switched bridge took a pulse shorter than the
 * dead time right, which gave the plant more voltage than the command:
 * 0.035 %, 0.078 % and 1.10 % off the fundamental's closed form; the
 * limits 1.5 %, 0.6 % and 5 % were set on 0.412 %, 0.189 % and 1.62 %.) */
static void case_no_false_trip_realistic(void) { no_false_trip(RUN_REALISTIC, 0.002, 0.001); }
static void case_no_false_trip_realistic_mismatch(void)
{
    no_false_trip(RUN_REALISTIC | RUN_MISMATCH, 0.003, 0.02);
}

/* One fault class: trips (name, outputs off within `off_within_s`), stays
 * latched while the cause lasts and until `ack`, then the motor restarts
 * (the mean speed over 2.3-2.4 s within `restart_tol` rpm of 1000).
 * The cause `inject` lies just beyond the threshold (1.5 %: a threshold
 * scaled wrong by more than that fails one of the two runs), and the same
 * cause just short of it (`near`, 1.5 % the other side; NULL for the
 * over-current pulse) runs on without a fault. */
static void check_fault(int mm, const char *name, const char *inject, const char *near,
                        const char *clear, double off_within_s, double restart_tol)
{
    /* An ack while the cause lasts (0.9 s) and starts before the ack
     * (1.0, 1.3 s) are refused; the ack after the cause (1.4 s) clears. */
    char text[512];
    snprintf(text, sizeof text,
             "0 start\n0 speed 1000\n0.6 %s\n0.9 ack\n1.0 start\n1.1 %s\n1.3 start\n"
             "1.4 ack\n1.5 start\n2.4 end\n",
             inject, clear);
    if (strcmp(inject, "overcurrent") == 0) {
        /* a pulse: no cause lasts, so no early ack */
        snprintf(text, sizeof text,
                 "0 start\n0 speed 1000\n0.6 %s\n1.0 start\n1.1 %s\n1.3 start\n"
                 "1.4 ack\n1.5 start\n2.4 end\n",
                 inject, clear);
    }
    run_t r;
    run_default(text, mm, &r);
    const double t_trip = run_first_fault(&r, 0.6, name);
    const size_t k = run_index_at(&r, t_trip);
    double t_off = -1.0;
    for (size_t j = k; j < r.n; j++) {
        if (r.rows[j].bridge == PMSM_BRIDGE_OFF) {
            t_off = r.rows[j].t_s;
            break;
        }
    }
    const char *at_099 = r.rows[run_index_at(&r, 0.99)].state;
    const char *at_139 = r.rows[run_index_at(&r, 1.39)].state;
    const double t_restart = run_first_state(&r, 1.5, "RUN");
    const double speed = run_mean_speed(&r, 2.3, 2.4);
    printf("%-14s (%s)%s trip %.2f ms after the cause, outputs off %.2f ms after; latched after "
           "an early ack: %s; after the cause: %s; restarted: RUN at %.3f s, %.2f rpm (limit "
           "+-%.1f)\n",
           name, inject, plant_name(mm), (t_trip - 0.6) * 1e3, (t_off - t_trip) * 1e3, at_099,
           at_139, t_restart, speed, restart_tol);
    TK_CHECK(t_trip >= 0.6 && t_trip - 0.6 <= off_within_s, "%s: trip at %.4f s", name, t_trip);
    TK_CHECK(t_off >= 0.0 && t_off - 0.6 <= off_within_s, "%s: outputs off at %.4f s", name, t_off);
    TK_CHECK(strcmp(at_099, "FAULT") == 0, "%s: not latched at 0.99 s (%s)", name, at_099);
    TK_CHECK(strcmp(at_139, "FAULT") == 0, "%s: cleared without ack (%s)", name, at_139);
    TK_CHECK(t_restart > 0.0 && fabs(speed - 1000.0) <= restart_tol && r.fault == 0,
             "%s: no restart (RUN %.3f s, %.1f rpm, %s)", name, t_restart, speed,
             foc_fault_name(r.fault));
    run_free(&r);
    if (near == NULL) {
        return;
    }
    snprintf(text, sizeof text, "0 start\n0 speed 1000\n0.6 %s\n1.2 end\n", near);
    run_default(text, mm, &r);
    const double speed_near = run_mean_speed(&r, 1.1, 1.2);
    printf("%-14s (%s)%s just short of the threshold: final %s, fault %s, %.1f rpm\n", name,
           near, plant_name(mm), foc_state_name(r.final_state), foc_fault_name(r.fault),
           speed_near);
    TK_CHECK(r.fault == 0 && r.final_state == FOC_STATE_RUN, "%s: %s tripped (%s, %s)", name, near,
             foc_state_name(r.final_state), foc_fault_name(r.fault));
    run_free(&r);
}

/* "vdc <v>" or "temp <degC>" at `ratio` x `value` */
static const char *cause(char *buf, size_t len, const char *what, double value, double ratio)
{
    snprintf(buf, len, "%s %.3f", what, ratio * value);
    return buf;
}

static void fault_overcurrent(int mm, double restart_tol)
{
    /* The cause is a pulse; the latch holds until ack. */
    check_fault(mm, "OVERCURRENT", "overcurrent", NULL, "temp 25", 1.0 / PWM_FREQUENCY_HZ,
                restart_tol);
}

static void fault_overvoltage(int mm, double restart_tol)
{
    char above[32], below[32];
    check_fault(mm, "OVERVOLTAGE", cause(above, sizeof above, "vdc", OVERVOLTAGE_V, 1.015),
                cause(below, sizeof below, "vdc", OVERVOLTAGE_V, 0.985), "vdc 24", FOC_SLOW_TS_S,
                restart_tol);
}

static void fault_undervoltage(int mm, double restart_tol)
{
    char above[32], below[32];
    check_fault(mm, "UNDERVOLTAGE", cause(below, sizeof below, "vdc", UNDERVOLTAGE_V, 0.985),
                cause(above, sizeof above, "vdc", UNDERVOLTAGE_V, 1.015), "vdc 24", FOC_SLOW_TS_S,
                restart_tol);
}

static void fault_overtemp(int mm, double restart_tol)
{
    char above[32], below[32];
    check_fault(mm, "OVERTEMP", cause(above, sizeof above, "temp", OVERTEMP_DEGC, 1.015),
                cause(below, sizeof below, "temp", OVERTEMP_DEGC, 0.985), "temp 25", FOC_SLOW_TS_S,
                restart_tol);
}

/* Measured: the restarted speed at most 0.04 rpm off 1000 rpm (0.21 on
 * the mismatch; the limit was 20 rpm, then 1.0 and 1.5 on 0.21 and
 * 0.40); the trip and the outputs off in the period (fast) or slow tick
 * of the cause.  Limits about 4-5 x. */
static void case_fault_overcurrent(void) { fault_overcurrent(0, 0.2); }
static void case_fault_overcurrent_mismatch(void) { fault_overcurrent(1, 0.8); }
static void case_fault_overvoltage(void) { fault_overvoltage(0, 0.2); }
static void case_fault_overvoltage_mismatch(void) { fault_overvoltage(1, 0.8); }
static void case_fault_undervoltage(void) { fault_undervoltage(0, 0.2); }
static void case_fault_undervoltage_mismatch(void) { fault_undervoltage(1, 0.8); }
static void case_fault_overtemp(void) { fault_overtemp(0, 0.2); }
static void case_fault_overtemp_mismatch(void) { fault_overtemp(1, 0.8); }
/* On `plant realistic`: the restarted speed at most 0.43 rpm off (0.52 on
 * top of the mismatch; 1.19 and 0.90, limits 4.0 and 3.0, before the
 * switched bridge took a pulse shorter than the dead time right). */
static void case_fault_overcurrent_realistic(void) { fault_overcurrent(RUN_REALISTIC, 1.7); }
static void case_fault_overcurrent_realistic_mismatch(void)
{
    fault_overcurrent(RUN_REALISTIC | RUN_MISMATCH, 2.0);
}
static void case_fault_overvoltage_realistic(void) { fault_overvoltage(RUN_REALISTIC, 1.7); }
static void case_fault_overvoltage_realistic_mismatch(void)
{
    fault_overvoltage(RUN_REALISTIC | RUN_MISMATCH, 2.0);
}
static void case_fault_undervoltage_realistic(void) { fault_undervoltage(RUN_REALISTIC, 1.7); }
static void case_fault_undervoltage_realistic_mismatch(void)
{
    fault_undervoltage(RUN_REALISTIC | RUN_MISMATCH, 2.0);
}
static void case_fault_overtemp_realistic(void) { fault_overtemp(RUN_REALISTIC, 1.7); }
static void case_fault_overtemp_realistic_mismatch(void)
{
    fault_overtemp(RUN_REALISTIC | RUN_MISMATCH, 2.0);
}

/* Stops from 2000 rpm: shorted windings and the brake resistor (on a
 * 470 uF bus) stop faster than coasting, current within the limit, bus
 * below the over-voltage threshold. */
static double stop_time(int mm, const char *extra, int stop_mode, int resistor, double *peak_a,
                        double *vdc_max, uint16_t *fault)
{
    char text[256];
    snprintf(text, sizeof text, "%s0 start\n0 speed 2000\n0.8 stop\n4.0 end\n", extra);
    sim_options_t opt;
    sim_default_options(&opt);
    opt.stop_mode = stop_mode;
    opt.brake_resistor = resistor;
    run_t r;
    run_opt(text, mm, &opt, &r);
    double t_stop = -1.0;
    *vdc_max = 0.0;
    for (size_t k = run_index_at(&r, 0.8); k < r.n; k++) {
        *vdc_max = fmax(*vdc_max, r.rows[k].vdc_v);
        if (t_stop < 0.0 && fabs(r.rows[k].speed_rpm) < 20.0) {
            t_stop = r.rows[k].t_s - 0.8;
        }
    }
    *peak_a = run_max_phase_current(&r, 0.8, 4.0);
    *fault = r.fault;
    run_free(&r);
    return t_stop;
}

/* Limits: the shorted windings' and the resistor's stop times (both
 * asked only to beat coasting), the bus's excursion above
 * BRAKE_RESISTOR_ON_V with the resistor (asked only to stay below
 * OVERVOLTAGE_V). */
static void braking(int mm, double shorted_max, double resistor_max, double bus_over_on_max)
{
    double peak[4], vmax[4];
    uint16_t fault[4];
    const double coast = stop_time(mm, "", STOP_MODE_COAST, 0, &peak[0], &vmax[0], &fault[0]);
    const double shorted = stop_time(mm, "", STOP_MODE_SHORT, 0, &peak[1], &vmax[1], &fault[1]);
    const char *bus = "0 plant buscap 470e-6\n0 plant brakeres 10\n";
    const double resistor = stop_time(mm, bus, STOP_MODE_RAMP, 1, &peak[2], &vmax[2], &fault[2]);
    const double no_res = stop_time(mm, bus, STOP_MODE_RAMP, 0, &peak[3], &vmax[3], &fault[3]);
    printf("stop from 2000 rpm to < 20 rpm%s: coast %.3f s; shorted windings %.3f s (limit %.3f, "
           "peak %.3f A); resistor %.3f s (limit %.3f, peak %.3f A, bus max %.3f V, %.3f V above "
           "ON, limit %.3f); same ramp without resistor: bus max %.2f V, fault %s\n",
           plant_name(mm), coast, shorted, shorted_max, peak[1], resistor, resistor_max, peak[2],
           vmax[2], vmax[2] - BRAKE_RESISTOR_ON_V, bus_over_on_max, vmax[3],
           foc_fault_name(fault[3]));
    (void)no_res;
    const double coast_s = coast < 0.0 ? 1e9 : coast; /* not stopped within 3.2 s */
    TK_CHECK(fault[0] == 0 && fault[1] == 0 && fault[2] == 0, "faults %s %s %s",
             foc_fault_name(fault[0]), foc_fault_name(fault[1]), foc_fault_name(fault[2]));
    TK_CHECK(shorted > 0.0 && shorted < coast_s && shorted <= shorted_max,
             "short %.3f s vs coast %.3f s", shorted, coast);
    TK_CHECK(resistor > 0.0 && resistor < coast_s && resistor <= resistor_max,
             "resistor %.3f s vs coast %.3f s", resistor, coast);
    TK_CHECK(peak[1] <= LIMIT_A && peak[2] <= LIMIT_A, "peaks %.3f %.3f A", peak[1], peak[2]);
    TK_CHECK(vmax[2] < OVERVOLTAGE_V && vmax[2] - BRAKE_RESISTOR_ON_V <= bus_over_on_max,
             "bus %.3f V with the resistor", vmax[2]);
}

/* Measured: shorted 0.049 / 0.050 s, resistor 0.283 / 0.280 s (coasting
 * 0.770 / 0.774 s), the bus 0.031 / 0.033 V above BRAKE_RESISTOR_ON_V (it
 * was asked to stay below OVERVOLTAGE_V, 3 V above). */
static void case_braking(void) { braking(0, 0.2, 1.0, 0.12); }
static void case_braking_mismatch(void) { braking(1, 0.2, 1.0, 0.12); }
/* On `plant realistic` (with the mismatch): shorted 0.048 (0.049) s,
 * resistor 0.271 (0.294) s, the bus 0.041 (0.037) V above ON. */
static void case_braking_realistic(void) { braking(RUN_REALISTIC, 0.2, 1.0, 0.12); }
static void case_braking_realistic_mismatch(void)
{
    braking(RUN_REALISTIC | RUN_MISMATCH, 0.2, 1.0, 0.12);
}

/* FAULT_BRAKE: an over-voltage at 1000 rpm (below the short-circuit safe
 * speed) shorts the windings: the rotor stops far sooner than coasting
 * (within `stop_max` s), current within the limit; at 3000 rpm (above
 * it) the outputs go off. */
static void fault_brake(int mm, double stop_max)
{
    sim_options_t opt;
    sim_default_options(&opt);
    opt.fault_brake = 1;
    run_t r;
    /* the over-voltage 1.5 % beyond its threshold (it was 40 V, 25 %) */
    char text[128];
    snprintf(text, sizeof text, "0 start\n0 speed 1000\n0.8 vdc %.3f\n1.6 end\n",
             1.015 * OVERVOLTAGE_V);
    run_opt(text, mm, &opt, &r);
    const size_t k = run_index_at(&r, 0.8);
    double t_stop = -1.0;
    for (size_t j = k; j < r.n; j++) {
        if (fabs(r.rows[j].speed_rpm) < 20.0) {
            t_stop = r.rows[j].t_s - 0.8;
            break;
        }
    }
    const double peak = run_max_phase_current(&r, 0.8, 1.6);
    const int shorted = r.rows[k].bridge == PMSM_BRIDGE_LOW_SIDES;
    const int off_later = r.rows[r.n - 1].bridge == PMSM_BRIDGE_OFF;
    printf("fault brake at 1000 rpm%s: windings shorted %s, stopped (< 20 rpm) after %.4f s "
           "(limit %.3f), peak %.3f A, outputs off afterwards %s\n",
           plant_name(mm), shorted ? "yes" : "NO", t_stop, stop_max, peak,
           off_later ? "yes" : "NO");
    TK_CHECK(shorted && off_later, "shorted %d, off later %d", shorted, off_later);
    TK_CHECK(t_stop > 0.0 && t_stop < stop_max, "stop after %.3f s", t_stop);
    TK_CHECK(peak <= LIMIT_A, "peak %.3f A", peak);
    run_free(&r);

    snprintf(text, sizeof text, "0 start\n0 speed 3000\n0.8 vdc %.3f\n1.0 end\n",
             1.015 * OVERVOLTAGE_V);
    run_opt(text, mm, &opt, &r);
    const int fast_off = r.rows[run_index_at(&r, 0.8)].bridge == PMSM_BRIDGE_OFF;
    printf("fault at 3000 rpm (above the safe speed)%s: outputs off %s\n", plant_name(mm),
           fast_off ? "yes" : "NO");
    TK_CHECK(fast_off, "shorted above the safe speed");
    run_free(&r);
}

/* Measured: stopped after 16.2 / 17.9 ms (the limit was 200 ms). */
static void case_fault_brake(void) { fault_brake(0, 0.06); }
static void case_fault_brake_mismatch(void) { fault_brake(1, 0.06); }
/* The dead-time current floor (config.h DEADTIME_MIN_CURRENT_A), from
 * the plant's true currents.  Sensorless at light load, the d current is
 * -(floor - |load current|), the floor in double from userparms.h: the
 * least of DEADTIME_MIN_CURRENT_A, the ramp from 1.25 x FOC_DT_FLOOR_RPM
 * over a quarter of it, and the current whose ohmic drop is 1/4 of the
 * back-EMF; the load current the plant's mean q current.  None at 400 rpm
 * (under 1.25 x the dead time's command floor), none under 0.05 Nm (its
 * q current is above the floor), none with field weakening off.  Each
 * mean over 0.2 s of steady state, within `tol_a`.  Measured at worst 3.6
 * mA off on `plant realistic` (4.5 on top of the mismatch) where the floor
 * acts, 3.3 (8.6) mA where it does not (the angle error turns a share of
 * the loaded q current into d); limits 3 x. */
static double floor_cf_a(double rpm)
{
    const double from = 1.25 * FOC_DT_FLOOR_RPM;
    if (rpm <= from) {
        return 0.0;
    }
    const double ramp = DEADTIME_MIN_CURRENT_A * (rpm - from) / (0.25 * (FOC_DT_FLOOR_RPM + 1.0));
    const double emf = FOC_FLUX_WB * rpm * MOTOR_POLE_PAIRS * 2.0 * FOC_PI_D / 60.0;
    return fmin(fmin(DEADTIME_MIN_CURRENT_A, ramp), emf / (4.0 * MOTOR_RS_OHM));
}

/* The plant's mean d and q currents over [t0, t1), A. */
static void mean_dq(const run_t *r, double t0, double t1, double *id, double *iq)
{
    double sd = 0.0, sq = 0.0;
    size_t n = 0;
    for (size_t k = run_index_at(r, t0); k < r->n && r->rows[k].t_s < t1; k++) {
        sd += r->rows[k].id_a;
        sq += r->rows[k].iq_a;
        n++;
    }
    *id = n ? sd / (double)n : 0.0;
    *iq = n ? sq / (double)n : 0.0;
}

static int floor_window(const run_t *r, double t1, double rpm, int floor_on, double tol_a,
                        const char *what)
{
    double id, iq;
    mean_dq(r, t1 - 0.2, t1, &id, &iq);
    const double want = floor_on ? -fmax(floor_cf_a(rpm) - fabs(iq), 0.0) : 0.0;
    const int ok = fabs(id - want) <= tol_a;
    printf("  %-34s id %7.4f A (want %7.4f, iq %7.4f A): %.4f A off (limit %.3f) %s\n", what, id,
           want, iq, fabs(id - want), tol_a, ok ? "ok" : "FAIL");
    return ok;
}

static void dt_current_floor(int mm, double tol_a)
{
    run_t r;
    run_default("0 start\n0 speed 1000\n1.0 speed 470\n1.6 speed 600\n2.2 speed 400\n"
                "2.8 speed 1000\n3.4 load 0.05\n4.0 end\n",
                mm, &r);
    printf("dead-time current floor%s, final %s %s:\n", plant_name(mm), foc_state_name(r.final_state),
           foc_fault_name(r.fault));
    int ok = r.fault == 0;
    ok &= floor_window(&r, 1.0, 1000.0, 1, tol_a, "1000 rpm, no load (the floor)");
    ok &= floor_window(&r, 1.6, 470.0, 1, tol_a, "470 rpm, no load (the ramp)");
    ok &= floor_window(&r, 2.2, 600.0, 1, tol_a, "600 rpm, no load (the EMF's bound)");
    ok &= floor_window(&r, 2.8, 400.0, 0, tol_a, "400 rpm, no load");
    ok &= floor_window(&r, 3.4, 1000.0, 1, tol_a, "1000 rpm, no load, again");
    ok &= floor_window(&r, 4.0, 1000.0, 0, tol_a, "1000 rpm, 0.05 Nm");
    run_free(&r);
    sim_options_t opt;
    sim_default_options(&opt);
    opt.fw_mode = FW_MODE_OFF;
    run_opt("0 start\n0 speed 1000\n1.0 end\n", mm, &opt, &r);
    ok &= r.fault == 0 && floor_window(&r, 1.0, 1000.0, 0, tol_a, "1000 rpm, field weakening off");
    run_free(&r);
    TK_CHECK(ok, "see the lines above");
}

static void case_dt_current_floor_realistic(void) { dt_current_floor(RUN_REALISTIC, 0.011); }
static void case_dt_current_floor_realistic_mismatch(void)
{
    dt_current_floor(RUN_REALISTIC | RUN_MISMATCH, 0.026);
}

/* On `plant realistic`: 16.3 ms (18.2 on top of the mismatch). */
static void case_fault_brake_realistic(void) { fault_brake(RUN_REALISTIC, 0.06); }
static void case_fault_brake_realistic_mismatch(void)
{
    fault_brake(RUN_REALISTIC | RUN_MISMATCH, 0.06);
}

TK_CASES(TK_CASE(case_fault_brake), TK_CASE(case_fault_brake_mismatch),
         TK_CASE(case_dt_current_floor_realistic), TK_CASE(case_dt_current_floor_realistic_mismatch),
         TK_CASE(case_startup_matrix), TK_CASE(case_startup_matrix_mismatch),
         TK_CASE(case_startup_matrix_luenberger), TK_CASE(case_startup_matrix_luenberger_mismatch),
         TK_CASE(case_startup_matrix_flux), TK_CASE(case_startup_matrix_flux_mismatch),
         TK_CASE(case_startup_matrix_realistic), TK_CASE(case_startup_matrix_luenberger_realistic),
         TK_CASE(case_startup_matrix_flux_realistic),
         TK_CASE(case_startup_matrix_realistic_mismatch),
         TK_CASE(case_locked_rotor_fails_startup),
         TK_CASE(case_locked_rotor_fails_startup_mismatch),
         TK_CASE(case_field_weakening_max_speed), TK_CASE(case_field_weakening_max_speed_mismatch),
         TK_CASE(case_unreachable_speed_settles), TK_CASE(case_unreachable_speed_settles_mismatch),
         TK_CASE(case_low_command_raised), TK_CASE(case_low_command_raised_mismatch),
         TK_CASE(case_stall_detected), TK_CASE(case_stall_detected_mismatch),
         TK_CASE(case_no_false_trip), TK_CASE(case_no_false_trip_mismatch),
         TK_CASE(case_fault_overcurrent), TK_CASE(case_fault_overcurrent_mismatch),
         TK_CASE(case_fault_overvoltage), TK_CASE(case_fault_overvoltage_mismatch),
         TK_CASE(case_fault_undervoltage), TK_CASE(case_fault_undervoltage_mismatch),
         TK_CASE(case_fault_overtemp), TK_CASE(case_fault_overtemp_mismatch),
         TK_CASE(case_braking), TK_CASE(case_braking_mismatch),
         TK_CASE(case_fault_brake_realistic), TK_CASE(case_fault_brake_realistic_mismatch),
         TK_CASE(case_locked_rotor_fails_startup_realistic),
         TK_CASE(case_locked_rotor_fails_startup_realistic_mismatch),
         TK_CASE(case_field_weakening_max_speed_realistic),
         TK_CASE(case_field_weakening_max_speed_realistic_mismatch),
         TK_CASE(case_unreachable_speed_settles_realistic),
         TK_CASE(case_unreachable_speed_settles_realistic_mismatch),
         TK_CASE(case_low_command_raised_realistic),
         TK_CASE(case_low_command_raised_realistic_mismatch),
         TK_CASE(case_stall_detected_realistic), TK_CASE(case_stall_detected_realistic_mismatch),
         TK_CASE(case_no_false_trip_realistic), TK_CASE(case_no_false_trip_realistic_mismatch),
         TK_CASE(case_fault_overcurrent_realistic),
         TK_CASE(case_fault_overcurrent_realistic_mismatch),
         TK_CASE(case_fault_overvoltage_realistic),
         TK_CASE(case_fault_overvoltage_realistic_mismatch),
         TK_CASE(case_fault_undervoltage_realistic),
         TK_CASE(case_fault_undervoltage_realistic_mismatch),
         TK_CASE(case_fault_overtemp_realistic), TK_CASE(case_fault_overtemp_realistic_mismatch),
         TK_CASE(case_braking_realistic), TK_CASE(case_braking_realistic_mismatch))
