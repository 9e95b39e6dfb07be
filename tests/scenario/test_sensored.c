/*
 * Sensored closed loop on the userparms.h motor (Hurst075 by default):
 * the foundation's acceptance figures, measured on the true (model) speed
 * and currents.  Every case runs on the nominal plant and, as
 * case_*_mismatch, on the stated controller-plant mismatch (scenario_run.h:
 * Rs +30 %, L -20 %, flux +10 %, 2 codes of ADC noise, the board's dead
 * time); and as case_*_realistic on issue 13's `plant realistic`, on top
 * of the mismatch as case_*_realistic_mismatch.  Limits: the foundation
 * issue's where they are within about 5 x what is measured, else about
 * 3-5 x the measured figure (in the comments, nominal / mismatch).
 */
#include <math.h>
#include <stdio.h>

#include "foc/config.h"
#include "scenario_run.h"
#include "testkit.h"

static void run(const char *scenario, int mm, run_t *r)
{
    char text[1024];
    if ((mm & RUN_REALISTIC) != 0) {
        printf("plant: realistic\n");
    }
    if ((mm & RUN_MISMATCH) != 0) {
        printf("plant: %s\n", RUN_MISMATCH_NAME);
    }
    run_scenario(run_text(text, sizeof text, mm, scenario), FOC_EST_SENSORED, r);
}

typedef struct {
    double t_step, t_next, from, to;
} step_t;

static void check_step(const run_t *r, const step_t *s, double settle_max_s,
                       double overshoot_max_pct)
{
    const double settle =
        run_last_outside(r, s->t_step, s->t_next, s->to, 0.01 * fabs(s->to)) - s->t_step;
    const int up = s->to > s->from;
    const double ext = run_extreme_speed(r, s->t_step, s->t_next, !up);
    const double overshoot = up ? ext - s->to : s->to - ext;
    const double overshoot_pct = 100.0 * fmax(0.0, overshoot) / fabs(s->to - s->from);
    printf("step %.0f -> %.0f rpm: settled within 1 %% after %.1f ms (limit %.0f), overshoot "
           "%.2f %% of the step (limit %.1f)\n",
           s->from, s->to, settle * 1e3, settle_max_s * 1e3, overshoot_pct, overshoot_max_pct);
    TK_CHECK(settle <= settle_max_s, "%.0f->%.0f settle %.1f ms", s->from, s->to, settle * 1e3);
    TK_CHECK(overshoot_pct <= overshoot_max_pct, "%.0f->%.0f overshoot %.2f %%", s->from, s->to,
             overshoot_pct);
}

/* Measured: settling 110, 106, 163 ms / 109, 105, 161 ms; overshoot
 * 2.42, 2.40, 1.74 % / 2.33, 2.27, 1.69 %: the 300 ms and 10 %
 * (1.8 x and 4.1 x) kept. */
static void speed_steps(int mm, double settle_max_s, double overshoot_max_pct)
{
    run_t r;
    run("0 start\n0.1 speed 1000\n0.6 speed 2000\n1.1 speed 500\n1.6 end\n", mm, &r);
    const step_t steps[] = {
        { 0.1, 0.6, 0.0, 1000.0 },
        { 0.6, 1.1, 1000.0, 2000.0 },
        { 1.1, 1.6, 2000.0, 500.0 },
    };
    for (size_t i = 0; i < sizeof steps / sizeof steps[0]; i++) {
        check_step(&r, &steps[i], settle_max_s, overshoot_max_pct);
    }
    TK_CHECK(r.final_state == FOC_STATE_RUN, "final state %s", foc_state_name(r.final_state));
    run_free(&r);
}

static void case_speed_steps(void) { speed_steps(0, 0.300, 10.0); }
static void case_speed_steps_mismatch(void) { speed_steps(1, 0.300, 10.0); }
/* On `plant realistic` (and on top of the mismatch) every figure within
 * 2 % of the nominal plant's: settling 110.5, 106.4, 162.2 ms, overshoot
 * 2.28, 2.18, 1.82 %; the load step's dip 229.4 rpm, back after 28.7 ms;
 * the reversal 210.6 ms; the held overload 111.4 ms; the bus step 4.32
 * rpm, |id| 81.5 mA; the restart 171.3 ms; the stop 0 A, 0 rpm. */
