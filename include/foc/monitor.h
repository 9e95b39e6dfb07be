/*
 * Text monitor: a line protocol over a serial link (docs/monitor.md).
 *
 * The port feeds every received byte to foc_mon_feed(); a complete line is
 * executed at once and its reply written through the caller's `write`
 * callback.  Every command gets exactly one final line starting with "ok"
 * or "err"; data lines (help, vars, a scope dump) come before it.  A scope
 * dump is long, so it is written one line per foc_mon_poll() call (call it
 * from the main loop while it returns 1); any received byte other than a
 * line end aborts it.
 *
 * Context: foc_mon_feed and foc_mon_poll run in one context below the
 * control interrupts (the main loop, or a low-priority task); `write` may
 * block (polled UART) or queue into a transmit buffer.  Do not call them
 * from an interrupt if `write` blocks.  Commands only set controller
 * requests (foc_cmd_*) and scope settings, which are safe from there.
 *
 * The interrupt timing the `timing` command shows is measured by the port:
 * it calls foc_isr_timing_add() at the end of the fast-step interrupt with
 * the cycles the interrupt took (foc_port_timestamp() differences).
 *
 * No printf, no heap: numbers are formatted here, with 64-bit integers for
 * the unit conversions (monitor context only, never in an interrupt).
 */
#ifndef FOC_MONITOR_H
#define FOC_MONITOR_H

#include <stddef.h>
#include <stdint.h>
#include "foc/controller.h"
#include "foc/scope.h"

#define FOC_MON_LINE_MAX 63u  /* characters per command line */
#define FOC_MON_MAX_ARGS 7u   /* words per line, command included */
#define FOC_MON_TIMING_AVG_SHIFT 6u /* running average over ~64 periods */

/* Fast-step interrupt timing, filled by the port, read by the monitor. */
typedef struct {
    uint32_t min_cycles;
    uint32_t max_cycles;
    uint32_t avg_x64;       /* running average x 2^FOC_MON_TIMING_AVG_SHIFT */
    uint32_t count;         /* measurements since the last reset (sat.) */
    uint32_t clock_hz;      /* cycles per second of the port's time base */
    volatile uint8_t reset; /* set by the monitor; the next add restarts */
} foc_isr_timing_t;

/* Clears the statistics; `clock_hz` is the timestamp rate (0: unknown). */
void foc_isr_timing_init(foc_isr_timing_t *t, uint32_t clock_hz);

/* One measurement, from the interrupt (cycles clamped to 2^25). */
void foc_isr_timing_add(foc_isr_timing_t *t, uint32_t cycles);

typedef void (*foc_mon_write_t)(const char *s, size_t n);

typedef struct {
    foc_ctrl_t *ctrl;
    foc_scope_t *scope;        /* NULL: scope and dac answer "err" */
    foc_isr_timing_t *timing;  /* NULL: timing answers "err" */
    foc_mon_write_t write;

    char line[FOC_MON_LINE_MAX + 1u];
    uint8_t len;
    uint8_t line_error;        /* bits: too long, bad character */
    uint8_t last_cr;           /* the previous byte was CR (CR LF = one end) */

    uint8_t dump;              /* dump phase, 0 when none */
    uint16_t dump_index;       /* channel or frame being written */
    uint16_t dump_sum;         /* sum of the values written, mod 2^16 */
} foc_monitor_t;

/* `ctrl` and `write` are required; `scope` and `timing` may be NULL. */
void foc_mon_init(foc_monitor_t *m, foc_ctrl_t *ctrl, foc_scope_t *scope,
                  foc_isr_timing_t *timing, foc_mon_write_t write);

/* One received byte. */
void foc_mon_feed(foc_monitor_t *m, uint8_t byte);

/* Writes the next line of a pending scope dump; 1 while more follows. */
uint8_t foc_mon_poll(foc_monitor_t *m);

#endif /* FOC_MONITOR_H */
