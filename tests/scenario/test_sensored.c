/*
 * Sensored closed loop on the userparms.h motor (Hurst075 by default):
 * the foundation's acceptance figures, measured on the true (model) speed
 * and currents.
 */
#include <math.h>
#include <stdio.h>

#include "foc/config.h"
#include "scenario_run.h"
#include "testkit.h"

#define ID_BAND_A (0.02 * FOC_I_BASE_A) /* +-2 % of the current base */

typedef struct {
    double t_step, t_next, from, to;
} step_t;

static void check_step(const run_t *r, const step_t *s)
{
    const double settle =
        run_last_outside(r, s->t_step, s->t_next, s->to, 0.01 * fabs(s->to)) - s->t_step;
    const int up = s->to > s->from;
    const double ext = run_extreme_speed(r, s->t_step, s->t_next, !up);
    const double overshoot = up ? ext - s->to : s->to - ext;
    const double overshoot_pct = 100.0 * fmax(0.0, overshoot) / fabs(s->to - s->from);
    printf("step %.0f -> %.0f rpm: settled within 1 %% after %.1f ms, overshoot %.2f %% "
           "of the step\n",
           s->from, s->to, settle * 1e3, overshoot_pct);
    TK_CHECK(settle <= 0.300, "%.0f->%.0f settle %.1f ms > 300 ms", s->from, s->to,
             settle * 1e3);
    TK_CHECK(overshoot_pct <= 10.0, "%.0f->%.0f overshoot %.2f %% > 10 %%", s->from, s->to,
             overshoot_pct);
}

static void case_speed_steps(void)
{
    run_t r;
    run_scenario("0 start\n0.1 speed 1000\n0.6 speed 2000\n1.1 speed 500\n1.6 end\n",
                 FOC_EST_SENSORED, &r);
    const step_t steps[] = {
        { 0.1, 0.6, 0.0, 1000.0 },
        { 0.6, 1.1, 1000.0, 2000.0 },
        { 1.1, 1.6, 2000.0, 500.0 },
    };
    for (size_t i = 0; i < sizeof steps / sizeof steps[0]; i++) {
        check_step(&r, &steps[i]);
    }
    TK_CHECK(r.final_state == FOC_STATE_RUN, "final state %s", foc_state_name(r.final_state));
    run_free(&r);
}

static void case_load_step_recovery(void)
{
    run_t r;
    run_scenario("0 start\n0.1 speed 1000\n0.5 load 0.05\n0.8 end\n", FOC_EST_SENSORED, &r);
    const double dip = 1000.0 - run_extreme_speed(&r, 0.5, 0.8, 1);
    const double recovered = run_last_outside(&r, 0.5, 0.8, 1000.0, 10.0) - 0.5;
    printf("load step 0.05 Nm at 1000 rpm: dip %.1f rpm, back within 1 %% after %.1f ms\n",
           dip, recovered * 1e3);
    TK_CHECK(dip > 10.0, "the load step did not disturb the speed (dip %.1f rpm)", dip);
    TK_CHECK(recovered <= 0.100, "recovery %.1f ms > 100 ms", recovered * 1e3);
    run_free(&r);
}

/* Steady state below base speed, with and without load. */
static void case_id_stays_zero(void)
{
    run_t r;
    run_scenario("0 start\n0.1 speed 1000\n0.4 load 0.05\n0.7 speed 2000\n1.0 load 0\n"
                 "1.3 speed 500\n1.6 end\n",
                 FOC_EST_SENSORED, &r);
    const double windows[][2] = { { 0.3, 0.4 }, { 0.6, 0.7 }, { 0.9, 1.0 },
                                  { 1.2, 1.3 }, { 1.5, 1.6 } };
    for (size_t i = 0; i < sizeof windows / sizeof windows[0]; i++) {
        const double id_max = run_max_abs_id(&r, windows[i][0], windows[i][1]);
        printf("steady state %.1f..%.1f s: max |id| = %.4f A (band %.4f A)\n", windows[i][0],
               windows[i][1], id_max, ID_BAND_A);
        TK_CHECK(id_max <= ID_BAND_A, "|id| %.4f A > %.4f A in %.1f..%.1f s", id_max,
                 ID_BAND_A, windows[i][0], windows[i][1]);
    }
    run_free(&r);
}

