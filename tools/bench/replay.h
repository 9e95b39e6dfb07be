/*
 * Frame replay: a port (include/foc/port.h) whose samples come from a
 * recorded frame file, and the loop that drives the core through every
 * frame exactly as focsim drove it during the recording, comparing the
 * outputs after each period with the recorded ones.
 *
 * The same C99 code runs on the host (bench_replay_host, linked with the
 * host core) and in the Cortex-M3 bench image (tools/bench/arm), so "the
 * same frames through the core on both give the same outputs" is one
 * function run twice.
 *
 * Per frame: set-up on the first frame of a scenario (foc_init, then the
 * recorded configuration; a scenario whose estimator this core does not
 * contain, or that bench_scenario_mask leaves out, is skipped whole), the
 * recorded commands, foc_fast_step (which
 * reads the frame's samples through foc_port_read_samples), foc_slow_step
 * if the frame says it ran, then the outputs are encoded, hashed and
 * compared with the expected ones.
 */
#ifndef BENCH_REPLAY_H
#define BENCH_REPLAY_H

#include <stdint.h>
#include "bench_io.h"

#define BENCH_NO_MISMATCH 0xFFFFFFFFu

typedef struct {
    uint32_t status;          /* 0 ok, 1 malformed file */
    uint32_t frames;          /* frames run */
    uint32_t mismatches;      /* frames whose outputs differ */
    uint32_t first_mismatch;  /* frame index, or BENCH_NO_MISMATCH */
    uint32_t hash;            /* FNV-1a of every frame's encoded outputs */
    uint32_t skipped;         /* bit per scenario not run: masked out, or its
                               * estimator is not built into this core */
    uint8_t first_actual[BENCH_OUT_BYTES]; /* outputs at first_mismatch */
} bench_result_t;

/* The controller the replay drives (global so that a map file shows its
 * size: it is the core's RAM). */
extern foc_ctrl_t bench_ctrl;

/* Scenarios to run, a bit each (all by default; the simulator may change
 * it before the run). */
extern uint32_t bench_scenario_mask;

void bench_replay(const uint8_t *data, uint32_t len, bench_result_t *res);

#endif /* BENCH_REPLAY_H */
