/*
 * The new-motor workflow (docs/new-motor.md) on a motor that is not a
 * shipped default: motors/test_lowl_highspeed.ini (4 pole pairs, 0.1 ohm,
 * 60 uH, 10000 rpm nominal, 16000 rpm maximum) on a 24 V, 40 kHz board
 * (tests/tune/board_lv40k.ini).  userparms.h is written by tools/tune.py at
 * build time and the core is compiled against it; nothing here is tuned by
 * hand.  The steps, each a case:
 *
 *   case_open_loop_functioning  first spin in OPEN_LOOP_FUNCTIONING: the
 *       forced angle turns the rotor to the commanded speed, the estimator
 *       runs alongside and must agree with the rotor
 *   case_closed_loop            sensorless start from standstill (four rotor
 *       angles), speed steps, a load, a step into field weakening, a step
 *       down: RUN reached, every commanded speed held, no fault
 *   case_tuning_field_weakening TUNING with the tool's field-weakening
 *       tables (table mode): the reference creeps at the TUNING ramp up to
 *       the maximum speed, which is reached without fault
 *
 * OPEN_LOOP_FUNCTIONING and TUNING are #defines that only set
 * ctrl.opt.open_loop_only and ctrl.opt.tuning at foc_init(); the cases set
 * the same fields after sim_init() instead of compiling the core twice
 * more (tests/tune/test_tune.py checks that the tool's flags enable the
 * #defines).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "foc/config.h"
#include "scenario_run.h"
#include "testkit.h"

#define LIMIT_A (1.05 * CURRENT_LIMIT_A)

/* run_scenario_with() with the two tuning aids set. */
static void run_with_aids(const char *text, const sim_options_t *opt, int open_loop,
                          int tuning, run_t *out)
{
    sim_options_t o = *opt;
    o.open_loop_only = open_loop;
    o.tuning = tuning;
    run_scenario_with(text, &o, out);
}

/* RMS of the estimated - true electrical angle over [t0, t1), degrees. */
static double angle_rms(const run_t *r, double t0, double t1)
{
    double sum = 0.0;
    size_t n = 0;
    for (size_t k = run_index_at(r, t0); k < r->n && r->rows[k].t_s < t1; k++) {
        const double e = remainder(r->rows[k].theta_est_deg - r->rows[k].theta_e_deg, 360.0);
        sum += e * e;
        n++;
    }
    return n ? sqrt(sum / (double)n) : INFINITY;
}

/* 1 if the state was `state` at every row of [t0, t1). */
static int state_throughout(const run_t *r, double t0, double t1, const char *state)
{
    for (size_t k = run_index_at(r, t0); k < r->n && r->rows[k].t_s < t1; k++) {
        if (strcmp(r->rows[k].state, state) != 0) {
            return 0;
        }
    }
    return 1;
}

/* Step 4 of the workflow: open loop on the forced angle to 3000 rpm (a
 * third of nominal, where the back-EMF is clear), the estimator running
 * alongside. */
static void case_open_loop_functioning(void)
{
    sim_options_t opt;
    sim_default_options(&opt);
    run_t r;
    run_with_aids("0 start\n0 speed 3000\n1.2 load 0.05\n1.6 end\n", &opt, 1, 0, &r);
    const double speed = run_mean_speed(&r, 1.0, 1.2);
    const double loaded = run_mean_speed(&r, 1.4, 1.6);
    const double err = angle_rms(&r, 1.0, 1.6);
    const double est = r.rows[r.n - 1].speed_est_rpm;
    printf("open loop: %.1f rpm (%.1f rpm with 0.05 Nm), estimated %.1f rpm, estimated - true "
           "angle %.2f deg RMS, final %s %s, RUN %s\n",
           speed, loaded, est, err, foc_state_name(r.final_state), foc_fault_name(r.fault),
           run_first_state(&r, 0.0, "RUN") < 0.0 ? "never" : "REACHED");
    TK_CHECK(run_first_state(&r, 0.0, "RUN") < 0.0, "left open loop");
    TK_CHECK(state_throughout(&r, 0.8, 1.6, "OPENLOOP"), "not in OPENLOOP");
    TK_CHECK(r.fault == 0, "fault %s", foc_fault_name(r.fault));
    TK_CHECK(fabs(speed - 3000.0) <= 15.0 && fabs(loaded - 3000.0) <= 15.0,
             "rotor not synchronous: %.1f / %.1f rpm", speed, loaded);
    TK_CHECK(fabs(est - 3000.0) <= 60.0, "estimated speed %.1f rpm", est);
    TK_CHECK(err <= 5.0, "estimator angle error %.2f deg RMS", err);
    run_free(&r);
}

