#include "report.h"

#include <math.h>
#include <string.h>

#include "foc/config.h"

void report_init(report_t *r, const scn_t *scn)
{
    memset(r, 0, sizeof *r);
    r->current = -1;
    r->dt_s = 1.0 / PWM_FREQUENCY_HZ;
    /* a step ends at the next speed command, a stop, or the end */
    int open = 0;
    for (size_t k = 0; k < scn->count; k++) {
        const scn_kind_t kind = scn->events[k].kind;
        if (kind != SCN_SPEED && kind != SCN_STOP) {
            continue;
        }
        if (open) {
            r->steps[r->n_steps - 1].t_end_s = scn->events[k].t_s;
            open = 0;
        }
        if (kind == SCN_SPEED && r->n_steps < REPORT_STEPS_MAX) {
            report_step_t *s = &r->steps[r->n_steps];
            s->t0_s = scn->events[k].t_s;
            s->last_outside_s = -INFINITY;
            r->n_steps++;
            open = 1;
        }
    }
    if (open) {
        r->steps[r->n_steps - 1].t_end_s = scn->end_s;
    }
}

/* The band around a target: REPORT_BAND_PCT of it, of the maximum speed
 * for a target near zero. */
static double band_rpm(double target_rpm)
{
    return REPORT_BAND_PCT / 100.0 * fmax(fabs(target_rpm), 0.05 * MOTOR_MAX_SPEED_RPM);
}

/* One row of a step: the band, the excursion beyond the target in the
 * step's direction, the steady share's error. */
static void step_add(report_step_t *s, const sim_row_t *row, double dt_s)
{
    const double dir = (s->target_rpm >= s->start_rpm) ? 1.0 : -1.0;
    const double err = row->speed_rpm - s->target_rpm;
    if (fabs(err) > band_rpm(s->target_rpm)) {
        s->last_outside_s = row->t_s + dt_s;
    }
    s->overshoot_rpm = fmax(s->overshoot_rpm, dir * err);
    if (row->t_s >= s->t_end_s - REPORT_STEADY_SHARE * (s->t_end_s - s->t0_s)) {
        s->steady_sum_rpm += err;
        s->steady_n++;
    }
}

void report_add(report_t *r, const sim_row_t *row, double command_rpm)
{
    while (r->current + 1 < r->n_steps && row->t_s >= r->steps[r->current + 1].t0_s) {
        r->current++;
        r->steps[r->current].start_rpm = row->speed_rpm;
        r->steps[r->current].target_rpm = command_rpm;
    }
    if (r->current >= 0 && row->t_s < r->steps[r->current].t_end_s) {
        step_add(&r->steps[r->current], row, r->dt_s);
    }
    if (strcmp(row->state, "RUN") == 0) {
        const double e = remainder(row->theta_est_deg - row->theta_e_deg, 360.0);
        r->angle_sq_sum += e * e;
        r->angle_peak_deg = fmax(r->angle_peak_deg, fabs(e));
        r->angle_n++;
    }
    const double i_peak = fmax(fabs(row->ia_a), fmax(fabs(row->ib_a), fabs(row->ic_a)));
    r->peak_current_a = fmax(r->peak_current_a, i_peak);
    if (i_peak > CURRENT_LIMIT_A) {
        r->above_limit_s += r->dt_s;
    }
}

static void print_step(FILE *f, int k, const report_step_t *s)
{
    const double step = s->target_rpm - s->start_rpm;
    /* still outside the band at the step's end: never settled */
    const double settle = !isfinite(s->last_outside_s)         ? 0.0
                          : (s->last_outside_s >= s->t_end_s) ? NAN
                                                                : s->last_outside_s - s->t0_s;
    fprintf(f, "step%d_t_s=%.4f\nstep%d_target_rpm=%.2f\nstep%d_start_rpm=%.2f\n", k, s->t0_s, k,
            s->target_rpm, k, s->start_rpm);
    fprintf(f, "step%d_settle_s=%.4f\n", k, settle);
    fprintf(f, "step%d_overshoot_rpm=%.2f\nstep%d_overshoot_pct=%.2f\n", k, s->overshoot_rpm, k,
            fabs(step) > 0.0 ? 100.0 * s->overshoot_rpm / fabs(step) : 0.0);
    fprintf(f, "step%d_steady_err_rpm=%.3f\n", k,
            s->steady_n ? s->steady_sum_rpm / (double)s->steady_n : NAN);
}

void report_print(const report_t *r, FILE *f)
{
    fprintf(f, "report_band_pct=%.1f\nreport_max_speed_rpm=%.1f\nreport_current_limit_a=%.4f\n",
            REPORT_BAND_PCT, (double)MOTOR_MAX_SPEED_RPM, (double)CURRENT_LIMIT_A);
    fprintf(f, "report_steps=%d\n", r->n_steps);
    for (int k = 0; k < r->n_steps; k++) {
        print_step(f, k + 1, &r->steps[k]);
    }
    fprintf(f, "run_angle_err_rms_deg=%.3f\nrun_angle_err_peak_deg=%.3f\n",
            r->angle_n ? sqrt(r->angle_sq_sum / (double)r->angle_n) : NAN, r->angle_peak_deg);
    fprintf(f, "peak_phase_current_a=%.4f\ntime_above_current_limit_s=%.6f\n", r->peak_current_a,
            r->above_limit_s);
}
