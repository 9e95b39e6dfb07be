/*
 * The application on the build's motor (Hurst075 by default) with its
 * configured estimator (PLL): sensorless start-up, field weakening, stall
 * detection, fault classes and braking, with the limits of the
 * application issue.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "foc/config.h"
#include "scenario_run.h"
#include "testkit.h"

#define LIMIT_A (1.05 * CURRENT_LIMIT_A) /* limit + 5 % */

static void run_default(const char *text, run_t *r)
{
    run_scenario(text, FOC_ESTIMATOR, r);
}

/* 12 rotor angles x loads {0, 0.02, 0.05} Nm x inertia {1, 5} x default:
 * every start reaches RUN and then the commanded 1000 rpm, with estimator
 * `est`. */
static void startup_matrix(foc_est_kind_t est)
{
    const double loads[] = { 0.0, 0.02, 0.05 };
    const double inertias[] = { 1.0, 5.0 };
    int ok = 0, total = 0;
    double worst = 0.0;
    char worst_case[96] = "";
    for (size_t j = 0; j < 2; j++) {
        for (size_t l = 0; l < 3; l++) {
            for (int a = 0; a < 360; a += 30) {
                char text[256];
                snprintf(text, sizeof text,
                         "0 plant j %g\n0 angle %d\n0 load %g\n0 start\n0 speed 1000\n1.6 end\n",
                         inertias[j] * MOTOR_INERTIA_KGM2, a, loads[l]);
                run_t r;
                run_scenario(text, est, &r);
                const double t_run = run_first_state(&r, 0.0, "RUN");
                const double speed = run_mean_speed(&r, 1.4, 1.6);
                const int good = t_run >= 0.0 && r.final_state == FOC_STATE_RUN && r.fault == 0 &&
                                 fabs(speed - 1000.0) <= 20.0;
                total++;
                ok += good;
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
    printf("start-up (%s): %d/%d reached RUN and 1000 rpm; worst start->RUN %.1f ms (%s)\n",
           foc_est_name(est), ok, total, worst * 1e3, worst_case);
    TK_CHECK(ok == total, "%d of %d starts failed", total - ok, total);
    TK_CHECK(worst <= 0.5, "worst start->RUN %.1f ms > 500 ms", worst * 1e3);
}

static void case_startup_matrix(void)
{
    startup_matrix(FOC_ESTIMATOR);
}

static void case_startup_matrix_luenberger(void)
{
    startup_matrix(FOC_EST_LUENBERGER);
}

static void case_startup_matrix_flux(void)
{
    startup_matrix(FOC_EST_FLUX);
}

/* A rotor locked before `start` never reaches RUN: STARTUP_FAILED within
 * the start-up time, outputs off. */
static void case_locked_rotor_fails_startup(void)
{
    for (int a = 0; a < 360; a += 90) {
        char text[128];
        snprintf(text, sizeof text, "0 lock\n0 angle %d\n0 start\n0 speed 1000\n2.0 end\n", a);
        run_t r;
        run_default(text, &r);
        const double t_fault = run_first_fault(&r, 0.0, "STARTUP_FAILED");
        const double limit = CALIB_TIME_S + STARTUP_TIMEOUT_S + 0.01;
        printf("locked rotor at %3d deg: STARTUP_FAILED at %.3f s (limit %.3f s), RUN %s\n", a,
               t_fault, limit, run_first_state(&r, 0.0, "RUN") < 0 ? "never" : "REACHED");
        TK_CHECK(run_first_state(&r, 0.0, "RUN") < 0.0, "angle %d: reached RUN", a);
        TK_CHECK(t_fault > 0.0 && t_fault <= limit, "angle %d: fault at %.3f s", a, t_fault);
        const size_t k = run_index_at(&r, t_fault);
        TK_CHECK(k < r.n && r.rows[k].bridge == PMSM_BRIDGE_OFF, "angle %d: outputs on", a);
        TK_CHECK(run_max_phase_current(&r, t_fault + 0.005, 2.0) < 0.01, "angle %d: current", a);
        run_free(&r);
    }
}

/* 4000 rpm asked, above the motor's maximum: the command is clamped to
 * MOTOR_MAX_SPEED_RPM (3500 rpm, 1.75x nominal), which on 24 V needs field
 * weakening; within 80 rpm at no load, held with 0.015 Nm, current within
 * the limit, no fault. */
static void case_field_weakening_max_speed(void)
{
    run_t r;
    run_default("0 start\n0 speed 4000\n1.2 load 0.015\n2.0 end\n", &r);
    const double no_load = run_mean_speed(&r, 1.0, 1.2);
    const double loaded = run_mean_speed(&r, 1.8, 2.0);
    const double peak = run_max_phase_current(&r, 0.0, 2.0);
    const double id = r.rows[r.n - 1].id_a;
    printf("field weakening: %.1f rpm no load, %.1f rpm with 0.015 Nm, peak %.3f A, id %.3f A\n",
           no_load, loaded, peak, id);
    TK_CHECK(fabs(no_load - MOTOR_MAX_SPEED_RPM) <= 80.0, "no load %.1f rpm", no_load);
    TK_CHECK(fabs(loaded - MOTOR_MAX_SPEED_RPM) <= 80.0, "loaded %.1f rpm", loaded);
    TK_CHECK(id < -0.1, "no field weakening (id %.3f A)", id);
    TK_CHECK(peak <= LIMIT_A, "peak %.3f A", peak);
    TK_CHECK(r.fault == 0, "fault %s", foc_fault_name(r.fault));
    run_free(&r);
}

/* A sensorless command below SENSORLESS_MIN_SPEED_RPM (by default
 * STARTUP_MIN_SPEED_RPM, 250 rpm) turns the rotor at that speed, its sign
 * kept: judged on the plant's speed, against the same command with the
 * floor set to 0 (the rotor then turns at the command). */
static void case_low_command_raised(void)
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
            run_scenario_with(text, &opt, &r);
            const double want = (min_speed < 0) ? floor : asked[k];
            const double got = run_mean_speed(&r, 2.0, 2.5);
            printf("%+.0f rpm asked, floor %s: %.1f rpm (want %.0f), fault %s\n", asked[k],
                   min_speed < 0 ? "default" : "0", got, want, foc_fault_name(r.fault));
            TK_CHECK(fabs(got - want) <= 0.05 * fabs(want), "%+.0f rpm asked: %.1f rpm",
                     asked[k], got);
            TK_CHECK(r.fault == 0, "fault %s", foc_fault_name(r.fault));
            run_free(&r);
        }
    }
}

