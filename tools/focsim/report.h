/*
 * focsim --report: what a user would otherwise script from the CSV, judged
 * on the plant's true values (the rows' speed_rpm, theta_e_deg, phase
 * currents), never on what the controller says about itself.
 *
 * Per speed step (each scenario `speed` event, to the next one, a `stop`
 * or the end): the target (the command as the controller accepted it, its clamps
 * included: the caller passes it), the settling time (from the
 * event until the true speed stays within the band REPORT_BAND_PCT of the
 * target, or of the maximum speed for a target of zero; NaN if it never
 * does), the overshoot beyond the target in the step's direction (rpm and
 * % of the step), the steady error (mean true speed minus target over the
 * step's last REPORT_STEADY_SHARE); over the whole run: the angle error's
 * RMS and peak in RUN, the peak phase current and the time it spent above
 * CURRENT_LIMIT_A.  The keys begin with the references (the band, the
 * build's maximum speed and current limit).
 */
#ifndef FOCSIM_REPORT_H
#define FOCSIM_REPORT_H

#include <stdint.h>
#include <stdio.h>

#include "scenario.h"
#include "sim.h"

#define REPORT_STEPS_MAX 32
#define REPORT_BAND_PCT 2.0
#define REPORT_STEADY_SHARE 0.2

typedef struct {
    double t0_s, t_end_s;     /* the step's span */
    double start_rpm;         /* true speed at its start */
    double target_rpm;        /* the command as accepted */
    double last_outside_s;    /* last time outside the band (< t0: never) */
    double overshoot_rpm;     /* largest excursion beyond the target, signed */
    double steady_sum_rpm;    /* true - reference over the last share */
    uint64_t steady_n;
} report_step_t;

typedef struct {
    report_step_t steps[REPORT_STEPS_MAX];
    int n_steps;              /* the scenario's speed events (at most the max) */
    int current;              /* the step the rows are in, -1 before the first */
    double angle_sq_sum, angle_peak_deg;
    uint64_t angle_n;
    double above_limit_s;     /* time with max |phase current| > the limit */
    double peak_current_a;
    double dt_s;              /* one PWM period */
} report_t;

/* The steps from the scenario's `speed` events (the first REPORT_STEPS_MAX). */
void report_init(report_t *r, const scn_t *scn);

/* One period's row (every period, in order) and the speed command the
 * controller holds then (rpm). */
void report_add(report_t *r, const sim_row_t *row, double command_rpm);

/* The report's summary keys (README.md, focsim). */
void report_print(const report_t *r, FILE *f);

#endif /* FOCSIM_REPORT_H */
