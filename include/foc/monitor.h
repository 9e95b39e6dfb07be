/*
 * Monitor: the binary protocol a PC (tools/foc-monitor) speaks with a
 * board or with focsim, over any byte stream (docs/monitor.md, byte by
 * byte).  Frames are COBS with a CRC-16 (foc/mon_link.h); every good
 * request gets exactly one reply; a malformed frame is dropped, counted
 * (status: dropped frames) and never executed.
 *
 * Commands: identify, start, stop, ack, speed, status, the variable and
 * parameter table (info, read, write: writes range-checked, refused while
 * the motor is driven where unsafe), the scope (configure, arm, stop,
 * state, read back in chunks), commissioning (request, results).
 *
 * Use (the application's main loop, never the control interrupt):
 *
 *   foc_mon_init(&mon, &ctrl, &scope);
 *   for (;;) {
 *       while (uart_rx_ready()) foc_mon_rx(&mon, uart_getc());
 *       while (uart_tx_ready() && foc_mon_tx(&mon, &b) != 0u) uart_putc(b);
 *       mon.cpu_load_q15 = ...;    (the port's measurements, optional)
 *       mon.overruns = ...;
 *   }
 *
 * The control interrupt never waits on the monitor: commands set the
 * controller's requests (foc_cmd_*) or scope settings, and the only thing
 * in the interrupt is the scope's tick (foc/scope.h), which the fast step
 * calls.  Work per received or transmitted byte is bounded (a reply is
 * built when its request's last byte arrives: at most one chunk of
 * FOC_MON_SCOPE_CHUNK samples).
 */
#ifndef FOC_MONITOR_H
#define FOC_MONITOR_H

#include <stdint.h>
#include "foc/controller.h"
#include "foc/mon_link.h"
#include "foc/scope.h"

#define FOC_MON_PROTOCOL 1u        /* protocol version (identify) */
#define FOC_MON_FW_VERSION 0x0100u /* firmware version, major.minor (identify) */
#define FOC_MON_SCOPE_CHUNK 16u    /* samples per scope read */
#define FOC_MON_LOAD_UNKNOWN 0xFFFFu

/* Commands (request byte 0); the reply's byte 0 is the command | 0x80. */
#define FOC_MON_IDENTIFY 0x01u
#define FOC_MON_START 0x02u
#define FOC_MON_STOP 0x03u
#define FOC_MON_ACK 0x04u
#define FOC_MON_SPEED 0x05u
#define FOC_MON_STATUS 0x06u
#define FOC_MON_VAR_INFO 0x07u
#define FOC_MON_VAR_READ 0x08u
#define FOC_MON_VAR_WRITE 0x09u
#define FOC_MON_SCOPE_SET 0x10u
#define FOC_MON_SCOPE_ARM 0x11u
#define FOC_MON_SCOPE_STOP 0x12u
#define FOC_MON_SCOPE_STATE 0x13u
#define FOC_MON_SCOPE_READ 0x14u
#define FOC_MON_COMMISSION 0x20u
#define FOC_MON_COMM_RESULT 0x21u

/* Reply byte 1: the outcome. */
#define FOC_MON_OK 0u
#define FOC_MON_E_COMMAND 1u  /* unknown command */
#define FOC_MON_E_LENGTH 2u   /* wrong argument length */
#define FOC_MON_E_RANGE 3u    /* argument out of range */
#define FOC_MON_E_RUNNING 4u  /* refused while the motor is driven / not IDLE */
#define FOC_MON_E_READONLY 5u /* the entry cannot be written */
#define FOC_MON_E_BUSY 6u     /* a capture runs: stop it first */
#define FOC_MON_E_NOSCOPE 7u  /* no scope attached */
#define FOC_MON_E_NODATA 8u   /* no finished capture */

/* The table: entries 0 .. FOC_VAR_COUNT-1 are the scope's live variables
 * (foc_var_t, read-only), then the parameters from FOC_MON_PARAM_BASE:
 * FOC_MON_PARAMS with every estimator built (focsim), fewer in a firmware
 * built for one (identify says how many). */
#define FOC_MON_PARAM_BASE 64u
#define FOC_MON_PARAMS 19u

typedef struct {
    foc_link_t link;
    foc_ctrl_t *ctrl;
    foc_scope_t *scope;     /* NULL: the variable reads and scope commands */
                            /* answer FOC_MON_E_NOSCOPE */
    uint16_t cpu_load_q15;  /* [app] the control interrupt's share of the */
                            /* CPU, Q15 (32768 = 100 %); FOC_MON_LOAD_UNKNOWN */
    uint16_t overruns;      /* [app] control interrupts that overran their */
                            /* period, as the port counts them (saturating) */
} foc_mon_t;

/* `ctrl` is required, `scope` may be NULL.  Load unknown. */
void foc_mon_init(foc_mon_t *m, foc_ctrl_t *ctrl, foc_scope_t *scope);

/* One received byte; a good request is executed when its frame ends. */
void foc_mon_rx(foc_mon_t *m, uint8_t byte);

/* The next byte to transmit into *byte: 1, or 0 when there is none. */
uint8_t foc_mon_tx(foc_mon_t *m, uint8_t *byte);

#endif /* FOC_MONITOR_H */
