/*
 * dsPIC port: the minimal text monitor (hal/dspic33fj/dspic_monitor.c):
 * parsing, line assembly, the status line, number formatting, rpm
 * conversion.
 */
#include <limits.h>
#include <string.h>

#include "dspic_monitor.h"
#include "testkit.h"

static void expect_cmd(const char *line, dspic_mon_kind_t kind, int32_t rpm)
{
    const dspic_mon_cmd_t c = dspic_mon_parse(line);
    TK_CHECK(c.kind == kind, "'%s': kind %d, expected %d", line, (int)c.kind, (int)kind);
    if (kind == DSPIC_MON_SPEED) {
        TK_CHECK(c.rpm == rpm, "'%s': rpm %ld, expected %ld", line, (long)c.rpm, (long)rpm);
    }
}

static void case_parse(void)
{
    expect_cmd("start", DSPIC_MON_START, 0);
    expect_cmd("  stop  ", DSPIC_MON_STOP, 0);
    expect_cmd("ack", DSPIC_MON_ACK, 0);
    expect_cmd("status", DSPIC_MON_STATUS, 0);
    expect_cmd("help", DSPIC_MON_HELP, 0);
    expect_cmd("speed 1500", DSPIC_MON_SPEED, 1500);
    expect_cmd("speed   -200 ", DSPIC_MON_SPEED, -200);
    expect_cmd("speed +35", DSPIC_MON_SPEED, 35);
    expect_cmd("speed 0", DSPIC_MON_SPEED, 0);
    expect_cmd("speed 100000", DSPIC_MON_SPEED, 100000);
    expect_cmd("speed pot", DSPIC_MON_SPEED_POT, 0);
    expect_cmd("speed", DSPIC_MON_ERR_ARGUMENT, 0);
    expect_cmd("speed abc", DSPIC_MON_ERR_ARGUMENT, 0);
    expect_cmd("speed 12x", DSPIC_MON_ERR_ARGUMENT, 0);
    expect_cmd("speed -", DSPIC_MON_ERR_ARGUMENT, 0);
    expect_cmd("speed 100001", DSPIC_MON_ERR_ARGUMENT, 0);
    expect_cmd("speed 99999999999", DSPIC_MON_ERR_ARGUMENT, 0);
    expect_cmd("speed potato", DSPIC_MON_ERR_ARGUMENT, 0);
    expect_cmd("speedy", DSPIC_MON_ERR_UNKNOWN, 0);
    expect_cmd("start now", DSPIC_MON_ERR_UNKNOWN, 0);
    expect_cmd("go", DSPIC_MON_ERR_UNKNOWN, 0);
    expect_cmd("   ", DSPIC_MON_NONE, 0);
    TK_CHECK(strcmp(dspic_mon_reply(DSPIC_MON_START), "ok") == 0, "ok reply");
    TK_CHECK(strncmp(dspic_mon_reply(DSPIC_MON_ERR_UNKNOWN), "err", 3) == 0, "err reply");
    TK_CHECK(strncmp(dspic_mon_reply(DSPIC_MON_ERR_TOO_LONG), "err", 3) == 0, "err reply");
}

/* Feeds a string; returns the number of commands and the last one. */
static int feed(dspic_mon_t *m, const char *s, dspic_mon_cmd_t *last)
{
    int n = 0;
    while (*s != '\0') {
        dspic_mon_cmd_t c;
        if (dspic_mon_feed(m, *s, &c) != 0u) {
            *last = c;
            n++;
        }
        s++;
    }
    return n;
}

static void case_feed_lines(void)
{
    dspic_mon_t m;
    dspic_mon_cmd_t c = { DSPIC_MON_NONE, 0 };
    dspic_mon_init(&m);
    TK_CHECK(feed(&m, "START\r\n", &c) == 1 && c.kind == DSPIC_MON_START, "CR LF, upper case");
    TK_CHECK(feed(&m, "\r\n\n  \r", &c) == 0, "blank lines give nothing");
    TK_CHECK(feed(&m, "Speed 2500\n", &c) == 1 && c.kind == DSPIC_MON_SPEED && c.rpm == 2500,
             "speed line");
    TK_CHECK(feed(&m, "stat", &c) == 0, "no command before the line end");
    TK_CHECK(feed(&m, "us\r", &c) == 1 && c.kind == DSPIC_MON_STATUS, "split line");

    /* a line longer than the buffer is refused as a whole, then recovery */
    char longline[64];
    memset(longline, 'x', sizeof longline);
    longline[DSPIC_MON_LINE_MAX + 5u] = '\n';
    longline[DSPIC_MON_LINE_MAX + 6u] = '\0';
    TK_CHECK(feed(&m, longline, &c) == 1 && c.kind == DSPIC_MON_ERR_TOO_LONG, "too long: %d",
             (int)c.kind);
    TK_CHECK(feed(&m, "stop\n", &c) == 1 && c.kind == DSPIC_MON_STOP, "recovers");

    /* exactly DSPIC_MON_LINE_MAX characters fit */
    char fit[DSPIC_MON_LINE_MAX + 2u];
    memset(fit, ' ', sizeof fit);
    memcpy(fit, "ack", 3);
    fit[DSPIC_MON_LINE_MAX] = '\n';
    fit[DSPIC_MON_LINE_MAX + 1u] = '\0';
    TK_CHECK(feed(&m, fit, &c) == 1 && c.kind == DSPIC_MON_ACK, "full-length line: %d", (int)c.kind);
    /* one more is too long */
    char over[DSPIC_MON_LINE_MAX + 3u];
    memset(over, ' ', sizeof over);
    memcpy(over, "ack", 3);
    over[DSPIC_MON_LINE_MAX + 1u] = '\n';
    over[DSPIC_MON_LINE_MAX + 2u] = '\0';
    TK_CHECK(feed(&m, over, &c) == 1 && c.kind == DSPIC_MON_ERR_TOO_LONG, "one over: %d",
             (int)c.kind);
}