static void case_speed_steps_realistic(void) { speed_steps(RUN_REALISTIC, 0.300, 10.0); }
static void case_speed_steps_realistic_mismatch(void)
{
    speed_steps(RUN_REALISTIC | RUN_MISMATCH, 0.300, 10.0);
}

static void load_step_recovery(int mm, double dip_min, double dip_max, double recovery_max_s)
{
    run_t r;
    run("0 start\n0.1 speed 1000\n0.5 load 0.05\n0.8 end\n", mm, &r);
    const double dip = 1000.0 - run_extreme_speed(&r, 0.5, 0.8, 1);
    const double recovered = run_last_outside(&r, 0.5, 0.8, 1000.0, 10.0) - 0.5;
    printf("load step 0.05 Nm at 1000 rpm: dip %.1f rpm (limits %.0f-%.0f), back within 1 %% "
           "after %.1f ms (limit %.0f)\n",
           dip, dip_min, dip_max, recovered * 1e3, recovery_max_s * 1e3);
    TK_CHECK(dip >= dip_min && dip <= dip_max, "dip %.1f rpm", dip);
    TK_CHECK(recovered <= recovery_max_s, "recovery %.1f ms", recovered * 1e3);
    run_free(&r);
}

/* Measured: dip 231.7 / 217.9 rpm (was only asked to exceed 10 rpm; now
 * within a third and 3 x of it), back within 1 % after 26.5 / 26.2 ms
 * (the 100 ms kept: 3.8 x). */
static void case_load_step_recovery(void) { load_step_recovery(0, 75.0, 700.0, 0.100); }
static void case_load_step_recovery_mismatch(void) { load_step_recovery(1, 70.0, 650.0, 0.100); }
static void case_load_step_recovery_realistic(void)
{
    load_step_recovery(RUN_REALISTIC, 75.0, 700.0, 0.100);
}
static void case_load_step_recovery_realistic_mismatch(void)
{
    load_step_recovery(RUN_REALISTIC | RUN_MISMATCH, 70.0, 650.0, 0.100);
}

/* `plant realistic`'s current sensors (README.md "Plant options": phase
 * A +2 %, phase B -2 %; the two the core reads) measure g0 i + G conj(i),
 * G = d (1 + j / sqrt 3), g0 = 1 + (ea + eb) / 2 + j d / sqrt 3,
 * d = (ea - eb) / 2 (gain_balance.h).  Returns d / Re(g0) (0 on the
 * other plants), from which:
 * - g0's turn, tan(phi) = d / sqrt 3 / Re(g0): no measurement tells it
 *   from the machine's, so the measured d current held at 0 leaves the
 *   true one at iq tan(phi), 9.2 mA at 0.8 A (measured 9.4 mA, the mean at
 *   2000 rpm with 0.05 Nm);
 * - the negative sequence's share |G| / Re(g0) = d sqrt(4/3) / Re(g0): a
 *   current of |i| as measured peaks up to that share above |i| in a phase
 *   while the gain balance has not learned G (it learns only with current
 *   and above 750 rpm, and holds through transients). */
static double sensor_mismatch(int mm)
{
    if ((mm & RUN_REALISTIC) == 0) {
        return 0.0;
    }
    const double ea = 0.02, eb = -0.02;
    return 0.5 * (ea - eb) / (1.0 + 0.5 * (ea + eb));
}

/* Steady state below base speed, with and without load: max |id| in each
 * window within its limit (on `plant realistic`, max |id - iq tan(phi)|,
 * the sensors' turn taken out: sensor_mismatch). */
static void id_stays_zero(int mm, const double band_a[5])
{
    run_t r;
    run("0 start\n0.1 speed 1000\n0.4 load 0.05\n0.7 speed 2000\n1.0 load 0\n"
        "1.3 speed 500\n1.6 end\n",
        mm, &r);
    const double windows[][2] = { { 0.3, 0.4 }, { 0.6, 0.7 }, { 0.9, 1.0 },
                                  { 1.2, 1.3 }, { 1.5, 1.6 } };
    const double tan_phi = sensor_mismatch(mm) / sqrt(3.0);
    for (size_t i = 0; i < sizeof windows / sizeof windows[0]; i++) {
        const double id_max = run_max_abs_id(&r, windows[i][0], windows[i][1], tan_phi);
        printf("steady state %.1f..%.1f s: max |id| = %.4f A (limit %.4f A)\n", windows[i][0],
               windows[i][1], id_max, band_a[i]);
        TK_CHECK(id_max <= band_a[i], "|id| %.4f A > %.4f A in %.1f..%.1f s", id_max, band_a[i],
                 windows[i][0], windows[i][1]);
    }
    run_free(&r);
}