/* A load the motor cannot carry within the current limit (0.2 Nm needs
 * about 3.3 A at Kt = 0.06 Nm/A), for 60 ms: the speed loop saturates and
 * the phase current must stay within the limit; once the load goes, the
 * speed comes back (no windup).  (Held longer, the rotor stalls and the
 * drive faults: case_overload_stall.) */
static void case_current_limit_holds(void)
{
    run_t r;
    run_scenario("0 start\n0.1 speed 2000\n0.4 load 0.2\n0.46 load 0\n0.9 end\n",
                 FOC_EST_SENSORED, &r);
    const double back = run_last_outside(&r, 0.46, 0.9, 2000.0, 20.0) - 0.46;
    printf("overload: peak phase current %.3f A (limit %.3f A); speed back within 1 %% "
           "%.1f ms after the load goes\n",
           r.peak_current_a, CURRENT_LIMIT_A, back * 1e3);
    TK_CHECK(r.peak_current_a >= 0.9 * CURRENT_LIMIT_A,
             "the test did not drive the current to the limit (peak %.3f A)", r.peak_current_a);
    TK_CHECK(r.peak_current_a <= 1.05 * CURRENT_LIMIT_A, "peak %.3f A > limit + 5 %% (%.3f A)",
             r.peak_current_a, 1.05 * CURRENT_LIMIT_A);
    TK_CHECK(back <= 0.2, "speed not back within 1 %% 200 ms after the overload (%.1f ms)",
             back * 1e3);
    run_free(&r);
}

/* The same load held: the rotor stalls (the plant's speed below 5 % of the
 * command) and the drive must say so, SPEED_FEEDBACK within 200 ms of the
 * stall (docs/safety.md), outputs off, the current within the limit. */
static void case_overload_stall(void)
{
    run_t r;
    run_scenario("0 start\n0.1 speed 2000\n0.4 load 0.2\n1.4 end\n", FOC_EST_SENSORED, &r);
    double t_stall = -1.0;
    for (size_t k = 0; k < r.n; k++) {
        if (r.rows[k].t_s >= 0.4 && fabs(r.rows[k].speed_rpm) < 100.0) {
            t_stall = r.rows[k].t_s;
            break;
        }
    }
    const double t_fault = run_first_fault(&r, 0.4, "SPEED_FEEDBACK");
    printf("held overload: stalled at %.3f s, SPEED_FEEDBACK at %.3f s (%.1f ms), peak %.3f A\n",
           t_stall, t_fault, (t_fault - t_stall) * 1e3, r.peak_current_a);
    TK_CHECK(t_stall > 0.0, "the rotor did not stall");
    TK_CHECK(t_fault > 0.0 && t_fault - t_stall <= 0.2, "fault %.3f s after the stall",
             t_fault - t_stall);
    TK_CHECK(r.peak_current_a <= 1.05 * CURRENT_LIMIT_A, "peak %.3f A", r.peak_current_a);
    TK_CHECK(run_max_phase_current(&r, t_fault + 0.005, 1.4) < 0.01, "outputs not off");
    run_free(&r);
}

static void case_reversal(void)
{
    run_t r;
    run_scenario("0 start\n0.1 speed 1000\n0.5 speed -1000\n1.0 end\n", FOC_EST_SENSORED, &r);
    const double settle = run_last_outside(&r, 0.5, 1.0, -1000.0, 10.0) - 0.5;
    printf("reversal 1000 -> -1000 rpm: within 1 %% after %.1f ms\n", settle * 1e3);
    TK_CHECK(settle <= 0.4, "reversal settle %.1f ms", settle * 1e3);
    TK_CHECK(r.final_state == FOC_STATE_RUN && r.fault == 0, "state %s fault %s",
             foc_state_name(r.final_state), foc_fault_name(r.fault));
    run_free(&r);
}

