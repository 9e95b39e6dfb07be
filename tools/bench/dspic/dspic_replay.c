/*
 * dspic_replay <frames.bin> <scenario mask> [fast|slow]: the bench frame replay
 * (tools/bench/replay.c) for the dsPIC33 cycle estimate (dspic_est.py).
 *
 * Two copies of the core are linked (dspic.mk): one built with clang's
 * source-based coverage, one plain whose every global symbol is renamed
 * u_<name> (objcopy --redefine-syms), and the harness objects are renamed
 * the same way.  So set-up, commands, the slow step and fast steps outside
 * the current-loop states run in the plain copy, and only fast steps that
 * start in ALIGN, OPENLOOP, RUN, STOP or BRAKE (tools/bench/bench.py's
 * LOOP_STATES) reach the instrumented foc_fast_step: the coverage counts
 * are exactly those steps' executions.  With "slow", the slow steps run
 * after such a fast step are the instrumented ones instead.  replay.c is
 * compiled with -Dfoc_fast_step=dspic_fast_step
 * -Dfoc_slow_step=dspic_slow_step to call the dispatchers below.
 *
 * Prints steps (the instrumented calls), frames, mismatches (must be 0:
 * both copies together reproduce the recording bit for bit) and
 * loop_periods (fast steps in the current-loop states).
 */
#include <stdio.h>
#include <stdlib.h>

#include "frames_file.h"
#include "replay.h"

void u_foc_fast_step(foc_ctrl_t *c);
void u_foc_slow_step(foc_ctrl_t *c);
void dspic_fast_step(foc_ctrl_t *c);
void dspic_slow_step(foc_ctrl_t *c);

static int count_slow;              /* 0: fast steps counted, 1: slow */
static unsigned long steps;         /* instrumented calls */
static unsigned long loop_periods;  /* fast steps in current-loop states */
static int in_loop;                 /* the last fast step was one */

void dspic_fast_step(foc_ctrl_t *c)
{
    switch (c->state) {
    case FOC_STATE_ALIGN:
    case FOC_STATE_OPENLOOP:
    case FOC_STATE_RUN:
    case FOC_STATE_STOP:
    case FOC_STATE_BRAKE:
        in_loop = 1;
        break;
    default:
        in_loop = 0;
        break;
    }
    loop_periods += (unsigned long)in_loop;
    if (in_loop && !count_slow) {
        steps++;
        foc_fast_step(c);
    } else {
        u_foc_fast_step(c);
    }
}

void dspic_slow_step(foc_ctrl_t *c)
{
    if (in_loop && count_slow) {
        steps++;
        foc_slow_step(c);
    } else {
        u_foc_slow_step(c);
    }
}

int main(int argc, char **argv)
{
    if (argc != 3 && argc != 4) {
        fprintf(stderr, "usage: dspic_replay <frames.bin> <scenario mask> [fast|slow]\n");
        return 2;
    }
    count_slow = argc == 4 && argv[3][0] == 's';
    uint32_t len = 0;
    uint8_t *data = bench_frames_load(argv[1], &len, "dspic_replay");
    if (data == NULL) {
        return 2;
    }
    bench_scenario_mask = (uint32_t)strtoul(argv[2], NULL, 0);
    static bench_result_t r;
    bench_replay(data, len, &r);
    printf("steps=%lu\nframes=%u\nmismatches=%u\nloop_periods=%lu\n", steps,
           (unsigned)r.frames, (unsigned)r.mismatches, loop_periods);
    free(data);
    return (r.status == 0 && r.mismatches == 0u && steps > 0u) ? 0 : 1;
}