#define ID_BAND_A (0.02 * FOC_I_BASE_A) /* the issue's +-2 % of the current base */

/* Measured: 3.4, 25.4, 21.0, 2.8, 5.0 mA (the loaded windows 0.6-1.0 s
 * the larger): the 88 mA for the loaded ones (3.5 x, 4.2 x),
 * 15 mA for the others (3-5 x). */
static void case_id_stays_zero(void)
{
    const double band[5] = { 0.015, ID_BAND_A, ID_BAND_A, 0.015, 0.015 };
    id_stays_zero(0, band);
}
/* Measured: 25.3, 46.1, 49.3, 28.0, 36.1 mA (the ADC noise): the issue's
 * 88 mA (1.8-3.5 x). */
static void case_id_stays_zero_mismatch(void)
{
    const double band[5] = { ID_BAND_A, ID_BAND_A, ID_BAND_A, ID_BAND_A, ID_BAND_A };
    id_stays_zero(1, band);
}
/* On `plant realistic`, |id - iq tan(phi)| (sensor_mismatch): 25.5,
 * 61.6, 67.2, 38.5, 26.9 mA (the true |id| 76.6 mA at 2000 rpm loaded;
 * 93.7 mA before the sensors' gain balance, gain_balance.h, took out
 * their 2-theta ripple); on top of the mismatch 35.1, 65.7, 80.7, 49.7,
 * 31.1 mA (the true |id| 90.0 mA there, where the current loop, 1 kHz,
 * meets the EMF harmonics' 6th, 1 kHz).  The 88 mA (1.1-3.5 x;
 * the mismatch's loaded windows were allowed 0.11 A while the sensors'
 * turn was counted as the controller's error). */
static void case_id_stays_zero_realistic(void)
{
    const double band[5] = { ID_BAND_A, ID_BAND_A, ID_BAND_A, ID_BAND_A, ID_BAND_A };
    id_stays_zero(RUN_REALISTIC, band);
}
static void case_id_stays_zero_realistic_mismatch(void)
{
    const double band[5] = { ID_BAND_A, ID_BAND_A, ID_BAND_A, ID_BAND_A, ID_BAND_A };
    id_stays_zero(RUN_REALISTIC | RUN_MISMATCH, band);
}

/* A load the motor cannot carry within the current limit (0.2 Nm needs
 * about 3.3 A at Kt = 0.06 Nm/A), for 60 ms: the speed loop saturates and
 * the phase current must stay at the regulated limit, CURRENT_LIMIT_A x
 * (1 - CURRENT_REF_MARGIN); once the load goes, the speed comes back (no
 * windup).  (Held longer, the rotor stalls and the drive faults:
 * case_overload_stall.) */
static void current_limit_holds(int mm, double peak_dev_max_a, double back_max_s)
{
    run_t r;
    run("0 start\n0.1 speed 2000\n0.4 load 0.2\n0.46 load 0\n0.9 end\n", mm, &r);
    const double back = run_last_outside(&r, 0.46, 0.9, 2000.0, 20.0) - 0.46;
    const double measured_limit = CURRENT_LIMIT_A * (1.0 - CURRENT_REF_MARGIN);
    /* the true current's peak: the measured limit, and up to the sensors'
     * negative sequence above it (the 2 % sensors unlearned) */
    const double negseq = sensor_mismatch(mm) * sqrt(4.0 / 3.0);
    const double regulated = measured_limit * (1.0 + 0.5 * negseq);
    peak_dev_max_a += 0.5 * measured_limit * negseq;
    printf("overload: peak phase current %.4f A (regulated limit %.4f A, +-%.4f A; limit + 5 %% "
           "%.3f A); speed back within 1 %% %.1f ms after the load goes (limit %.0f)\n",
           r.peak_current_a, regulated, peak_dev_max_a, 1.05 * CURRENT_LIMIT_A, back * 1e3,
           back_max_s * 1e3);
    TK_CHECK(fabs(r.peak_current_a - regulated) <= peak_dev_max_a,
             "peak %.4f A, the regulated limit %.4f A", r.peak_current_a, regulated);
    TK_CHECK(r.peak_current_a <= 1.05 * CURRENT_LIMIT_A, "peak %.3f A > limit + 5 %% (%.3f A)",
             r.peak_current_a, 1.05 * CURRENT_LIMIT_A);
    TK_CHECK(back <= back_max_s, "speed not back within 1 %% (%.1f ms)", back * 1e3);
    run_free(&r);
}

