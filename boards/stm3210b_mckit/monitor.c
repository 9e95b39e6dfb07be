#include "monitor.h"

#include "foc/config.h"
#include "foc/faults.h"

#define REPLY_MAX 128u
/* The replies are not time-critical: keep their helpers out of line
 * (at -O2 GCC would copy them into every caller). */
#define OUT_OF_LINE __attribute__((noinline))
#define SPEED_BASE ((int32_t)(SPEED_BASE_RPM + 0.5))
/* Bus reading (Q15 of the full scale) to tenths of a volt: x K / 2^16. */
#define VDC_DECIVOLT_K ((int32_t)(BOARD_VDC_FULL_SCALE_V * 20.0 + 0.5))

FOC_STATIC_ASSERT(SPEED_BASE_RPM < 65535.0, "monitor: SPEED_BASE_RPM too large");
FOC_STATIC_ASSERT(BOARD_VDC_FULL_SCALE_V < 3000.0, "monitor: bus scale too large");

void monitor_init(monitor_t *m)
{
    m->len = 0;
    m->too_long = 0;
    m->line[0] = '\0';
}

uint8_t monitor_feed(monitor_t *m, char ch)
{
    if (ch == '\r' || ch == '\n') {
        const uint8_t complete = (uint8_t)(m->len > 0u || m->too_long);
        m->line[(m->too_long != 0u) ? 0u : m->len] = '\0';
        m->len = 0;
        m->too_long = 0;
        return complete;
    }
    if (m->len + 1u >= MONITOR_LINE_MAX) {
        m->too_long = 1; /* the line is dropped: executes as empty */
        return 0;
    }
    m->line[m->len++] = ch;
    return 0;
}

OUT_OF_LINE size_t monitor_format_i32(char *buf, int32_t v)
{
    char tmp[11];
    size_t n = 0;
    size_t len = 0;
    /* Work on the magnitude as unsigned: INT32_MIN has no positive int32. */
    uint32_t u = (v < 0) ? (uint32_t)0u - (uint32_t)v : (uint32_t)v;
    do {
        tmp[n++] = (char)('0' + (uint8_t)(u % 10u));
        u /= 10u;
    } while (u != 0u);
    if (v < 0) {
        buf[len++] = '-';
    }
    while (n > 0u) {
        buf[len++] = tmp[--n];
    }
    buf[len] = '\0';
    return len;
}

uint8_t monitor_parse_i32(const char *s, int32_t *v)
{
    uint8_t negative = 0;
    uint32_t u = 0;
    if (*s == '+' || *s == '-') {
        negative = (uint8_t)(*s == '-');
        s++;
    }
    if (*s == '\0') {
        return 0;
    }
    for (; *s != '\0'; s++) {
        if (*s < '0' || *s > '9') {
            return 0;
        }
        const uint32_t digit = (uint32_t)(*s - '0');
        if (u > (2147483648u - digit) / 10u) {
            return 0;
        }
        u = u * 10u + digit;
    }
    if (!negative && u > 2147483647u) {
        return 0;
    }
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    *v = negative ? (int32_t)(0u - u) : (int32_t)u;
    return 1;
}

q15_t monitor_rpm_to_speed(int32_t rpm)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    if (rpm > SPEED_BASE) {
        /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
        rpm = SPEED_BASE;
    }
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    if (rpm < -SPEED_BASE) {
        /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
        rpm = -SPEED_BASE;
    }
    /* |rpm| x 32768 <= 65535 x 32768 < 2^31. */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    return foc_sat_q15(rpm * 32768 / SPEED_BASE);
}

int32_t monitor_speed_to_rpm(q15_t speed)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    return (int32_t)speed * SPEED_BASE / 32768;
}

/* ------------------------------------------------------------ replies -- */
typedef struct {
    char buf[REPLY_MAX];
    size_t len;
} reply_t;

OUT_OF_LINE static void put(reply_t *r, const char *s)
{
    while (*s != '\0' && r->len + 1u < REPLY_MAX) {
        r->buf[r->len++] = *s++;
    }
    r->buf[r->len] = '\0';
}

/* key, then the value; with `tenths` as "12.3". */
OUT_OF_LINE static void put_value(reply_t *r, const char *key, int32_t v, uint8_t tenths)
{
    char num[12];
    put(r, key);
    if (tenths != 0u) {
        const uint32_t mag = (v < 0) ? (uint32_t)0u - (uint32_t)v : (uint32_t)v;
        if (v < 0) {
            put(r, "-");
        }
        /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
        (void)monitor_format_i32(num, (int32_t)(mag / 10u));
        put(r, num);
        num[0] = '.';
        num[1] = (char)('0' + (uint8_t)(mag % 10u));
        num[2] = '\0';
    } else {
        (void)monitor_format_i32(num, v);
    }
    put(r, num);
}