/* The maximum speed asked with field weakening off: 24 V cannot reach it.
 * The speed settles where the voltage runs out (measured from the plant,
 * and below the 3500 rpm asked), steady within 1 % over its last 0.3 s,
 * current within the limit, no fault; the controller says so. */
static void case_unreachable_speed_settles(void)
{
    sim_options_t opt;
    sim_default_options(&opt);
    opt.fw_mode = FW_MODE_OFF;
    run_t r;
    run_scenario_with("0 start\n0 speed 3500\n2.0 end\n", &opt, &r);
    const double reached = run_mean_speed(&r, 1.7, 2.0);
    const double early = run_mean_speed(&r, 1.4, 1.7);
    const double peak = run_max_phase_current(&r, 0.0, 2.0);
    printf("no field weakening: %.1f rpm (asked 3500), peak %.3f A, speed_limited %d\n", reached,
           peak, r.speed_limited);
    TK_CHECK(reached < 3400.0 && reached > 2500.0, "%.1f rpm", reached);
    TK_CHECK(fabs(reached - early) <= 0.01 * reached, "not settled: %.1f then %.1f rpm", early,
             reached);
    TK_CHECK(peak <= LIMIT_A, "peak %.3f A", peak);
    TK_CHECK(r.fault == 0, "fault %s", foc_fault_name(r.fault));
    TK_CHECK(r.speed_limited == 1, "the controller does not report it");
    run_free(&r);
}