/* Measured: the peak 0.8 / 12.0 mA off the regulated 2.25 A (it was only
 * asked to lie between 2.25 A and 2.625 A), back after 36.3 / 38.6 ms
 * (was 200 ms). */
static void case_current_limit_holds(void) { current_limit_holds(0, 0.004, 0.15); }
static void case_current_limit_holds_mismatch(void) { current_limit_holds(1, 0.04, 0.15); }
/* On `plant realistic` the controller regulates the current it measures:
 * with the sensors' gains 2 % apart (unlearned through the overload) the
 * true peak may lie up to |G| = 2.3 % above the limit: measured 2.311 A
 * (2.299 on top of the mismatch), 35 (23) mA above that band's middle;
 * back after 36.0 (38.5) ms.  The mismatch's 40 mA either side of the
 * band (the limits were +-0.09 A around the measured limit). */
static void case_current_limit_holds_realistic(void)
{
    current_limit_holds(RUN_REALISTIC, 0.04, 0.15);
}
static void case_current_limit_holds_realistic_mismatch(void)
{
    current_limit_holds(RUN_REALISTIC | RUN_MISMATCH, 0.04, 0.15);
}

/* The same load held: the rotor stalls (the plant's speed below 100 rpm)
 * and the drive must say so, SPEED_FEEDBACK within 200 ms of the stall
 * (docs/safety.md), outputs off, the current within the limit. */
static void overload_stall(int mm, double fault_max_s)
{
    run_t r;
    run("0 start\n0.1 speed 2000\n0.4 load 0.2\n1.4 end\n", mm, &r);
    double t_stall = -1.0;
    for (size_t k = 0; k < r.n; k++) {
        if (r.rows[k].t_s >= 0.4 && fabs(r.rows[k].speed_rpm) < 100.0) {
            t_stall = r.rows[k].t_s;
            break;
        }
    }
    const double t_fault = run_first_fault(&r, 0.4, "SPEED_FEEDBACK");
    const double i_after = run_max_phase_current(&r, t_fault + 0.005, 1.4);
    printf("held overload: stalled at %.3f s, SPEED_FEEDBACK at %.3f s (%.1f ms, limit %.0f), "
           "peak %.3f A, then %.4f A\n",
           t_stall, t_fault, (t_fault - t_stall) * 1e3, fault_max_s * 1e3, r.peak_current_a,
           i_after);
    TK_CHECK(t_stall > 0.0, "the rotor did not stall");
    TK_CHECK(t_fault > 0.0 && t_fault - t_stall <= fault_max_s, "fault %.3f s after the stall",
             t_fault - t_stall);
    TK_CHECK(r.peak_current_a <= 1.05 * CURRENT_LIMIT_A, "peak %.3f A", r.peak_current_a);
    TK_CHECK(i_after < 0.01, "outputs not off");
    run_free(&r);
}

/* Measured: 111.4 / 109.3 ms (the 200 ms of docs/safety.md: 1.8 x). */
static void case_overload_stall(void) { overload_stall(0, 0.2); }
static void case_overload_stall_mismatch(void) { overload_stall(1, 0.2); }
static void case_overload_stall_realistic(void) { overload_stall(RUN_REALISTIC, 0.2); }
static void case_overload_stall_realistic_mismatch(void)
{
    overload_stall(RUN_REALISTIC | RUN_MISMATCH, 0.2);
}

static void reversal(int mm, double settle_max_s)
{
    run_t r;
    run("0 start\n0.1 speed 1000\n0.5 speed -1000\n1.0 end\n", mm, &r);
    const double settle = run_last_outside(&r, 0.5, 1.0, -1000.0, 10.0) - 0.5;
    printf("reversal 1000 -> -1000 rpm: within 1 %% after %.1f ms (limit %.0f)\n", settle * 1e3,
           settle_max_s * 1e3);
    TK_CHECK(settle <= settle_max_s, "reversal settle %.1f ms", settle * 1e3);
    TK_CHECK(r.final_state == FOC_STATE_RUN && r.fault == 0, "state %s fault %s",
             foc_state_name(r.final_state), foc_fault_name(r.fault));
    run_free(&r);
}

