/*
 * focsim: runs the real controller against the motor model.
 *
 *   focsim [--estimator sensored|pll|luenberger|flux] [--scenario FILE]
 *          [--csv FILE] [--plot FILE.svg] [--seed N] [--decimate N]
 *          [--field-weakening off|table|voltage]
 *          [--pty [--pace F]] [--time] [--substeps N]
 *          [--commission-out FILE.ini]
 *          [--measure-from T] [--report] [--print-default-scenario]
 *
 * --report adds, per speed step, the settling time, overshoot and steady
 * error of the true speed, and over the run the angle error's RMS and
 * peak in RUN, the peak phase current and the time above the current
 * limit (report.h).
 *
 * --commission-out writes the motor description (tools/tune.py's INI) of
 * a scenario's `commission` (sim.h sim_commission_ini); without valid
 * results nothing is written and the exit status is 1.
 * --substeps sets the motor model's RK4 substeps per PWM period (default
 * 4; fewer is faster and less accurate: docs/benchmarks.md, "focsim
 * speed").
 * --time adds the processor time of the simulation loop and the real-time
 * factor (simulated / processor seconds) to the summary.
 *
 * --pty serves the monitor (foc/monitor.h, docs/monitor.md) on a
 * pseudo-terminal whose path it prints on standard error ("pty:
 * /dev/pts/N", simmon.h), with a scope buffer sampled after every fast
 * step, and paces the simulation to wall time: --pace F runs it F times as
 * fast (default 1; 0 as fast as it can).  tools/foc-monitor connects to it.
 *
 * The summary's angle_err_rms_deg is the RMS of the estimated minus the
 * plant's true electrical angle (deg) over the PWM periods in RUN from
 * --measure-from T seconds on (default 0: all of RUN); nan when there was
 * no such period.
 *
 * Without --estimator it uses the one userparms.h selects (FOC_ESTIMATOR);
 * without --scenario it runs the scenario derived from the build's motor
 * (default_scenario.h), which --print-default-scenario prints.  Prints a summary
 * of key=value lines at the end (with id_rs_ohm, id_ld_h, id_lq_h,
 * id_flux_wb when the scenario commissioned).  Exit status: 0 after a completed run,
 * 1 on a usage, scenario or file error.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "foc/config.h"
#include "default_scenario.h"
#include "report.h"
#include "sim.h"
#include "simmon.h"
#include "svgplot.h"


typedef struct {
    const char *estimator; /* name, for the plot title and summary */
    const char *scenario;
    const char *csv;
    const char *plot;
    unsigned long decimate;
    int pty;                 /* --pty: the monitor on a pseudo-terminal */
    double pace;             /* --pace: simulated / wall time, 0 unpaced */
    const char *commission_out; /* --commission-out: motor INI, or NULL */
    int time;                /* --time: report the real-time factor */
    int report;              /* --report: report.h's keys */
    int print_default_scenario; /* --print-default-scenario */
    sim_options_t sim;
} cli_t;

/* What the plot needs, one entry per PWM period. */
typedef struct {
    size_t n, cap;
    double *t, *speed_ref, *speed, *speed_est, *id, *iq, *id_ref, *iq_ref,
        *angle_err;
    const char **state;
} trace_t;

static void usage(FILE *f)
{
    fputs("usage: focsim [--estimator sensored|pll|luenberger|flux] [--scenario FILE]\n"
          "              [--csv FILE] [--plot FILE.svg] [--seed N] [--decimate N]\n"
          "              [--field-weakening off|table|voltage] [--stop-mode ramp|coast|short]\n"
          "              [--brake-resistor on|off] [--sensored-start] [--min-speed-rpm N]\n"
          "              [--pty [--pace F]] [--time] [--substeps N]\n"
          "              [--ideal-inverter] [--rs-adapt on|off]\n"
          "              [--commission-out FILE.ini]\n"
          "              [--measure-from T] [--report] [--print-default-scenario]\n",
          f);
}

/* An on|off option's value into *out (1/0). */
static int on_off(const char *opt, const char *val, int *out)
{
    if (strcmp(val, "on") != 0 && strcmp(val, "off") != 0) {
        fprintf(stderr, "focsim: %s takes on or off\n", opt);
        return -1;
    }
    *out = strcmp(val, "on") == 0;
    return 0;
}

static int parse_ulong(const char *s, unsigned long *out)
{
    char *end = NULL;
    errno = 0;
    const unsigned long v = strtoul(s, &end, 10);
    if (errno != 0 || end == s || *end != '\0' || s[0] == '-') {
        return -1;
    }
    *out = v;
    return 0;
}

