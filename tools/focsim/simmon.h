/*
 * focsim's monitor: the core's text monitor (foc/monitor.h) and scope
 * (foc/scope.h) on the simulated controller, driven by a script of timed
 * command lines instead of a serial line.
 *
 * Script: one command per line, "<time_s> <monitor command>", times not
 * decreasing; blank lines and lines starting with '#' are ignored.  A
 * command is fed byte by byte (with CR LF) before the PWM period whose
 * time t_k >= <time_s> is simulated, as a scenario event is; a scope dump
 * is written out completely at once.  Everything the monitor writes (the
 * exact text a UART would carry) goes to the output file.
 *
 * The scope buffer (SIMMON_SCOPE_SAMPLES int16 samples) lives here, like an
 * application's RAM buffer on a board; the simulation samples it once per
 * PWM period right after the fast step (sim_t.scope).
 */
#ifndef FOCSIM_SIMMON_H
#define FOCSIM_SIMMON_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "foc/monitor.h"
#include "foc/scope.h"

#define SIMMON_SCOPE_SAMPLES 4096u

typedef struct {
    double t_s;
    char *text; /* without the line end */
} simmon_cmd_t;

typedef struct {
    foc_scope_t scope;
    foc_monitor_t mon;
    int16_t buf[SIMMON_SCOPE_SAMPLES];
    simmon_cmd_t *cmds;
    size_t count, next;
    FILE *out;
} simmon_t;

/* Reads the script and opens the output (NULL or "-": standard output);
 * 0, or -1 with a message naming the line. */
int simmon_open(simmon_t *m, const char *script, const char *out_path,
                foc_ctrl_t *ctrl, char *err, size_t errlen);

/* Feeds every command due at `t_s` and writes out any dump. */
void simmon_run(simmon_t *m, double t_s);

/* Closes the output and frees the script; 0, or -1 on a write error.
 * Commands never reached (after the scenario's end) are dropped. */
int simmon_close(simmon_t *m);

#endif /* FOCSIM_SIMMON_H */