/* Step 5: closed loop from standstill with the real sensorless start-up. */
static void case_closed_loop(void)
{
    static const char scn[] = "0 angle %d\n0 start\n0 speed 5000\n1.0 speed 10000\n"
                              "1.8 load 0.15\n2.5 speed 14000\n3.5 load 0\n3.6 speed 6000\n"
                              "4.6 end\n";
    /* window end, commanded speed, what */
    static const struct {
        double t, rpm;
        const char *what;
    } at[] = { { 1.0, 5000.0, "5000 rpm" },
               { 1.8, 10000.0, "10000 rpm (nominal)" },
               { 2.5, 10000.0, "10000 rpm, 0.15 Nm" },
               { 3.5, 14000.0, "14000 rpm, 0.15 Nm, field weakening" },
               { 4.6, 6000.0, "6000 rpm" } };
    double worst_run = 0.0, worst_err = 0.0;
    for (int a = 0; a < 360; a += 90) {
        char text[512];
        snprintf(text, sizeof text, scn, a);
        sim_options_t opt;
        sim_default_options(&opt);
        run_t r;
        run_scenario_with(text, &opt, &r);
        const double t_run = run_first_state(&r, 0.0, "RUN");
        printf("rotor at %3d deg: RUN at %.3f s, final %s %s, peak %.2f A (limit %.2f A)\n", a,
               t_run, foc_state_name(r.final_state), foc_fault_name(r.fault),
               run_max_phase_current(&r, 0.0, 4.6), CURRENT_LIMIT_A);
        TK_CHECK(t_run > 0.0 && t_run <= 0.6, "angle %d: RUN at %.3f s", a, t_run);
        TK_CHECK(r.fault == 0 && r.final_state == FOC_STATE_RUN, "angle %d: %s %s", a,
                 foc_state_name(r.final_state), foc_fault_name(r.fault));
        TK_CHECK(state_throughout(&r, t_run, 4.6, "RUN"), "angle %d: left RUN", a);
        TK_CHECK(run_max_phase_current(&r, 0.0, 4.6) <= LIMIT_A, "angle %d: peak current", a);
        for (size_t i = 0; i < sizeof at / sizeof at[0]; i++) {
            const double v = run_mean_speed(&r, at[i].t - 0.1, at[i].t);
            const double e = 100.0 * (v - at[i].rpm) / at[i].rpm;
            printf("    %-38s %8.1f rpm  (%+.3f %%)\n", at[i].what, v, e);
            TK_CHECK(fabs(e) <= 1.0, "angle %d, %s: %.1f rpm", a, at[i].what, v);
            worst_err = fmax(worst_err, fabs(e));
        }
        /* field weakening really acted: Id well negative at 14000 rpm */
        const double id = r.rows[run_index_at(&r, 3.45)].id_ref_a;
        printf("    id reference at 14000 rpm: %.2f A\n", id);
        TK_CHECK(id < -0.2 * FW_ID_MAX_A, "angle %d: no field weakening (id %.2f A)", a, id);
        worst_run = fmax(worst_run, t_run);
        run_free(&r);
    }
    printf("closed loop: worst start -> RUN %.3f s, worst speed error %.3f %%\n", worst_run,
           worst_err);
}

/* Step 6: TUNING (slow reference ramp) with the initial tables. */
static void case_tuning_field_weakening(void)
{
    sim_options_t opt;
    sim_default_options(&opt);
    opt.fw_mode = FW_MODE_TABLE;
    const double top = MOTOR_MAX_SPEED_RPM;
    /* The slope the firmware gives (Q15.15 steps: TUNING_RAMP_RPM_PER_S
     * within rounding). */
    const double slope_fw = FOC_TUNING_RAMP_STEP15 / 32768.0 * SPEED_BASE_RPM / 32768.0 / FOC_SLOW_TS_S;
    const double t_end = 0.6 + top / slope_fw + 1.0;
    char text[128];
    snprintf(text, sizeof text, "0 start\n0 speed %g\n%g end\n", top, t_end);
    run_t r;
    run_with_aids(text, &opt, 0, 1, &r);
    /* the reference's slope over 4 s in the middle */
    const double t0 = 0.5 * t_end - 2.0, t1 = 0.5 * t_end + 2.0;
    const double slope = (r.rows[run_index_at(&r, t1)].speed_ref_rpm -
                          r.rows[run_index_at(&r, t0)].speed_ref_rpm) / (t1 - t0);
    const double final = run_mean_speed(&r, t_end - 0.3, t_end);
    const double id = r.rows[r.n - 1].id_ref_a;
    printf("tuning: reference slope %.1f rpm/s (%.1f expected: TUNING_RAMP_RPM_PER_S %.1f in "
           "Q15.15 steps), %.1f rpm at the end (maximum %.0f), id reference %.2f A, "
           "final %s %s, peak %.2f A\n",
           slope, slope_fw, TUNING_RAMP_RPM_PER_S, final, top, id,
           foc_state_name(r.final_state), foc_fault_name(r.fault),
           run_max_phase_current(&r, 0.0, t_end));
    TK_CHECK(fabs(slope / slope_fw - 1.0) <= 0.05, "slope %.1f rpm/s", slope);
    TK_CHECK(fabs(slope_fw / TUNING_RAMP_RPM_PER_S - 1.0) <= 0.01,
             "firmware ramp %.1f rpm/s for TUNING_RAMP_RPM_PER_S %.1f", slope_fw,
             TUNING_RAMP_RPM_PER_S);
    TK_CHECK(fabs(final - top) <= 0.01 * top, "final %.1f rpm", final);
    TK_CHECK(id < -0.2 * FW_ID_MAX_A, "id reference %.2f A: no field weakening", id);
    TK_CHECK(r.fault == 0 && r.final_state == FOC_STATE_RUN, "%s %s",
             foc_state_name(r.final_state), foc_fault_name(r.fault));
    TK_CHECK(run_max_phase_current(&r, 0.0, t_end) <= LIMIT_A, "peak current");
    run_free(&r);
}

TK_CASES(TK_CASE(case_open_loop_functioning), TK_CASE(case_closed_loop),
         TK_CASE(case_tuning_field_weakening))