static void case_put_numbers(void)
{
    char buf[32];
    size_t len = 0;
    buf[0] = '\0';
    dspic_mon_put_int(buf, sizeof buf, &len, 0);
    dspic_mon_put_str(buf, sizeof buf, &len, " ");
    dspic_mon_put_int(buf, sizeof buf, &len, -5);
    dspic_mon_put_str(buf, sizeof buf, &len, " ");
    dspic_mon_put_int(buf, sizeof buf, &len, INT32_MIN);
    dspic_mon_put_str(buf, sizeof buf, &len, " ");
    dspic_mon_put_hex16(buf, sizeof buf, &len, 0xBEEFu);
    TK_CHECK(strcmp(buf, "0 -5 -2147483648 0xBEEF") == 0, "'%s'", buf);
    TK_CHECK(len == strlen(buf), "len %zu", len);

    /* truncation keeps the string terminated */
    char small[6];
    len = 0;
    small[0] = '\0';
    dspic_mon_put_int(small, sizeof small, &len, 123456789);
    TK_CHECK(strcmp(small, "12345") == 0 && len == 5, "'%s' %zu", small, len);
    dspic_mon_put_str(small, sizeof small, &len, "more");
    TK_CHECK(strcmp(small, "12345") == 0, "full buffer unchanged: '%s'", small);
}

static void case_status_line(void)
{
    const dspic_mon_status_t st = { "RUN", 0x0011u, "OVERCURRENT", 1498, 1500, -12, 340,
                                    24012u, 14900u, 20300u, 23700u, 1, 0 };
    char buf[160];
    const size_t n = dspic_mon_format_status(buf, sizeof buf, &st);
    const char *expect = "state=RUN faults=0x0011 first=OVERCURRENT rpm=1498 ref=1500 "
                         "id_ma=-12 iq_ma=340 vdc_mv=24012 isr_ns=14900/20300/23700 "
                         "range=fw src=uart";
    TK_CHECK(strcmp(buf, expect) == 0, "got '%s'", buf);
    TK_CHECK(n == strlen(expect), "length %zu", n);

    char tiny[10];
    const size_t m = dspic_mon_format_status(tiny, sizeof tiny, &st);
    TK_CHECK(m == 9 && strcmp(tiny, "state=RUN") == 0, "truncated '%s'", tiny);
}

static void case_rpm_conversion(void)
{
    TK_CHECK(dspic_rpm_to_q15(3000, 6000) == 16384, "half base");
    TK_CHECK(dspic_rpm_to_q15(-3000, 6000) == -16384, "minus half base");
    TK_CHECK(dspic_rpm_to_q15(6000, 6000) == 32767, "base saturates");
    TK_CHECK(dspic_rpm_to_q15(-6000, 6000) == -32768, "minus base");
    TK_CHECK(dspic_rpm_to_q15(100000, 6000) == 32767, "far above");
    TK_CHECK(dspic_rpm_to_q15(INT32_MIN, 6000) == -32768, "INT32_MIN");
    TK_CHECK(dspic_rpm_to_q15(100, 0) == 0, "bad base");
    TK_CHECK(dspic_q15_to_rpm(16384, 6000) == 3000, "back");
    TK_CHECK(dspic_q15_to_rpm(-32768, 6000) == -6000, "minus full");
    TK_CHECK(dspic_q15_to_rpm(-32768, 65535) == -65535, "largest base");
    for (int32_t rpm = -5999; rpm <= 5999; rpm++) {
        const q15_t q = dspic_rpm_to_q15(rpm, 6000);
        const double exact = (double)rpm * 32768.0 / 6000.0;
        TK_CHECK(q - exact <= 0.5 && exact - q <= 0.5, "%ld rpm -> %d (%.2f)", (long)rpm, q, exact);
        const int32_t back = dspic_q15_to_rpm(q, 6000);
        TK_CHECK(back - rpm <= 1 && rpm - back <= 1, "%ld rpm -> %d -> %ld", (long)rpm, q, (long)back);
    }
}

TK_CASES(TK_CASE(case_parse), TK_CASE(case_feed_lines), TK_CASE(case_put_numbers),
         TK_CASE(case_status_line), TK_CASE(case_rpm_conversion))
