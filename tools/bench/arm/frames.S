/* The recorded frames (BENCH_FRAMES_FILE, set by image.mk), in their own
 * region (see bench.ld). */
    .section .frames, "a"
    .global bench_frames_start
    .global bench_frames_end
    .p2align 2
bench_frames_start:
    .incbin BENCH_FRAMES_FILE
bench_frames_end:
