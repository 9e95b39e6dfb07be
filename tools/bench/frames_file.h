/*
 * Host-only: a whole frame file (tools/bench/record.c) read into memory,
 * for the host replays (bench_replay_host, the dsPIC estimate's replay).
 */
#ifndef BENCH_FRAMES_FILE_H
#define BENCH_FRAMES_FILE_H

#include <stdint.h>

/* The file's bytes (free() them) and their count in *len; NULL, with a
 * message on stderr naming `who` and the file, if it cannot be read. */
uint8_t *bench_frames_load(const char *path, uint32_t *len, const char *who);

#endif /* BENCH_FRAMES_FILE_H */
