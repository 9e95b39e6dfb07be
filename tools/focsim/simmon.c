/* focsim's monitor on a pseudo-terminal; see simmon.h. */
#define _XOPEN_SOURCE 600
#define _DEFAULT_SOURCE
#include "simmon.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

int simmon_open(simmon_t *m, foc_ctrl_t *ctrl, double pace, char *err, size_t errlen)
{
    m->master = posix_openpt(O_RDWR | O_NOCTTY);
    if (m->master < 0 || grantpt(m->master) != 0 || unlockpt(m->master) != 0) {
        snprintf(err, errlen, "cannot create a pseudo-terminal: %s", strerror(errno));
        return -1;
    }
    const char *name = ptsname(m->master);
    m->slave = (name != NULL) ? open(name, O_RDWR | O_NOCTTY) : -1;
    struct termios tio;
    if (m->slave < 0 || tcgetattr(m->slave, &tio) != 0) {
        snprintf(err, errlen, "cannot open the pseudo-terminal's slave: %s", strerror(errno));
        close(m->master);
        return -1;
    }
    cfmakeraw(&tio);
    tcsetattr(m->slave, TCSANOW, &tio);
    fcntl(m->master, F_SETFL, fcntl(m->master, F_GETFL) | O_NONBLOCK);
    m->pace = pace;
    m->countdown = 0;
    clock_gettime(CLOCK_MONOTONIC, &m->t0);
    foc_scope_init(&m->scope, ctrl, m->buf, (uint16_t)SIMMON_SCOPE_SAMPLES);
    foc_mon_init(&m->mon, ctrl, &m->scope);
    fprintf(stderr, "pty: %s\n", name);
    fflush(stderr);
    return 0;
}

static void serve(simmon_t *m)
{
    uint8_t in[256];
    ssize_t n;
    while ((n = read(m->master, in, sizeof in)) > 0) {
        for (ssize_t i = 0; i < n; i++) {
            foc_mon_rx(&m->mon, in[i]);
            /* the reply goes out before the next request byte, as a
             * board's main loop does (the host waits for it anyway) */
            uint8_t out[64];
            size_t k = 0;
            uint8_t b;
            while (foc_mon_tx(&m->mon, &b) != 0u) {
                out[k++] = b;
                if (k == sizeof out) {
                    (void)!write(m->master, out, k);
                    k = 0;
                }
            }
            if (k > 0) {
                (void)!write(m->master, out, k);
            }
        }
    }
}

void simmon_run(simmon_t *m, double t_s)
{
    if (m->countdown > 0u) {
        m->countdown--;
        return;
    }
    m->countdown = SIMMON_SERVICE_PERIODS - 1u;
    serve(m);
    if (m->pace > 0.0) {
        struct timespec now;
        clock_gettime(CLOCK_MONOTONIC, &now);
        const double wall = (double)(now.tv_sec - m->t0.tv_sec) + 1e-9 * (double)(now.tv_nsec - m->t0.tv_nsec);
        const double ahead = t_s / m->pace - wall;
        if (ahead > 0.001) {
            const struct timespec d = { (time_t)ahead, (long)((ahead - (double)(time_t)ahead) * 1e9) };
            nanosleep(&d, NULL);
        }
    }
}

void simmon_close(simmon_t *m)
{
    serve(m);
    close(m->slave);
    close(m->master);
}
