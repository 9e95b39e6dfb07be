/*
 * bench_replay_host <frames.bin>: runs the recorded frames through the
 * host build of the core with the frame-replay port (replay.c) and checks
 * that every period's outputs equal the recorded ones.  Prints the frame
 * count, mismatches and the output hash (which the Cortex-M3 run must
 * reproduce); exit status 0 only if nothing differs.
 */
#include <stdio.h>
#include <stdlib.h>

#include "frames_file.h"
#include "replay.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: bench_replay_host <frames.bin>\n");
        return 2;
    }
    uint32_t len = 0;
    uint8_t *data = bench_frames_load(argv[1], &len, "bench_replay_host");
    if (data == NULL) {
        return 2;
    }

    static bench_result_t r;
    bench_replay(data, len, &r);
    if (r.status != 0) {
        fprintf(stderr, "bench_replay_host: %s: not a frame file of this build "
                "(re-record it)\n", argv[1]);
        return 1;
    }
    printf("frames=%u\nmismatches=%u\nhash=0x%08x\nskipped=0x%x\n", (unsigned)r.frames,
           (unsigned)r.mismatches, (unsigned)r.hash, (unsigned)r.skipped);
    if (r.mismatches != 0u) {
        bench_file_t bf;
        (void)bench_file_open(&bf, data, (uint32_t)len);
        const uint8_t *e = bench_expected(&bf, r.first_mismatch);
        printf("first_mismatch=%u\nexpected=", (unsigned)r.first_mismatch);
        for (unsigned k = 0; k < BENCH_OUT_BYTES; k++) {
            printf("%02x", e[k]);
        }
        printf("\nactual=  ");
        for (unsigned k = 0; k < BENCH_OUT_BYTES; k++) {
            printf("%02x", r.first_actual[k]);
        }
        printf("\n");
    }
    free(data);
    if (r.skipped != 0u) {
        printf("bench_replay_host: scenarios skipped (estimator not built)\n");
    }
    return (r.mismatches == 0u && r.skipped == 0u) ? 0 : 1;
}
