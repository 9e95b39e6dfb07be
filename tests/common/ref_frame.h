/*
 * The monitor's framing written the textbook way, independent of the
 * link's own code (src/mon_link.c), for the tests and the fuzz harness
 * that judge it: CRC-16/CCITT-FALSE bit by bit, and COBS encoding
 * (docs/monitor.md).
 */
#ifndef REF_FRAME_H
#define REF_FRAME_H

#include <stddef.h>
#include <stdint.h>

/* CRC-16/CCITT-FALSE of p[0..n-1] (poly 0x1021, init 0xFFFF). */
uint16_t ref_crc(const uint8_t *p, size_t n);

/* COBS of p[0..n-1] then the delimiter, into out (room for n + n / 254 +
 * 2 bytes); returns its length. */
size_t ref_cobs(const uint8_t *p, size_t n, uint8_t *out);

#endif /* REF_FRAME_H */
