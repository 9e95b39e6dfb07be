/*
 * Cortex-M3 bench image: replays the recorded frames (linked in at
 * bench_frames_start, tools/bench/arm/frames.S) through the core, exactly
 * as bench_replay_host does on the host, and leaves the result in
 * bench_result for the simulator to read (tools/bench/bench.py).
 */
#include "replay.h"

extern const uint8_t bench_frames_start[];
extern const uint8_t bench_frames_end[];

bench_result_t bench_result;

int main(void)
{
    bench_replay(bench_frames_start,
                 (uint32_t)(bench_frames_end - bench_frames_start), &bench_result);
    return 0;
}
