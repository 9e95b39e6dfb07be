#include "scenario_run.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "foc/config.h"

void run_scenario(const char *text, foc_est_kind_t est, run_t *out)
{
    sim_options_t opt;
    sim_default_options(&opt);
    opt.estimator = est;
    run_scenario_with(text, &opt, out);
}

void run_scenario_with(const char *text, const sim_options_t *opt, run_t *out)
{
    scn_t scn;
    char err[256];
    if (scn_parse_text(text, "test", &scn, err, sizeof err) != 0) {
        fprintf(stderr, "scenario error: %s\n", err);
        exit(2);
    }
    static sim_t sim;
    if (sim_init(&sim, opt, &scn, err, sizeof err) != 0) {
        fprintf(stderr, "sim error: %s\n", err);
        exit(2);
    }
    size_t cap = 1024;
    out->rows = malloc(cap * sizeof *out->rows);
    out->limited = malloc(cap);
    out->n = 0;
    sim_row_t row;
    while (out->rows != NULL && out->limited != NULL && sim_step(&sim, &row)) {
        if (out->n == cap) {
            cap *= 2;
            sim_row_t *grown = realloc(out->rows, cap * sizeof *grown);
            unsigned char *grown_limited = realloc(out->limited, cap);
            if (grown != NULL) {
                out->rows = grown;
            }
            if (grown_limited != NULL) {
                out->limited = grown_limited;
            }
            if (grown == NULL || grown_limited == NULL) {
                free(out->rows);
                free(out->limited);
                out->rows = NULL;
                out->limited = NULL;
                break;
            }
        }
        out->limited[out->n] = sim.ctrl.speed_limited;
        out->rows[out->n++] = row;
    }
    if (out->rows == NULL || out->limited == NULL) {
        fprintf(stderr, "out of memory\n");
        exit(2);
    }
    out->closed_loop_time_s = sim.closed_loop_time_s;
    out->peak_current_a = sim.peak_current_a;
    out->final_state = sim.ctrl.state;
    out->fault = sim.ctrl.faults.first;
    out->on_estimator = sim.ctrl.est.use_sensor == 0u;
    out->speed_limited = sim.ctrl.speed_limited;
    scn_free(&scn);
}

void run_free(run_t *r)
{
    free(r->rows);
    free(r->limited);
    r->rows = NULL;
    r->limited = NULL;
    r->n = 0;
}

size_t run_index_at(const run_t *r, double t_s)
{
    size_t k = 0;
    while (k < r->n && r->rows[k].t_s < t_s) {
        k++;
    }
    return k;
}

double run_last_outside(const run_t *r, double t0, double t1, double target,
                        double tol)
{
    double last = t0;
    for (size_t k = run_index_at(r, t0); k < r->n && r->rows[k].t_s < t1; k++) {
        if (fabs(r->rows[k].speed_rpm - target) > tol) {
            last = r->rows[k].t_s;
        }
    }
    return last;
}

double run_extreme_speed(const run_t *r, double t0, double t1, int below)
{
    double ext = below ? INFINITY : -INFINITY;
    for (size_t k = run_index_at(r, t0); k < r->n && r->rows[k].t_s < t1; k++) {
        const double v = r->rows[k].speed_rpm;
        ext = below ? fmin(ext, v) : fmax(ext, v);
    }
    return ext;
}

double run_share_limited(const run_t *r, double t0, double t1)
{
    size_t n = 0, limited = 0;
    for (size_t k = run_index_at(r, t0); k < r->n && r->rows[k].t_s < t1; k++) {
        limited += r->limited[k] != 0u;
        n++;
    }
    return n ? (double)limited / (double)n : 0.0;
}

double run_max_abs_id(const run_t *r, double t0, double t1, double tan_phi)
{
    double m = 0.0;
    for (size_t k = run_index_at(r, t0); k < r->n && r->rows[k].t_s < t1; k++) {
        m = fmax(m, fabs(r->rows[k].id_a - r->rows[k].iq_a * tan_phi));
    }
    return m;
}

double run_first_state(const run_t *r, double t0, const char *state)
{
    for (size_t k = run_index_at(r, t0); k < r->n; k++) {
        if (strcmp(r->rows[k].state, state) == 0) {
            return r->rows[k].t_s;
        }
    }
    return -1.0;
}

double run_first_fault(const run_t *r, double t0, const char *fault)
{
    for (size_t k = run_index_at(r, t0); k < r->n; k++) {
        if (strcmp(r->rows[k].fault, fault) == 0) {
            return r->rows[k].t_s;
        }
    }
    return -1.0;
}

double run_max_phase_current(const run_t *r, double t0, double t1)
{
    double m = 0.0;
    for (size_t k = run_index_at(r, t0); k < r->n && r->rows[k].t_s < t1; k++) {
        const sim_row_t *w = &r->rows[k];
        m = fmax(m, fmax(fabs(w->ia_a), fmax(fabs(w->ib_a), fabs(w->ic_a))));
    }
    return m;
}

double run_mean_speed(const run_t *r, double t0, double t1)
{
    double sum = 0.0;
    size_t n = 0;
    for (size_t k = run_index_at(r, t0); k < r->n && r->rows[k].t_s < t1; k++) {
        sum += r->rows[k].speed_rpm;
        n++;
    }
    return n ? sum / (double)n : 0.0;
}

void run_mismatch_plant(char *buf, size_t len)
{
    snprintf(buf, len,
             "0 plant rs %.9g\n0 plant ld %.9g\n0 plant lq %.9g\n0 plant flux %.9g\n"
             "0 plant noise 2\n0 plant deadtime %.9g\n",
             1.3 * MOTOR_RS_OHM, 0.8 * MOTOR_LD_H, 0.8 * MOTOR_LQ_H, 1.1 * FOC_FLUX_WB,
             PWM_DEADTIME_S);
}

const char *run_text(char *buf, size_t len, int plant, const char *scenario)
{
    char mismatch[256] = "";
    if ((plant & RUN_MISMATCH) != 0) {
        run_mismatch_plant(mismatch, sizeof mismatch);
    }
    snprintf(buf, len, "%s%s%s", (plant & RUN_REALISTIC) != 0 ? "0 plant realistic\n" : "",
             mismatch, scenario);
    return buf;
}

void run_est_errors(const run_t *r, double t0, double t1, run_est_errors_t *out)
{
    double sa = 0.0, ss = 0.0, peak = 0.0;
    size_t n = 0;
    for (size_t k = run_index_at(r, t0); k < r->n && r->rows[k].t_s < t1; k++) {
        const sim_row_t *w = &r->rows[k];
        if (strcmp(w->state, "RUN") != 0) {
            continue;
        }
        const double a = remainder(w->theta_est_deg - w->theta_e_deg, 360.0);
        const double e = w->speed_est_rpm - w->speed_rpm;
        sa += a * a;
        ss += e * e;
        peak = fmax(peak, fabs(a));
        n++;
    }
    out->n_run = n;
    out->angle_rms_deg = n ? sqrt(sa / (double)n) : 0.0;
    out->angle_peak_deg = peak;
    out->speed_err_rms_rpm = n ? sqrt(ss / (double)n) : 0.0;
}