/* Rotor locked in RUN: SPEED_FEEDBACK within 200 ms, outputs off. */
static void case_stall_detected(void)
{
    const double speeds[] = { 500.0, 1000.0, 2000.0 };
    for (size_t i = 0; i < 3; i++) {
        char text[128];
        snprintf(text, sizeof text, "0 start\n0 speed %g\n1.0 lock\n1.6 end\n", speeds[i]);
        run_t r;
        run_default(text, &r);
        const double t = run_first_fault(&r, 1.0, "SPEED_FEEDBACK") - 1.0;
        printf("locked in RUN at %4.0f rpm: SPEED_FEEDBACK after %.1f ms\n", speeds[i], t * 1e3);
        TK_CHECK(t >= 0.0 && t <= 0.2, "%.0f rpm: %.1f ms", speeds[i], t * 1e3);
        TK_CHECK(r.rows[r.n - 1].bridge == PMSM_BRIDGE_OFF, "%.0f rpm: outputs on", speeds[i]);
        run_free(&r);
    }
}

/* 10 s of speed steps 500 <-> 3000 rpm, load steps 0 <-> 0.05 Nm and a
 * reversal 1000 -> -1000 rpm: no fault, and the speeds are reached. */
static void case_no_false_trip(void)
{
    run_t r;
    run_default("0 start\n0 speed 500\n1 speed 3000\n2 load 0.05\n3 speed 500\n4 load 0\n"
                "4.5 speed 3000\n5.5 speed 500\n5.6 load 0.05\n6.5 load 0\n7 speed 1000\n"
                "7.5 speed -1000\n8.7 speed 3000\n10 end\n",
                &r);
    const double checks[][2] = { { 0.9, 500 }, { 1.9, 3000 }, { 2.9, 3000 }, { 3.9, 500 },
                                 { 5.4, 3000 }, { 6.4, 500 }, { 7.4, 1000 }, { 8.6, -1000 },
                                 { 9.9, 3000 } };
    for (size_t i = 0; i < sizeof checks / sizeof checks[0]; i++) {
        const double v = run_mean_speed(&r, checks[i][0] - 0.05, checks[i][0]);
        TK_CHECK(fabs(v - checks[i][1]) <= 0.02 * fabs(checks[i][1]), "at %.2f s: %.1f rpm",
                 checks[i][0], v);
    }
    printf("10 s profile: final %s, fault %s\n", foc_state_name(r.final_state),
           foc_fault_name(r.fault));
    TK_CHECK(r.fault == 0 && r.final_state == FOC_STATE_RUN, "%s %s",
             foc_state_name(r.final_state), foc_fault_name(r.fault));
    run_free(&r);
}

/* One fault class: trips (name, outputs off within `off_within_s`), stays
 * latched while the cause lasts and until `ack`, then the motor restarts.
 * The cause `inject` lies just beyond the threshold (1.5 %: a threshold
 * scaled wrong by more than that fails one of the two runs), and the same
 * cause just short of it (`near`, 1.5 % the other side; NULL for the
 * over-current pulse) runs on without a fault. */
