#include "estimator_metrics.h"

#include "foc/config.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define WINDOW_S 0.2      /* angle and speed-estimate statistics */
/* The mean speed over about eleven periods of the light rotor's hunt at
 * 500 rpm (about 14 Hz): over the 0.2 s window it followed the hunt's
 * phase, -0.13 to +0.22 % with the start angle alone (Luenberger,
 * plant realistic, 500 rpm, six angles), +0.023 to +0.053 % over 0.8 s. */
#define MEAN_WINDOW_S 0.8
#define MIN_FIRST_RPM 400.0 /* above the sensored hand-over */

/* Time to ramp between two speeds at the configured slew rate. */
static double ramp_s(double from, double to)
{
    return fabs(to - from) / SPEED_RAMP_RPM_PER_S;
}

void est_measure(foc_est_kind_t kind, const est_case_t *c, est_result_t *out)
{
    const double sign = c->speed_rpm < 0.0 ? -1.0 : 1.0;
    const double first = sign * fmax(fabs(c->speed_rpm), MIN_FIRST_RPM);
    const double t_first = 0.1;
    const double t_target = t_first + ramp_s(0.0, first) + 0.1;
    const double t_load = t_target + ramp_s(first, c->speed_rpm) + 0.1;
    const double t_window = t_load + 0.3;
    const double t_end = t_window + MEAN_WINDOW_S;

    char text[1024];
    snprintf(text, sizeof text,
             "%s\n0 angle %g\n0 start\n%g speed %g\n%g speed %g\n%g load %g\n%g end\n",
             c->plant ? c->plant : "", c->angle_deg, t_first, first, t_target,
             c->speed_rpm, t_load, c->load_nm, t_end);
    sim_options_t opt;
    sim_default_options(&opt);
    opt.estimator = kind;
    opt.sensored_start = !c->aligned_start;
    opt.ideal_inverter = !c->realistic;
    /* the estimator itself, below the product's command floor
     * (SENSORLESS_MIN_SPEED_RPM) too */
    opt.min_speed_rpm = 0;
    run_t r;
    run_scenario_with(text, &opt, &r);

    double sum_e2 = 0.0, peak = 0.0, sum_s2 = 0.0, sum_speed = 0.0;
    size_t n = 0, n_mean = 0;
    const size_t k_stats_end = run_index_at(&r, t_window + WINDOW_S);
    out->in_run = 1;
    for (size_t k = run_index_at(&r, t_window); k < r.n; k++) {
        const sim_row_t *row = &r.rows[k];
        if (k < k_stats_end) {
            const double e = remainder(row->theta_est_deg - row->theta_e_deg, 360.0);
            const double se = row->speed_est_rpm - row->speed_rpm;
            sum_e2 += e * e;
            peak = fmax(peak, fabs(e));
            sum_s2 += se * se;
            n++;
        }
        sum_speed += row->speed_rpm;
        out->in_run &= strcmp(row->state, "RUN") == 0;
        n_mean++;
    }
    out->ran_on_estimator = r.on_estimator;
    out->angle_rms_deg = n ? sqrt(sum_e2 / (double)n) : INFINITY;
    out->angle_peak_deg = peak;
    out->speed_err_rms_pct = n ? 100.0 * sqrt(sum_s2 / (double)n) / fabs(c->speed_rpm) : INFINITY;
    out->speed_mean_rpm = n_mean ? sum_speed / (double)n_mean : 0.0;
    run_free(&r);
}

int est_check(const char *label, const est_result_t *r, const est_limits_t *lim,
              double target_rpm)
{
    const double speed_dev_pct = 100.0 * fabs(r->speed_mean_rpm - target_rpm) / fabs(target_rpm);
    const int ok = r->in_run && r->ran_on_estimator && r->angle_rms_deg <= lim->rms_deg &&
                   r->angle_peak_deg <= lim->peak_deg &&
                   r->speed_err_rms_pct <= lim->speed_err_pct &&
                   speed_dev_pct <= lim->speed_dev_pct;
    printf("%-40s angle rms %6.3f deg peak %6.3f deg | speed err rms %6.3f %% | "
           "speed %8.2f rpm (%5.3f %% off)%s%s  %s\n",
           label, r->angle_rms_deg, r->angle_peak_deg, r->speed_err_rms_pct,
           r->speed_mean_rpm, speed_dev_pct, r->in_run ? "" : " NOT-RUN",
           r->ran_on_estimator ? "" : " ON-SENSOR", ok ? "ok" : "FAIL");
    if (!ok) {
        printf("%-40s limits: rms %.3f deg, peak %.3f deg, speed err %.3f %%, speed %.3f %%\n",
               "", lim->rms_deg, lim->peak_deg, lim->speed_err_pct, lim->speed_dev_pct);
    }
    return ok;
}

