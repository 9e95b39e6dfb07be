/*
 * focsim's monitor: the core's monitor (foc/monitor.h) and scope
 * (foc/scope.h) on the simulated controller, served on a pseudo-terminal
 * (--pty) as a board serves them on its UART, so that tools/foc-monitor
 * talks to focsim exactly as to a board.
 *
 * simmon_open creates the pseudo-terminal (posix_openpt), sets its slave
 * side raw (no line discipline: the protocol is binary) and keeps it open
 * (so the master never sees a hang-up between two host connections), and
 * prints one line "pty: /dev/pts/N" on standard error.  simmon_run, called
 * before every PWM period, moves the bytes both ways every
 * SIMMON_SERVICE_PERIODS periods (the application's main loop) and paces
 * the simulation: simulated time runs `pace` times as fast as wall time
 * (0: as fast as it can).
 *
 * The scope buffer (SIMMON_SCOPE_SAMPLES int16 samples) lives here, like an
 * application's RAM buffer on a board; the simulation samples it once per
 * PWM period at the end of the fast step (sim_t.scope).  The control
 * interrupt's load is unknown on the host (FOC_MON_LOAD_UNKNOWN).
 */
#ifndef FOCSIM_SIMMON_H
#define FOCSIM_SIMMON_H

#include <stddef.h>
#include <stdint.h>
#include <time.h>

#include "foc/monitor.h"
#include "foc/scope.h"

#define SIMMON_SCOPE_SAMPLES 4096u
#define SIMMON_SERVICE_PERIODS 10u

typedef struct {
    foc_scope_t scope;
    foc_mon_t mon;
    int16_t buf[SIMMON_SCOPE_SAMPLES];
    int master, slave;
    double pace;
    struct timespec t0;
    unsigned countdown;
} simmon_t;

/* 0, or -1 with a message. */
int simmon_open(simmon_t *m, foc_ctrl_t *ctrl, double pace, char *err, size_t errlen);

/* Before the PWM period starting at `t_s`. */
void simmon_run(simmon_t *m, double t_s);

void simmon_close(simmon_t *m);

#endif /* FOCSIM_SIMMON_H */