static void check_fault(const char *name, const char *inject, const char *near, const char *clear,
                        double off_within_s)
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
    run_default(text, &r);
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
    printf("%-14s (%s) trip %.2f ms after the cause, outputs off %.2f ms after; latched after "
           "an early ack: %s; after the cause: %s; restarted: RUN at %.3f s, %.1f rpm\n",
           name, inject, (t_trip - 0.6) * 1e3, (t_off - t_trip) * 1e3, at_099, at_139, t_restart,
           speed);
    TK_CHECK(t_trip >= 0.6 && t_trip - 0.6 <= off_within_s, "%s: trip at %.4f s", name, t_trip);
    TK_CHECK(t_off >= 0.0 && t_off - 0.6 <= off_within_s, "%s: outputs off at %.4f s", name, t_off);
    TK_CHECK(strcmp(at_099, "FAULT") == 0, "%s: not latched at 0.99 s (%s)", name, at_099);
    TK_CHECK(strcmp(at_139, "FAULT") == 0, "%s: cleared without ack (%s)", name, at_139);
    TK_CHECK(t_restart > 0.0 && fabs(speed - 1000.0) <= 20.0 && r.fault == 0,
             "%s: no restart (RUN %.3f s, %.1f rpm, %s)", name, t_restart, speed,
             foc_fault_name(r.fault));
    run_free(&r);
    if (near == NULL) {
        return;
    }
    snprintf(text, sizeof text, "0 start\n0 speed 1000\n0.6 %s\n1.2 end\n", near);
    run_default(text, &r);
    const double speed_near = run_mean_speed(&r, 1.1, 1.2);
    printf("%-14s (%s) just short of the threshold: final %s, fault %s, %.1f rpm\n", name, near,
           foc_state_name(r.final_state), foc_fault_name(r.fault), speed_near);
    TK_CHECK(r.fault == 0 && r.final_state == FOC_STATE_RUN, "%s: %s tripped (%s, %s)", name, near,
             foc_state_name(r.final_state), foc_fault_name(r.fault));
    run_free(&r);
}

static void case_fault_overcurrent(void)
{
    /* The cause is a pulse; the latch holds until ack. */
    check_fault("OVERCURRENT", "overcurrent", NULL, "temp 25", 1.0 / PWM_FREQUENCY_HZ);
}

/* "vdc <v>" or "temp <degC>" at `ratio` x `value` */
static const char *cause(char *buf, size_t len, const char *what, double value, double ratio)
{
    snprintf(buf, len, "%s %.3f", what, ratio * value);
    return buf;
}

static void case_fault_overvoltage(void)
{
    char above[32], below[32];
    check_fault("OVERVOLTAGE", cause(above, sizeof above, "vdc", OVERVOLTAGE_V, 1.015),
                cause(below, sizeof below, "vdc", OVERVOLTAGE_V, 0.985), "vdc 24", FOC_SLOW_TS_S);
}

static void case_fault_undervoltage(void)
{
    char above[32], below[32];
    check_fault("UNDERVOLTAGE", cause(below, sizeof below, "vdc", UNDERVOLTAGE_V, 0.985),
                cause(above, sizeof above, "vdc", UNDERVOLTAGE_V, 1.015), "vdc 24", FOC_SLOW_TS_S);
}

static void case_fault_overtemp(void)
{
    char above[32], below[32];
    check_fault("OVERTEMP", cause(above, sizeof above, "temp", OVERTEMP_DEGC, 1.015),
                cause(below, sizeof below, "temp", OVERTEMP_DEGC, 0.985), "temp 25", FOC_SLOW_TS_S);
}

/* Stops from 2000 rpm: shorted windings and the brake resistor (on a
 * 470 uF bus) stop faster than coasting, current within the limit, bus
 * below the over-voltage threshold. */