/* The bus sags from 24 to 18 V: compensation keeps speed and currents. */
static void case_bus_compensation(void)
{
    run_t r;
    run_scenario("0 start\n0.1 speed 1000\n0.4 load 0.03\n0.5 vdc 18\n0.8 end\n",
                 FOC_EST_SENSORED, &r);
    const double settle = run_last_outside(&r, 0.5, 0.8, 1000.0, 10.0) - 0.5;
    const double id_max = run_max_abs_id(&r, 0.6, 0.8);
    printf("bus 24 -> 18 V at 1000 rpm: speed within 1 %% after %.1f ms, max |id| %.4f A\n",
           settle * 1e3, id_max);
    TK_CHECK(settle <= 0.05, "speed disturbed for %.1f ms by the bus step", settle * 1e3);
    TK_CHECK(id_max <= ID_BAND_A, "|id| %.4f A", id_max);
    run_free(&r);
}

/* Hardware fault input: outputs off at once, latched, cleared by ack,
 * restart works. */
static void case_overcurrent_latch_and_restart(void)
{
    run_t r;
    run_scenario("0 start\n0.1 speed 1000\n0.3 overcurrent\n0.35 start\n0.45 ack\n"
                 "0.5 start\n0.95 end\n",
                 FOC_EST_SENSORED, &r);
    const size_t k = run_index_at(&r, 0.3);
    TK_CHECK(k + 1 < r.n, "run too short");
    const sim_row_t *trip = &r.rows[k];
    TK_CHECK(trip->state[0] == 'F', "state at the fault period: %s", trip->state);
    TK_CHECK(trip->fault[0] == 'O', "fault: %s", trip->fault);
    /* the start at 0.35 s is refused while the fault is latched */
    const sim_row_t *before_ack = &r.rows[run_index_at(&r, 0.449)];
    TK_CHECK(before_ack->state[0] == 'F', "state before ack: %s", before_ack->state);
    /* bridge off: the current decays within a few periods (back-EMF < Vdc) */
    const sim_row_t *after = &r.rows[run_index_at(&r, 0.303)];
    const double i_after = fmax(fabs(after->ia_a), fabs(after->ib_a));
    TK_CHECK(i_after < 0.05, "current %.3f A 3 ms after the trip", i_after);
    const double settle = run_last_outside(&r, 0.5, 0.95, 1000.0, 10.0) - 0.5;
    TK_CHECK(r.final_state == FOC_STATE_RUN && settle < 0.4,
             "restart: state %s, settle %.1f ms", foc_state_name(r.final_state), settle * 1e3);
    run_free(&r);
}

static void case_stop_turns_outputs_off(void)
{
    run_t r;
    run_scenario("0 start\n0.1 speed 1000\n0.4 stop\n0.9 end\n", FOC_EST_SENSORED, &r);
    TK_CHECK(r.final_state == FOC_STATE_IDLE, "final state %s", foc_state_name(r.final_state));
    const sim_row_t *end = &r.rows[r.n - 1];
    TK_CHECK(fabs(end->ia_a) < 0.01 && fabs(end->ib_a) < 0.01, "current after stop %.3f A",
             fabs(end->ia_a));
    TK_CHECK(fabs(end->speed_rpm) < 100.0, "speed after stop %.1f rpm", end->speed_rpm);
    run_free(&r);
}

TK_CASES(TK_CASE(case_speed_steps), TK_CASE(case_load_step_recovery),
         TK_CASE(case_id_stays_zero), TK_CASE(case_current_limit_holds),
         TK_CASE(case_overload_stall),
         TK_CASE(case_reversal), TK_CASE(case_bus_compensation),
         TK_CASE(case_overcurrent_latch_and_restart), TK_CASE(case_stop_turns_outputs_off))