/* One option with its value; 0, or -1 with a message. */
static int parse_option(cli_t *cli, const char *opt, const char *val)
{
    unsigned long n = 0;
    if (strcmp(opt, "--estimator") == 0) {
        cli->estimator = val;
        if (sim_estimator_from_name(val, &cli->sim.estimator) != 0) {
            fprintf(stderr, "focsim: unknown estimator '%s'\n", val);
            return -1;
        }
    } else if (strcmp(opt, "--scenario") == 0) {
        cli->scenario = val;
    } else if (strcmp(opt, "--csv") == 0) {
        cli->csv = val;
    } else if (strcmp(opt, "--plot") == 0) {
        cli->plot = val;
    } else if (strcmp(opt, "--field-weakening") == 0) {
        if (sim_fw_mode_from_name(val, &cli->sim.fw_mode) != 0) {
            fprintf(stderr, "focsim: unknown field-weakening mode '%s'\n", val);
            return -1;
        }
    } else if (strcmp(opt, "--stop-mode") == 0) {
        if (sim_stop_mode_from_name(val, &cli->sim.stop_mode) != 0) {
            fprintf(stderr, "focsim: unknown stop mode '%s'\n", val);
            return -1;
        }
    } else if (strcmp(opt, "--brake-resistor") == 0) {
        return on_off(opt, val, &cli->sim.brake_resistor);
    } else if (strcmp(opt, "--rs-adapt") == 0) {
        return on_off(opt, val, &cli->sim.rs_adapt);
    } else if (strcmp(opt, "--seed") == 0) {
        if (parse_ulong(val, &n) != 0 || n > 0xFFFFFFFFul) {
            fprintf(stderr, "focsim: --seed takes a whole number 0..4294967295\n");
            return -1;
        }
        cli->sim.seed = (uint32_t)n;
    } else if (strcmp(opt, "--substeps") == 0) {
        if (parse_ulong(val, &n) != 0 || n < 1u || n > 64u) {
            fprintf(stderr, "focsim: --substeps takes 1..64\n");
            return -1;
        }
        cli->sim.substeps = (int)n;
    } else if (strcmp(opt, "--min-speed-rpm") == 0) {
        if (parse_ulong(val, &n) != 0 || n > (unsigned long)MOTOR_MAX_SPEED_RPM) {
            fprintf(stderr, "focsim: --min-speed-rpm takes 0..%.0f (MOTOR_MAX_SPEED_RPM)\n",
                    MOTOR_MAX_SPEED_RPM);
            return -1;
        }
        cli->sim.min_speed_rpm = (int)n;
    } else if (strcmp(opt, "--measure-from") == 0) {
        char *end = NULL;
        const double t = strtod(val, &end);
        if (end == val || *end != '\0' || !(t >= 0.0) || !isfinite(t)) {
            fprintf(stderr, "focsim: --measure-from takes a time in seconds >= 0\n");
            return -1;
        }
        cli->sim.measure_from_s = t;
    } else if (strcmp(opt, "--pace") == 0) {
        char *end = NULL;
        cli->pace = strtod(val, &end);
        if (end == val || *end != '\0' || !(cli->pace >= 0.0)) {
            fprintf(stderr, "focsim: --pace takes a factor >= 0\n");
            return -1;
        }
    } else if (strcmp(opt, "--commission-out") == 0) {
        cli->commission_out = val;
    } else if (strcmp(opt, "--decimate") == 0) {
        if (parse_ulong(val, &cli->decimate) != 0 || cli->decimate == 0) {
            fprintf(stderr, "focsim: --decimate takes a whole number >= 1\n");
            return -1;
        }
    } else {
        fprintf(stderr, "focsim: unknown option '%s'\n", opt);
        return -1;
    }
    return 0;
}

static int parse_cli(int argc, char **argv, cli_t *cli)
{
    cli->scenario = NULL; /* the motor's default (default_scenario.h) */
    cli->csv = NULL;
    cli->plot = NULL;
    cli->decimate = 1;
    cli->pty = 0;
    cli->pace = 1.0;
    cli->commission_out = NULL;
    cli->time = 0;
    cli->report = 0;
    cli->print_default_scenario = 0;
    sim_default_options(&cli->sim);
    cli->estimator = foc_est_name(cli->sim.estimator);
    for (int i = 1; i < argc; i++) {
        const char *opt = argv[i];
        if (strcmp(opt, "--help") == 0 || strcmp(opt, "-h") == 0) {
            usage(stdout);
            exit(0);
        }
        if (strcmp(opt, "--sensored-start") == 0) {
            cli->sim.sensored_start = 1;
            continue;
        }
        if (strcmp(opt, "--time") == 0) {
            cli->time = 1;
            continue;
        }
        if (strcmp(opt, "--pty") == 0) {
            cli->pty = 1;
            continue;
        }
        if (strcmp(opt, "--report") == 0) {
            cli->report = 1;
            continue;
        }
        if (strcmp(opt, "--print-default-scenario") == 0) {
            cli->print_default_scenario = 1;
            continue;
        }
        if (strcmp(opt, "--ideal-inverter") == 0) {
            cli->sim.ideal_inverter = 1;
            continue;
        }
        if (i + 1 >= argc) {
            fprintf(stderr, "focsim: %s needs a value\n", opt);
            return -1;
        }
        if (parse_option(cli, opt, argv[++i]) != 0) {
            return -1;
        }
    }
    return 0;
}