static double stop_time(const char *extra, int stop_mode, int resistor, double *peak_a,
                        double *vdc_max, uint16_t *fault)
{
    char text[256];
    snprintf(text, sizeof text, "%s0 start\n0 speed 2000\n0.8 stop\n4.0 end\n", extra);
    sim_options_t opt;
    sim_default_options(&opt);
    opt.stop_mode = stop_mode;
    opt.brake_resistor = resistor;
    run_t r;
    run_scenario_with(text, &opt, &r);
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

static void case_braking(void)
{
    double peak[4], vmax[4];
    uint16_t fault[4];
    const double coast = stop_time("", STOP_MODE_COAST, 0, &peak[0], &vmax[0], &fault[0]);
    const double shorted = stop_time("", STOP_MODE_SHORT, 0, &peak[1], &vmax[1], &fault[1]);
    const char *bus = "0 plant buscap 470e-6\n0 plant brakeres 10\n";
    const double resistor = stop_time(bus, STOP_MODE_RAMP, 1, &peak[2], &vmax[2], &fault[2]);
    const double no_res = stop_time(bus, STOP_MODE_RAMP, 0, &peak[3], &vmax[3], &fault[3]);
    printf("stop from 2000 rpm to < 20 rpm: coast %.3f s; shorted windings %.3f s (peak %.3f A); "
           "resistor %.3f s (peak %.3f A, bus max %.2f V); same ramp without resistor: bus max "
           "%.2f V, fault %s\n",
           coast, shorted, peak[1], resistor, peak[2], vmax[2], vmax[3],
           foc_fault_name(fault[3]));
    (void)no_res;
    const double coast_s = coast < 0.0 ? 1e9 : coast; /* not stopped within 3.2 s */
    TK_CHECK(fault[0] == 0 && fault[1] == 0 && fault[2] == 0, "faults %s %s %s",
             foc_fault_name(fault[0]), foc_fault_name(fault[1]), foc_fault_name(fault[2]));
    TK_CHECK(shorted > 0.0 && shorted < coast_s, "short %.3f s vs coast %.3f s", shorted, coast);
    TK_CHECK(resistor > 0.0 && resistor < coast_s, "resistor %.3f s vs coast %.3f s", resistor,
             coast);
    TK_CHECK(peak[1] <= LIMIT_A && peak[2] <= LIMIT_A, "peaks %.3f %.3f A", peak[1], peak[2]);
    TK_CHECK(vmax[2] < OVERVOLTAGE_V, "bus %.2f V with the resistor", vmax[2]);
}

/* FAULT_BRAKE: an over-voltage at 1000 rpm (below the short-circuit safe
 * speed) shorts the windings: the rotor stops far sooner than coasting,
 * current within the limit; at 3000 rpm (above it) the outputs go off. */
static void case_fault_brake(void)
{
    sim_options_t opt;
    sim_default_options(&opt);
    opt.fault_brake = 1;
    run_t r;
    run_scenario_with("0 start\n0 speed 1000\n0.8 vdc 40\n1.6 end\n", &opt, &r);
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
    printf("fault brake at 1000 rpm: windings shorted %s, stopped (< 20 rpm) after %.3f s, peak "
           "%.3f A, outputs off afterwards %s\n",
           shorted ? "yes" : "NO", t_stop, peak, off_later ? "yes" : "NO");
    TK_CHECK(shorted && off_later, "shorted %d, off later %d", shorted, off_later);
    TK_CHECK(t_stop > 0.0 && t_stop < 0.2, "stop after %.3f s", t_stop);
    TK_CHECK(peak <= LIMIT_A, "peak %.3f A", peak);
    run_free(&r);

    run_scenario_with("0 start\n0 speed 3000\n0.8 vdc 40\n1.0 end\n", &opt, &r);
    const int fast_off = r.rows[run_index_at(&r, 0.8)].bridge == PMSM_BRIDGE_OFF;
    printf("fault at 3000 rpm (above the safe speed): outputs off %s\n", fast_off ? "yes" : "NO");
    TK_CHECK(fast_off, "shorted above the safe speed");
    run_free(&r);
}

TK_CASES(TK_CASE(case_fault_brake), TK_CASE(case_startup_matrix), TK_CASE(case_startup_matrix_luenberger),
         TK_CASE(case_startup_matrix_flux), TK_CASE(case_locked_rotor_fails_startup),
         TK_CASE(case_field_weakening_max_speed), TK_CASE(case_unreachable_speed_settles),
         TK_CASE(case_low_command_raised),
         TK_CASE(case_stall_detected),
         TK_CASE(case_no_false_trip), TK_CASE(case_fault_overcurrent),
         TK_CASE(case_fault_overvoltage), TK_CASE(case_fault_undervoltage),
         TK_CASE(case_fault_overtemp), TK_CASE(case_braking))
