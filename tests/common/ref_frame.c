#include "ref_frame.h"

uint16_t ref_crc(const uint8_t *p, size_t n)
{
    uint32_t crc = 0xFFFF;
    for (size_t i = 0; i < n; i++) {
        for (int b = 7; b >= 0; b--) {
            const uint32_t bit = ((crc >> 15) ^ ((uint32_t)p[i] >> b)) & 1u;
            crc = ((crc << 1) & 0xFFFF) ^ (bit ? 0x1021u : 0u);
        }
    }
    return (uint16_t)crc;
}

size_t ref_cobs(const uint8_t *p, size_t n, uint8_t *out)
{
    size_t o = 1, code_at = 0;
    uint8_t code = 1;
    for (size_t i = 0; i < n; i++) {
        if (p[i] == 0) {
            out[code_at] = code;
            code_at = o++;
            code = 1;
        } else {
            out[o++] = p[i];
            code++;
        }
    }
    out[code_at] = code;
    out[o++] = 0;
    return o;
}
