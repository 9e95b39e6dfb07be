/*
 * Monitor link: the framing of the monitor's binary protocol over any byte
 * stream (docs/monitor.md, "Framing").
 *
 * A frame is a payload followed by its CRC-16 (CRC-16/CCITT-FALSE:
 * polynomial 0x1021, initial value 0xFFFF, no reflection, no final XOR;
 * low byte first), COBS-encoded (no zero byte inside) and ended by one
 * zero byte.  Received bytes are decoded as they arrive into `rx`; a frame
 * whose COBS is broken, that overflows `rx`, that is shorter than a
 * command byte and its CRC, or whose CRC is wrong is dropped and counted
 * in `dropped`, never handed on.  Empty frames (a zero byte after a zero
 * byte) are ignored: a sender may start with a zero to resynchronise.
 *
 * A reply is built in `tx` by the caller, then foc_link_send() appends its
 * CRC and foc_link_tx() hands out a zero (ending whatever text the board
 * printed before, a banner) and the encoded bytes one by one (encoding on
 * the fly: no second buffer).  While a reply is being sent, a request
 * that completes is dropped and counted (the host waits for each reply).
 *
 * Context: the application's main loop (or one low-priority task); never
 * the control interrupt.  No blocking, bounded work per byte (the COBS
 * encoder scans at most FOC_LINK_TX_MAX bytes for the next zero).
 */
#ifndef FOC_MON_LINK_H
#define FOC_MON_LINK_H

#include <stdint.h>

#define FOC_LINK_RX_MAX 20u /* decoded request bytes, CRC included */
#define FOC_LINK_TX_MAX 48u /* reply bytes, CRC included (< 254: one COBS block) */

typedef struct {
    uint8_t rx[FOC_LINK_RX_MAX];
    uint8_t tx[FOC_LINK_TX_MAX];
    uint8_t rx_len;     /* decoded bytes of the frame so far */
    uint8_t rx_left;    /* data bytes left in the COBS block; 0: a code next */
    uint8_t rx_zero;    /* 1: the present block ends with an implied zero */
    uint8_t rx_state;   /* FOC_LINK_RX_*: idle, in a frame, frame is bad */
    uint8_t tx_len;     /* reply bytes, CRC included */
    uint8_t tx_pos;     /* next reply byte to encode */
    uint8_t tx_left;    /* data bytes left in the COBS block being sent */
    uint8_t tx_state;   /* idle, leading zero, code next, data, delimiter */
    uint16_t dropped;   /* frames dropped (saturates at 65535) */
} foc_link_t;

void foc_link_init(foc_link_t *l);

/* CRC-16/CCITT-FALSE of n bytes (check value: "123456789" -> 0x29B1). */
uint16_t foc_crc16(const uint8_t *p, uint8_t n);

/* One received byte.  Returns the payload length (CRC removed, >= 1) when
 * it ends a good frame, whose payload is then rx[0 .. length-1]; else 0. */
uint8_t foc_link_rx(foc_link_t *l, uint8_t byte);

/* Sends tx[0 .. n-1] as a frame (n <= FOC_LINK_TX_MAX - 2): appends the
 * CRC and starts the encoder. */
void foc_link_send(foc_link_t *l, uint8_t n);

/* 1 while a reply is being sent. */
uint8_t foc_link_tx_busy(const foc_link_t *l);

/* The next byte to transmit into *byte: 1, or 0 when there is none. */
uint8_t foc_link_tx(foc_link_t *l, uint8_t *byte);

#endif /* FOC_MON_LINK_H */