static double *grow(double *p, size_t cap)
{
    double *q = realloc(p, cap * sizeof *q);
    if (q == NULL) {
        fputs("focsim: out of memory\n", stderr);
        exit(1);
    }
    return q;
}

static void trace_add(trace_t *tr, const sim_row_t *r)
{
    if (tr->n == tr->cap) {
        tr->cap = tr->cap ? tr->cap * 2 : 65536;
        double **cols[] = { &tr->t, &tr->speed_ref, &tr->speed, &tr->speed_est, &tr->id,
                            &tr->iq, &tr->id_ref, &tr->iq_ref, &tr->angle_err };
        for (size_t i = 0; i < sizeof cols / sizeof cols[0]; i++) {
            *cols[i] = grow(*cols[i], tr->cap);
        }
        const char **st = realloc(tr->state, tr->cap * sizeof *st);
        if (st == NULL) {
            fputs("focsim: out of memory\n", stderr);
            exit(1);
        }
        tr->state = st;
    }
    const size_t k = tr->n++;
    tr->t[k] = r->t_s;
    tr->speed_ref[k] = r->speed_ref_rpm;
    tr->speed[k] = r->speed_rpm;
    tr->speed_est[k] = r->speed_est_rpm;
    tr->id[k] = r->id_a;
    tr->iq[k] = r->iq_a;
    tr->id_ref[k] = r->id_ref_a;
    tr->iq_ref[k] = r->iq_ref_a;
    tr->angle_err[k] = remainder(r->theta_est_deg - r->theta_e_deg, 360.0);
    tr->state[k] = r->state;
}

static void trace_free(trace_t *tr)
{
    free(tr->t);
    free(tr->speed_ref);
    free(tr->speed);
    free(tr->speed_est);
    free(tr->id);
    free(tr->iq);
    free(tr->id_ref);
    free(tr->iq_ref);
    free(tr->angle_err);
    free(tr->state);
}

/* One band per stretch of constant state. */
static int write_plot(const char *path, const trace_t *tr, const char *estimator)
{
    svg_band_t *bands = malloc((tr->n ? tr->n : 1) * sizeof *bands);
    size_t nb = 0;
    if (bands == NULL) {
        return -1;
    }
    for (size_t k = 0; k < tr->n; k++) {
        if (nb == 0 || strcmp(bands[nb - 1].label, tr->state[k]) != 0) {
            bands[nb].t0_s = tr->t[k];
            bands[nb].label = tr->state[k];
            nb++;
        }
        bands[nb - 1].t1_s = tr->t[k];
    }
    const svg_series_t speed[] = {
        { "reference", "#888888", tr->speed_ref },
        { "true", "#1f77b4", tr->speed },
        { "estimated", "#d62728", tr->speed_est },
    };
    const svg_series_t currents[] = {
        { "id", "#2ca02c", tr->id },      { "iq", "#9467bd", tr->iq },
        { "id ref", "#98df8a", tr->id_ref }, { "iq ref", "#c5b0d5", tr->iq_ref },
    };
    const svg_series_t angle[] = { { "estimated - true", "#ff7f0e", tr->angle_err } };
    const svg_panel_t panels[] = {
        { "Speed (mechanical)", "rpm", speed, 3 },
        { "Rotor-frame currents", "A", currents, 4 },
        { "Angle error (electrical)", "deg", angle, 1 },
    };
    char title[128];
    snprintf(title, sizeof title, "focsim: estimator %s", estimator);
    const int rc = svg_write(path, title, tr->t, tr->n, panels, 3, bands, nb);
    free(bands);
    return rc;
}

static void print_summary(const sim_t *s, const sim_row_t *last, const char *est)
{
    printf("estimator=%s\n", est);
    printf("final_state=%s\n", foc_state_name(s->ctrl.state));
    printf("fault=%s\n", foc_fault_name(s->ctrl.faults.first));
    printf("closed_loop_time_s=%.4f\n", s->closed_loop_time_s);
    printf("speed_rpm_final=%.2f\n", last->speed_rpm);
    printf("speed_ref_rpm_final=%.2f\n", last->speed_ref_rpm);
    printf("speed_est_rpm_final=%.2f\n", last->speed_est_rpm);
    printf("peak_current_a=%.4f\n", s->peak_current_a);
    printf("angle_err_rms_deg=%.3f\n", sim_angle_err_rms_deg(s));
    printf("sim_time_s=%.4f\n", last->t_s);
}

