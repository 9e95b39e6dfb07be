/*
 * Text monitor over the serial port: one command per line, one reply line.
 *
 *   start | stop | ack        -> "ok"
 *   speed <rpm>               -> "ok" (signed mechanical rpm, clamped to
 *                                the speed base) or "err ..."
 *   status                    -> "state=RUN fault=NONE first=NONE
 *                                rpm=1498 ref=1500 vdc=24.1"
 *   isr                       -> "isr min=.. avg=.. max=.. budget=..
 *                                overruns=.. unclean=.. spurious=..
 *                                breaks=.." (CPU cycles of the control
 *                                interrupt; budget = one PWM period)
 *   isr reset                 -> "ok" (statistics restart)
 *   help                      -> the command list
 * Anything else: "err unknown command".  Lines end with CR, LF or both;
 * replies end with CR LF.  No printf: integers are formatted here.
 */
#ifndef MONITOR_H
#define MONITOR_H

#include <stddef.h>
#include <stdint.h>
#include "foc/controller.h"

#define MONITOR_LINE_MAX 40u

typedef void (*monitor_write_fn)(const char *s);

/* Figures the board collects for the replies. */
typedef struct {
    uint32_t isr_min, isr_avg, isr_max; /* CPU cycles */
    uint32_t period_cycles;
    uint32_t overruns, unclean, spurious, breaks;
} monitor_info_t;

typedef struct {
    char line[MONITOR_LINE_MAX];
    uint8_t len;
    uint8_t too_long;
} monitor_t;

typedef enum {
    MONITOR_NO_ACTION = 0,
    MONITOR_RESET_ISR_STATS
} monitor_action_t;

void monitor_init(monitor_t *m);

/* Adds a received character; returns 1 when m->line holds a complete
 * line (NUL-terminated), to be executed before the next call. */
uint8_t monitor_feed(monitor_t *m, char ch);

/* Executes one line.  c may be NULL (controller not running: clock
 * fault); status then reports state=CLOCKFAULT and commands are refused. */
monitor_action_t monitor_execute(const char *line, foc_ctrl_t *c,
                                 const monitor_info_t *info, monitor_write_fn out);

/* Decimal text of v into buf (at least 12 bytes), NUL-terminated; returns
 * the length. */
size_t monitor_format_i32(char *buf, int32_t v);

/* Parses an optionally signed decimal integer that is the whole string;
 * returns 1 and sets *v, or 0 (empty, other characters, overflow). */
uint8_t monitor_parse_i32(const char *s, int32_t *v);

/* Mechanical rpm <-> Q15 of SPEED_BASE_RPM (rpm clamped to the Q15 range). */
q15_t monitor_rpm_to_speed(int32_t rpm);
int32_t monitor_speed_to_rpm(q15_t speed);

#endif /* MONITOR_H */