/* Measured: 210.2 / 208.4 ms (the ramp alone takes 200 ms; 400 ms kept). */
static void case_reversal(void) { reversal(0, 0.4); }
static void case_reversal_mismatch(void) { reversal(1, 0.4); }
static void case_reversal_realistic(void) { reversal(RUN_REALISTIC, 0.4); }
static void case_reversal_realistic_mismatch(void) { reversal(RUN_REALISTIC | RUN_MISMATCH, 0.4); }

/* The bus sags from 24 to 18 V: compensation keeps speed and currents. */
static void bus_compensation(int mm, double dev_max_rpm, double id_max_a)
{
    run_t r;
    run("0 start\n0.1 speed 1000\n0.4 load 0.03\n0.5 vdc 18\n0.8 end\n", mm, &r);
    const double before = fmax(run_extreme_speed(&r, 0.45, 0.5, 0) - 1000.0,
                               1000.0 - run_extreme_speed(&r, 0.45, 0.5, 1));
    const double dev = fmax(run_extreme_speed(&r, 0.5, 0.8, 0) - 1000.0,
                            1000.0 - run_extreme_speed(&r, 0.5, 0.8, 1));
    const double id_max = run_max_abs_id(&r, 0.6, 0.8, sensor_mismatch(mm) / sqrt(3.0));
    printf("bus 24 -> 18 V at 1000 rpm: speed at most %.2f rpm off after (%.2f before; limit "
           "%.2f), max |id| %.4f A (limit %.4f)\n",
           dev, before, dev_max_rpm, id_max, id_max_a);
    TK_CHECK(dev <= dev_max_rpm, "speed %.2f rpm off after the bus step", dev);
    TK_CHECK(id_max <= id_max_a, "|id| %.4f A", id_max);
    run_free(&r);
}

/* Measured: the speed 1.19 / 2.38 rpm off after the step (it was asked to
 * be back within 1 %, 10 rpm, after 50 ms and never left it; 2.94 / 3.90
 * when 10 rpm was kept), |id| 23.8 / 46.2 mA: 5 and 10 rpm and the
 * issue's 88 mA (1.9-4.2 x).  On `plant realistic` (alone / on the
 * mismatch) 4.32 / 4.70 rpm, |id - iq tan(phi)| 75.7 / 70.2 mA (the true
 * |id| 81.5 / 75.4). */
static void case_bus_compensation(void) { bus_compensation(0, 5.0, ID_BAND_A); }
static void case_bus_compensation_mismatch(void) { bus_compensation(1, 10.0, ID_BAND_A); }
static void case_bus_compensation_realistic(void)
{
    bus_compensation(RUN_REALISTIC, 10.0, ID_BAND_A);
}
static void case_bus_compensation_realistic_mismatch(void)
{
    bus_compensation(RUN_REALISTIC | RUN_MISMATCH, 10.0, ID_BAND_A);
}

/* Hardware fault input: outputs off at once, latched, cleared by ack,
 * restart works. */
static void overcurrent_latch_and_restart(int mm, double i_after_max_a, double settle_max_s)
{
    run_t r;
    run("0 start\n0.1 speed 1000\n0.3 overcurrent\n0.35 start\n0.45 ack\n"
        "0.5 start\n0.95 end\n",
        mm, &r);
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
    const double i_after = fmax(fabs(after->ia_a), fmax(fabs(after->ib_a), fabs(after->ic_a)));
    const double settle = run_last_outside(&r, 0.5, 0.95, 1000.0, 10.0) - 0.5;
    printf("over-current input: %.4f A 3 ms after the trip (limit %.4f), restarted: within 1 %% "
           "of 1000 rpm %.1f ms after the start (limit %.0f)\n",
           i_after, i_after_max_a, settle * 1e3, settle_max_s * 1e3);
    TK_CHECK(i_after < i_after_max_a, "current %.4f A 3 ms after the trip", i_after);
    TK_CHECK(r.final_state == FOC_STATE_RUN && settle < settle_max_s,
             "restart: state %s, settle %.1f ms", foc_state_name(r.final_state), settle * 1e3);
    run_free(&r);
}

/* Measured: 0.0000 A 3 ms after the trip (limit 50 mA -> 5 mA, about one
 * count of the current ADC), restarted within 1 % after 170.9 / 169.3 ms
 * (400 ms kept: 2.3 x). */