int main(int argc, char **argv)
{
    cli_t cli;
    if (parse_cli(argc, argv, &cli) != 0) {
        usage(stderr);
        return 1;
    }
    scn_t scn;
    char err[512];
    char default_text[1024];
    if (cli.scenario == NULL && sim_default_scenario(default_text, sizeof default_text) < 0) {
        fprintf(stderr, "focsim: the default scenario does not fit its buffer\n");
        return 1;
    }
    if (cli.print_default_scenario) {
        fputs(default_text, stdout);
        return 0;
    }
    if ((cli.scenario != NULL) ? scn_parse_file(cli.scenario, &scn, err, sizeof err) != 0
                               : scn_parse_text(default_text, "default scenario", &scn, err, sizeof err) != 0) {
        fprintf(stderr, "focsim: %s\n", err);
        return 1;
    }
    static sim_t sim;
    if (sim_init(&sim, &cli.sim, &scn, err, sizeof err) != 0) {
        fprintf(stderr, "focsim: %s\n", err);
        scn_free(&scn);
        return 1;
    }
    static simmon_t mon;
    if (cli.pty) {
        if (simmon_open(&mon, &sim.ctrl, cli.pace, err, sizeof err) != 0) {
            fprintf(stderr, "focsim: %s\n", err);
            scn_free(&scn);
            return 1;
        }
        sim.ctrl.scope = &mon.scope; /* after sim_init's foc_init */
    }

    FILE *csv = NULL;
    if (cli.csv != NULL) {
        csv = fopen(cli.csv, "w");
        if (csv == NULL) {
            fprintf(stderr, "focsim: cannot write %s: %s\n", cli.csv, strerror(errno));
            scn_free(&scn);
            return 1;
        }
        fprintf(csv, "%s\n", sim_csv_header());
    }

    trace_t tr = { 0 };
    static report_t rep;
    report_init(&rep, &scn);
    sim_row_t row, last = { 0 };
    char line[512];
    const clock_t t0 = clock();
    for (;;) {
        if (cli.pty) {
            simmon_run(&mon, sim.t_s); /* the board's main loop between periods */
        }
        /* a row only where one is used: CSV, plot, the summary's last */
        const int need_row = csv != NULL || cli.plot != NULL || cli.report || sim_last_period(&sim);
        if (!sim_step(&sim, need_row ? &row : NULL)) {
            break;
        }
        const uint64_t index = sim.period - 1u; /* the period just simulated */
        if (csv != NULL && index % cli.decimate == 0u) {
            sim_csv_row(&row, line, sizeof line);
            fprintf(csv, "%s\n", line);
        }
        if (cli.plot != NULL) {
            trace_add(&tr, &row);
        }
        if (cli.report) {
            report_add(&rep, &row, sim_rpm_from_q15(sim.ctrl.req.speed));
        }
        if (need_row) {
            last = row;
        }
    }
    const double cpu_s = (double)(clock() - t0) / CLOCKS_PER_SEC;

    int rc = 0;
    if (sim.model_failed) {
        fprintf(stderr, "focsim: the motor model's state is no longer finite at %.6f s "
                        "(a plant value beyond physical range?)\n", sim.t_s);
        rc = 1;
    }
    if (csv != NULL && fclose(csv) != 0) {
        fprintf(stderr, "focsim: error writing %s\n", cli.csv);
        rc = 1;
    }
    if (cli.plot != NULL && write_plot(cli.plot, &tr, cli.estimator) != 0) {
        fprintf(stderr, "focsim: cannot write %s\n", cli.plot);
        rc = 1;
    }
    if (cli.pty) {
        simmon_close(&mon);
    }
    print_summary(&sim, &last, cli.estimator);
    sim_commission_print(&sim, stdout);
    if (cli.report) {
        report_print(&rep, stdout);
    }
    if (cli.commission_out != NULL) {
        FILE *ini = fopen(cli.commission_out, "w");
        const int written = ini != NULL && sim_commission_ini(&sim, ini) == 0;
        if (ini == NULL || fclose(ini) != 0 || !written) {
            fprintf(stderr, "focsim: no commissioning results written to %s\n", cli.commission_out);
            rc = 1;
        }
    }
    if (cli.time) {
        printf("cpu_time_s=%.3f\nrealtime_factor=%.1f\n", cpu_s,
               cpu_s > 0.0 ? sim.t_s / cpu_s : 0.0);
    }
    trace_free(&tr);
    scn_free(&scn);
    return rc;
}