double est_lowest_speed(foc_est_kind_t kind, const double *speeds, int n,
                        double rms_max_deg, const char *plant, int realistic,
                        double *worst_rms_deg)
{
    double lowest = 0.0, worst = 0.0;
    for (int i = 0; i < n; i++) {
        const est_case_t c = { speeds[i], 0.0, 77.0, plant, realistic, 0 };
        est_result_t r;
        est_measure(kind, &c, &r);
        const int ok = r.in_run && r.ran_on_estimator && r.angle_rms_deg <= rms_max_deg &&
                       fabs(r.speed_mean_rpm - speeds[i]) <= 0.1 * speeds[i];
        printf("  %6.1f rpm: angle rms %7.3f deg, speed %7.1f rpm %s\n", speeds[i],
               r.angle_rms_deg, r.speed_mean_rpm, ok ? "ok" : "out");
        if (!ok) {
            break;
        }
        lowest = speeds[i];
        worst = fmax(worst, r.angle_rms_deg);
    }
    if (worst_rms_deg != NULL) {
        *worst_rms_deg = worst;
    }
    return lowest;
}

#define WALK_HOLD_S 0.5

double est_lowest_speed_walk(foc_est_kind_t kind, const double *speeds, int n,
                             double rms_max_deg, const char *plant, int realistic)
{
    char text[1024];
    int len = snprintf(text, sizeof text, "%s\n0 angle 77\n0 start\n", plant ? plant : "");
    for (int i = 0; i < n; i++) {
        len += snprintf(text + len, sizeof text - (size_t)len, "%g speed %g\n",
                        0.1 + WALK_HOLD_S * i, speeds[i]);
    }
    snprintf(text + len, sizeof text - (size_t)len, "%g end\n", 0.1 + WALK_HOLD_S * n);
    sim_options_t opt;
    sim_default_options(&opt);
    opt.estimator = kind;
    opt.sensored_start = 1;
    opt.ideal_inverter = !realistic;
    opt.min_speed_rpm = 0;
    run_t r;
    run_scenario_with(text, &opt, &r);
    double lowest = 0.0;
    for (int i = 0; i < n; i++) {
        const double t1 = 0.1 + WALK_HOLD_S * (i + 1);
        run_est_errors_t e;
        run_est_errors(&r, t1 - WINDOW_S, t1, &e);
        const size_t rows = run_index_at(&r, t1) - run_index_at(&r, t1 - WINDOW_S);
        const double speed = run_mean_speed(&r, t1 - WINDOW_S, t1);
        const int ok = r.on_estimator && e.n_run == rows && rows > 0 &&
                       e.angle_rms_deg <= rms_max_deg && fabs(speed - speeds[i]) <= 0.1 * speeds[i];
        printf("  %6.1f rpm (held): angle rms %7.3f deg, speed %7.1f rpm %s\n", speeds[i],
               e.angle_rms_deg, speed, ok ? "ok" : "out");
        if (!ok) {
            break;
        }
        lowest = speeds[i];
    }
    run_free(&r);
    return lowest;
}

void est_detuned_plant(char *buf, size_t len)
{
    snprintf(buf, len, "0 plant rs %g\n0 plant ld %g\n0 plant lq %g\n0 plant flux %g",
             1.3 * MOTOR_RS_OHM, 0.8 * MOTOR_LD_H, 0.8 * MOTOR_LQ_H, 0.9 * FOC_FLUX_WB);
}

int est_luenberger_500rpm_switched(const char *motor, const est_switched_limits_t lim[3])
{
    static const char *const text[3] = {
        "0 plant switched 1\n0 start\n0.1 speed 500\n1.5 end\n",
        "0 plant realistic\n0 start\n0.1 speed 500\n1.5 end\n",
        "0 plant realistic\n0 start\n0.1 speed 500\n0.6 load 0.05\n1.5 end\n",
    };
    int ok = 1;
    for (size_t i = 0; i < 3u; i++) {
        run_t r;
        run_scenario(text[i], FOC_EST_LUENBERGER, &r);
        run_est_errors_t e;
        run_est_errors(&r, 0.9, 1.5, &e);
        const size_t n = run_index_at(&r, 1.5) - run_index_at(&r, 0.9);
        const double speed = run_mean_speed(&r, 0.9, 1.5);
        const int pass = r.final_state == FOC_STATE_RUN && r.fault == 0 && e.n_run == n && n > 0 &&
                         e.angle_rms_deg <= lim[i].rms_max_deg &&
                         e.speed_err_rms_rpm <= lim[i].speed_err_max_rpm && fabs(speed - 500.0) < 10.0;
        printf("  %s luenberger 500 rpm, run %zu: final %s %s, %zu of %zu rows in RUN, angle rms %.2f "
               "(<= %.1f) peak %.2f deg, speed estimate error rms %.1f (<= %.0f) rpm, mean speed "
               "%.1f rpm: %s\n",
               motor, i, foc_state_name(r.final_state), foc_fault_name(r.fault), e.n_run, n,
               e.angle_rms_deg, lim[i].rms_max_deg, e.angle_peak_deg, e.speed_err_rms_rpm,
               lim[i].speed_err_max_rpm, speed, pass ? "ok" : "FAIL");
        ok &= pass;
        run_free(&r);
    }
    return ok;
}