static void case_overcurrent_latch_and_restart(void)
{
    overcurrent_latch_and_restart(0, 0.005, 0.4);
}
static void case_overcurrent_latch_and_restart_mismatch(void)
{
    overcurrent_latch_and_restart(1, 0.005, 0.4);
}
static void case_overcurrent_latch_and_restart_realistic(void)
{
    overcurrent_latch_and_restart(RUN_REALISTIC, 0.005, 0.4);
}
static void case_overcurrent_latch_and_restart_realistic_mismatch(void)
{
    overcurrent_latch_and_restart(RUN_REALISTIC | RUN_MISMATCH, 0.005, 0.4);
}

static void stop_turns_outputs_off(int mm, double i_max_a, double speed_max_rpm)
{
    run_t r;
    run("0 start\n0.1 speed 1000\n0.4 stop\n0.9 end\n", mm, &r);
    const sim_row_t *end = &r.rows[r.n - 1];
    const double i_end = fmax(fabs(end->ia_a), fmax(fabs(end->ib_a), fabs(end->ic_a)));
    printf("stop at 1000 rpm: final %s, 0.5 s later %.4f A (limit %.4f), %.2f rpm (limit %.1f)\n",
           foc_state_name(r.final_state), i_end, i_max_a, end->speed_rpm, speed_max_rpm);
    TK_CHECK(r.final_state == FOC_STATE_IDLE, "final state %s", foc_state_name(r.final_state));
    TK_CHECK(i_end < i_max_a, "current after stop %.4f A", i_end);
    TK_CHECK(fabs(end->speed_rpm) < speed_max_rpm, "speed after stop %.1f rpm", end->speed_rpm);
    run_free(&r);
}

/* Measured: 0.0000 A and 0.00 rpm 0.5 s after the stop (limits 10 mA
 * kept, 100 rpm -> 1 rpm). */
static void case_stop_turns_outputs_off(void) { stop_turns_outputs_off(0, 0.01, 1.0); }
static void case_stop_turns_outputs_off_mismatch(void) { stop_turns_outputs_off(1, 0.01, 1.0); }
static void case_stop_turns_outputs_off_realistic(void)
{
    stop_turns_outputs_off(RUN_REALISTIC, 0.01, 1.0);
}
static void case_stop_turns_outputs_off_realistic_mismatch(void)
{
    stop_turns_outputs_off(RUN_REALISTIC | RUN_MISMATCH, 0.01, 1.0);
}

TK_CASES(TK_CASE(case_speed_steps), TK_CASE(case_speed_steps_mismatch),
         TK_CASE(case_load_step_recovery), TK_CASE(case_load_step_recovery_mismatch),
         TK_CASE(case_id_stays_zero), TK_CASE(case_id_stays_zero_mismatch),
         TK_CASE(case_current_limit_holds), TK_CASE(case_current_limit_holds_mismatch),
         TK_CASE(case_overload_stall), TK_CASE(case_overload_stall_mismatch),
         TK_CASE(case_reversal), TK_CASE(case_reversal_mismatch),
         TK_CASE(case_bus_compensation), TK_CASE(case_bus_compensation_mismatch),
         TK_CASE(case_overcurrent_latch_and_restart),
         TK_CASE(case_overcurrent_latch_and_restart_mismatch),
         TK_CASE(case_stop_turns_outputs_off), TK_CASE(case_stop_turns_outputs_off_mismatch),
         TK_CASE(case_speed_steps_realistic), TK_CASE(case_speed_steps_realistic_mismatch),
         TK_CASE(case_load_step_recovery_realistic),
         TK_CASE(case_load_step_recovery_realistic_mismatch),
         TK_CASE(case_id_stays_zero_realistic), TK_CASE(case_id_stays_zero_realistic_mismatch),
         TK_CASE(case_current_limit_holds_realistic),
         TK_CASE(case_current_limit_holds_realistic_mismatch),
         TK_CASE(case_overload_stall_realistic), TK_CASE(case_overload_stall_realistic_mismatch),
         TK_CASE(case_reversal_realistic), TK_CASE(case_reversal_realistic_mismatch),
         TK_CASE(case_bus_compensation_realistic),
         TK_CASE(case_bus_compensation_realistic_mismatch),
         TK_CASE(case_overcurrent_latch_and_restart_realistic),
         TK_CASE(case_overcurrent_latch_and_restart_realistic_mismatch),
         TK_CASE(case_stop_turns_outputs_off_realistic),
         TK_CASE(case_stop_turns_outputs_off_realistic_mismatch))
