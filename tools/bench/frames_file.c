#include "frames_file.h"

#include <stdio.h>
#include <stdlib.h>

uint8_t *bench_frames_load(const char *path, uint32_t *len, const char *who)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        perror(path);
        return NULL;
    }
    fseek(f, 0, SEEK_END);
    const long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *data = malloc(n > 0 ? (size_t)n : 1u);
    if (data == NULL || n <= 0 || fread(data, 1, (size_t)n, f) != (size_t)n) {
        fprintf(stderr, "%s: cannot read %s\n", who, path);
        free(data);
        fclose(f);
        return NULL;
    }
    fclose(f);
    *len = (uint32_t)n;
    return data;
}
