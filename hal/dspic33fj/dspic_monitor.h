/*
 * Minimal text monitor over a serial line (pure logic: no UART access).
 *
 * Commands, one per line (CR, LF or CR LF), case-insensitive, at most
 * DSPIC_MON_LINE_MAX characters:
 *   start            request a start (foc_cmd_start)
 *   stop             request a stop (foc_cmd_stop)
 *   ack              acknowledge a fault (foc_cmd_ack)
 *   speed <rpm>      speed command, mechanical rpm, signed; from then on
 *                    the potentiometer is ignored
 *   speed pot        the potentiometer sets the speed again
 *   status           one status line (dspic_mon_format_status)
 *   help             the command list
 * Replies: "ok", "err <reason>", or the status line.  A fuller protocol
 * replaces this one later; the board decides what each command does.
 */
#ifndef DSPIC_MONITOR_H
#define DSPIC_MONITOR_H

#include <stddef.h>
#include <stdint.h>
#include "foc/q15.h"

#define DSPIC_MON_LINE_MAX 31u
#define DSPIC_MON_RPM_LIMIT 100000L /* |rpm| accepted by the parser */

typedef enum {
    DSPIC_MON_NONE = 0,
    DSPIC_MON_START,
    DSPIC_MON_STOP,
    DSPIC_MON_ACK,
    DSPIC_MON_SPEED,
    DSPIC_MON_SPEED_POT,
    DSPIC_MON_STATUS,
    DSPIC_MON_HELP,
    DSPIC_MON_ERR_UNKNOWN,  /* not a command */
    DSPIC_MON_ERR_ARGUMENT, /* speed without a valid number */
    DSPIC_MON_ERR_TOO_LONG  /* line longer than DSPIC_MON_LINE_MAX */
} dspic_mon_kind_t;

typedef struct {
    dspic_mon_kind_t kind;
    int32_t rpm; /* DSPIC_MON_SPEED only */
} dspic_mon_cmd_t;

typedef struct {
    char line[DSPIC_MON_LINE_MAX + 1u];
    uint8_t len;
    uint8_t overflow;
} dspic_mon_t;

void dspic_mon_init(dspic_mon_t *m);

/* Feeds one received character.  Returns 1 and fills *cmd when a
 * non-empty line has ended, 0 otherwise. */
uint8_t dspic_mon_feed(dspic_mon_t *m, char c, dspic_mon_cmd_t *cmd);

/* Parses one line (no line end). */
dspic_mon_cmd_t dspic_mon_parse(const char *line);

/* The reply to an error kind ("err unknown command"...), "ok" otherwise. */
const char *dspic_mon_reply(dspic_mon_kind_t kind);

/* The command list, one line. */
const char *dspic_mon_help(void);

/* What the status line shows. */
typedef struct {
    const char *state;       /* foc_state_name() */
    uint16_t faults;         /* active fault bits */
    const char *first_fault; /* foc_fault_name() of the first fault */
    int32_t speed_rpm;       /* estimated mechanical speed */
    int32_t ref_rpm;         /* speed command */
    int32_t id_ma;           /* measured d and q currents, mA */
    int32_t iq_ma;
    uint32_t vdc_mv;         /* bus voltage, mV */
    uint32_t isr_min_ns;     /* fast-step interrupt, min/avg/max, ns */
    uint32_t isr_avg_ns;
    uint32_t isr_max_ns;
    uint8_t fw_range;        /* 1: extended (field-weakening) speed range */
    uint8_t pot_source;      /* 1: the potentiometer sets the speed */
} dspic_mon_status_t;

/* "state=RUN faults=0x0000 first=NONE rpm=1498 ref=1500 id_ma=-12
 * iq_ma=340 vdc_mv=24012 isr_ns=14900/20300/23700 range=normal src=pot"
 * (one line, no line end)
 * into buf, truncated to size - 1 characters and always terminated.
 * Returns the length written. */
size_t dspic_mon_format_status(char *buf, size_t size, const dspic_mon_status_t *st);

/* Mechanical rpm <-> Q15 of a base speed (1..65535 rpm), saturating,
 * rounded to nearest (halves away from zero). */
q15_t dspic_rpm_to_q15(int32_t rpm, int32_t base_rpm);
int32_t dspic_q15_to_rpm(q15_t q, int32_t base_rpm);

/* Appends text / a signed decimal / "0x" and 4 hex digits at buf[*len],
 * never past size - 1, keeping buf terminated. */
void dspic_mon_put_str(char *buf, size_t size, size_t *len, const char *s);
void dspic_mon_put_int(char *buf, size_t size, size_t *len, int32_t v);
void dspic_mon_put_hex16(char *buf, size_t size, size_t *len, uint16_t v);

#endif /* DSPIC_MONITOR_H */
