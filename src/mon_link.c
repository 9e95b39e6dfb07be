/* Monitor link: COBS framing and CRC-16; see mon_link.h. */
#include "foc/mon_link.h"

#define RX_IDLE 0u   /* between frames */
#define RX_FRAME 1u  /* receiving a frame */
#define RX_BAD 2u    /* the frame is already broken: dropped at its end */

#define TX_IDLE 0u
#define TX_LEAD 4u   /* the leading zero next */
#define TX_CODE 1u   /* a COBS code byte next */
#define TX_DATA 2u   /* data bytes of the block next */
#define TX_END 3u    /* the zero delimiter next */

void foc_link_init(foc_link_t *l)
{
    l->rx_len = 0u;
    l->rx_left = 0u;
    l->rx_zero = 0u;
    l->rx_state = RX_IDLE;
    l->tx_len = 0u;
    l->tx_pos = 0u;
    l->tx_left = 0u;
    l->tx_state = TX_IDLE;
    l->dropped = 0u;
}

uint16_t foc_crc16(const uint8_t *p, uint8_t n)
{
    uint16_t crc = 0xFFFFu;
    for (uint8_t i = 0u; i < n; i++) {
        crc ^= (uint16_t)((uint16_t)p[i] << 8u);
        for (uint8_t b = 0u; b < 8u; b++) {
            if ((crc & 0x8000u) != 0u) {
                crc = (uint16_t)((uint16_t)(crc << 1u) ^ 0x1021u);
            } else {
                crc = (uint16_t)(crc << 1u);
            }
        }
    }
    return crc;
}

static void count_dropped(foc_link_t *l)
{
    if (l->dropped < 0xFFFFu) {
        l->dropped++;
    }
}

static void rx_put(foc_link_t *l, uint8_t byte)
{
    if (l->rx_len < FOC_LINK_RX_MAX) {
        l->rx[l->rx_len] = byte;
        l->rx_len++;
    } else {
        l->rx_state = RX_BAD;
    }
}

/* The frame just ended: its payload length if it is good, else 0. */
static uint8_t rx_end(foc_link_t *l)
{
    uint8_t n = 0u;
    if (l->rx_state == RX_FRAME && l->rx_left == 0u && l->rx_len >= 3u &&
        foc_link_tx_busy(l) == 0u) {
        const uint8_t len = (uint8_t)(l->rx_len - 2u);
        const uint16_t crc = (uint16_t)((uint16_t)l->rx[len] |
                                        (uint16_t)((uint16_t)l->rx[len + 1u] << 8u));
        if (crc == foc_crc16(l->rx, len)) {
            n = len;
        }
    }
    if (n == 0u && l->rx_state != RX_IDLE) {
        count_dropped(l);
    }
    l->rx_len = 0u;
    l->rx_left = 0u;
    l->rx_zero = 0u;
    l->rx_state = RX_IDLE;
    return n;
}

uint8_t foc_link_rx(foc_link_t *l, uint8_t byte)
{
    uint8_t n = 0u;
    if (byte == 0u) {
        n = rx_end(l);
    } else if (l->rx_left == 0u) {
        /* a code byte: the previous block's implied zero, then a block of
         * byte - 1 data bytes */
        if (l->rx_zero != 0u) {
            rx_put(l, 0u);
        }
        if (l->rx_state == RX_IDLE) {
            l->rx_state = RX_FRAME;
        }
        l->rx_left = (uint8_t)(byte - 1u);
        l->rx_zero = (uint8_t)((byte != 0xFFu) ? 1u : 0u);
    } else {
        rx_put(l, byte);
        l->rx_left--;
    }
    return n;
}

void foc_link_send(foc_link_t *l, uint8_t n)
{
    const uint16_t crc = foc_crc16(l->tx, n);
    l->tx[n] = (uint8_t)(crc & 0xFFu);
    l->tx[n + 1u] = (uint8_t)(crc >> 8u);
    l->tx_len = (uint8_t)(n + 2u);
    l->tx_pos = 0u;
    l->tx_left = 0u;
    l->tx_state = TX_LEAD;
}

uint8_t foc_link_tx_busy(const foc_link_t *l)
{
    return (uint8_t)((l->tx_state != TX_IDLE) ? 1u : 0u);
}

uint8_t foc_link_tx(foc_link_t *l, uint8_t *byte)
{
    uint8_t got = 1u;
    if (l->tx_state == TX_LEAD) {
        *byte = 0u;
        l->tx_state = TX_CODE;
    } else if (l->tx_state == TX_CODE) {
        /* the block runs to the next zero or to the end of the reply */
        uint8_t k = l->tx_pos;
        while (k < l->tx_len && l->tx[k] != 0u) {
            k++;
        }
        l->tx_left = (uint8_t)(k - l->tx_pos);
        *byte = (uint8_t)(l->tx_left + 1u);
        l->tx_state = (l->tx_left != 0u) ? TX_DATA : TX_CODE;
        if (l->tx_left == 0u) {
            /* an empty block: it stands for a zero, or ends the frame */
            l->tx_state = (k < l->tx_len) ? TX_CODE : TX_END;
            l->tx_pos = (uint8_t)(k + 1u);
        }
    } else if (l->tx_state == TX_DATA) {
        *byte = l->tx[l->tx_pos];
        l->tx_pos++;
        l->tx_left--;
        if (l->tx_left == 0u) {
            if (l->tx_pos < l->tx_len) {
                l->tx_pos++; /* the zero this block's code stands for */
                l->tx_state = TX_CODE;
            } else {
                l->tx_state = TX_END;
            }
        }
    } else if (l->tx_state == TX_END) {
        *byte = 0u;
        l->tx_state = TX_IDLE;
    } else {
        got = 0u;
    }
    return got;
}