OUT_OF_LINE static void status(reply_t *r, const foc_ctrl_t *c)
{
    if (c == NULL) {
        put(r, "state=CLOCKFAULT");
        return;
    }
    put(r, "state=");
    put(r, foc_state_name(c->state));
    put(r, " fault=");
    put(r, foc_fault_name(c->faults.active));
    put(r, " first=");
    put(r, foc_fault_name(c->faults.first));
    put_value(r, " rpm=", monitor_speed_to_rpm(c->est.speed), 0);
    put_value(r, " ref=", monitor_speed_to_rpm(c->req.speed), 0);
    /* cppcheck-suppress [misra-c2012-10.1, misra-c2012-10.8] ; D1 Q-format shift, D2 compile-time constant */
    put_value(r, " vdc=", ((int32_t)c->samples.vdc * VDC_DECIVOLT_K) >> 16, 1);
}

OUT_OF_LINE static void isr(reply_t *r, const monitor_info_t *info)
{
    static const char *const keys[] = {
        "isr min=", " avg=", " max=", " budget=",
        " overruns=", " unclean=", " spurious=", " breaks=",
    };
    const uint32_t values[] = {
        info->isr_min, info->isr_avg, info->isr_max, info->period_cycles,
        info->overruns, info->unclean, info->spurious, info->breaks,
    };
    for (size_t i = 0; i < sizeof values / sizeof values[0]; i++) {
        const uint32_t v = values[i];
        put_value(r, keys[i], (v > 2147483647u) ? 2147483647 : (int32_t)v, 0);
    }
}

/* Splits a line into up to three words (the rest is ignored); returns the
 * number found.  Words are as long as the line at most. */
static size_t split(const char *line, char words[3][MONITOR_LINE_MAX])
{
    size_t n = 0;
    for (size_t w = 0; w < 3u; w++) {
        size_t len = 0;
        while (*line == ' ' || *line == '\t') {
            line++;
        }
        while (*line != '\0' && *line != ' ' && *line != '\t' &&
               len + 1u < MONITOR_LINE_MAX) {
            words[w][len++] = *line++;
        }
        words[w][len] = '\0';
        if (len > 0u) {
            n = w + 1u;
        }
    }
    return n;
}

/* String equality (newlib's strcmp is ten times this size). */
static uint8_t same(const char *a, const char *b)
{
    while (*a != '\0' && *a == *b) {
        a++;
        b++;
    }
    return (uint8_t)(*a == *b);
}

typedef enum { CMD_START, CMD_STOP, CMD_ACK, CMD_SPEED, CMD_STATUS, CMD_ISR, CMD_HELP,
               CMD_COUNT } command_t;

static const char *const command_names[CMD_COUNT] = {
    "start", "stop", "ack", "speed", "status", "isr", "help",
};

monitor_action_t monitor_execute(const char *line, foc_ctrl_t *c,
                                 const monitor_info_t *info, monitor_write_fn out)
{
    reply_t r;
    char words[3][MONITOR_LINE_MAX];
    monitor_action_t action = MONITOR_NO_ACTION;
    const size_t n = split(line, words);
    unsigned cmd = 0;
    while (cmd < (unsigned)CMD_COUNT && !same(words[0], command_names[cmd])) {
        cmd++;
    }
    /* Commands that act on the motor need it; all but speed and isr take
     * no argument. */
    uint8_t args_ok = (uint8_t)(n == 1u);
    if (cmd == (unsigned)CMD_SPEED) {
        args_ok = (uint8_t)(n == 2u);
    } else if (cmd == (unsigned)CMD_ISR) {
        args_ok = (uint8_t)(n <= 2u);
    } else {
        /* no argument */
    }
    r.len = 0;
    r.buf[0] = '\0';
    if (cmd == (unsigned)CMD_COUNT || !args_ok) {
        put(&r, cmd == (unsigned)CMD_SPEED ? "err speed <rpm>" : "err unknown command");
    } else if (c == NULL && cmd <= (unsigned)CMD_SPEED) {
        put(&r, "err clock fault: motor disabled");
    } else {
        const char *reply = "ok";
        int32_t rpm = 0;
        switch ((command_t)cmd) {
        case CMD_START:
            foc_cmd_start(c);
            break;
        case CMD_STOP:
            foc_cmd_stop(c);
            break;
        case CMD_ACK:
            foc_cmd_ack(c);
            break;
        case CMD_SPEED:
            if (monitor_parse_i32(words[1], &rpm) != 0u) {
                foc_cmd_speed(c, monitor_rpm_to_speed(rpm));
            } else {
                reply = "err speed <rpm>";
            }
            break;
        case CMD_STATUS:
            status(&r, c);
            reply = "";
            break;
        case CMD_ISR:
            if (n == 1u) {
                isr(&r, info);
                reply = "";
            } else if (same(words[1], "reset") != 0u) {
                action = MONITOR_RESET_ISR_STATS;
            } else {
                reply = "err unknown command";
            }
            break;
        default:
            reply = "start stop ack speed <rpm> status isr [reset] help";
            break;
        }
        put(&r, reply);
    }
    put(&r, "\r\n");
    out(r.buf);
    return action;
}
