/*
 * STM3210B-MCKIT serial monitor (boards/stm3210b_mckit/monitor.c) on the
 * host: line assembly, parsing, number formatting, and the replies and
 * requests of each command against a controller structure.
 */
#include <stdint.h>
#include <string.h>

#include "foc/config.h"
#include "foc/controller.h"
#include "monitor.h"
#include "testkit.h"

/* The controller library refers to the port; the monitor never runs it. */
void foc_port_read_samples(foc_samples_t *s) { (void)s; }
void foc_port_set_duties(const foc_duty_t *d) { (void)d; }
void foc_port_pwm_enable(void) {}
void foc_port_pwm_disable(void) {}
void foc_port_low_sides_on(void) {}
void foc_port_brake_resistor(uint8_t on) { (void)on; }
uint8_t foc_port_overcurrent_latched(void) { return 0; }
void foc_port_overcurrent_clear(void) {}
void foc_port_debug_out(q15_t a, q15_t b) { (void)a; (void)b; }
uint32_t foc_port_timestamp(void) { return 0; }

static char out[256];

static void capture(const char *s)
{
    strncat(out, s, sizeof out - strlen(out) - 1);
}

static monitor_action_t run(const char *line, foc_ctrl_t *c)
{
    static const monitor_info_t info = { 1200, 1500, 2100, 4500, 3, 7, 1, 2 };
    out[0] = '\0';
    return monitor_execute(line, c, &info, capture);
}

static void case_format(void)
{
    char b[12];
    struct { int32_t v; const char *s; } t[] = {
        { 0, "0" }, { 7, "7" }, { -7, "-7" }, { 1500, "1500" },
        { INT32_MAX, "2147483647" }, { INT32_MIN, "-2147483648" },
    };
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
        const size_t n = monitor_format_i32(b, t[i].v);
        TK_CHECK(strcmp(b, t[i].s) == 0 && n == strlen(t[i].s), "%d -> '%s'", (int)t[i].v, b);
    }
}

static void case_parse(void)
{
    int32_t v = 99;
    TK_CHECK(monitor_parse_i32("1500", &v) && v == 1500, "1500");
    TK_CHECK(monitor_parse_i32("-250", &v) && v == -250, "-250");
    TK_CHECK(monitor_parse_i32("+3", &v) && v == 3, "+3");
    TK_CHECK(monitor_parse_i32("2147483647", &v) && v == INT32_MAX, "max");
    TK_CHECK(monitor_parse_i32("-2147483648", &v) && v == INT32_MIN, "min");
    v = 99;
    TK_CHECK(!monitor_parse_i32("2147483648", &v) && v == 99, "overflow");
    TK_CHECK(!monitor_parse_i32("-2147483649", &v), "underflow");
    TK_CHECK(!monitor_parse_i32("99999999999", &v), "long overflow");
    TK_CHECK(!monitor_parse_i32("", &v), "empty");
    TK_CHECK(!monitor_parse_i32("-", &v), "sign only");
    TK_CHECK(!monitor_parse_i32("12a", &v), "trailing letter");
    TK_CHECK(!monitor_parse_i32("1 2", &v), "space");
}

static void case_feed_lines(void)
{
    monitor_t m;
    monitor_init(&m);
    const char *in = "stop\r\n\nspeed 10\r";
    int lines = 0;
    char got[2][MONITOR_LINE_MAX];
    for (const char *p = in; *p; p++) {
        if (monitor_feed(&m, *p)) {
            if (lines < 2) {
                strcpy(got[lines], m.line);
            }
            lines++;
        }
    }
    TK_CHECK(lines == 2, "%d lines (empty lines are skipped)", lines);
    TK_CHECK(lines >= 2 && strcmp(got[0], "stop") == 0 && strcmp(got[1], "speed 10") == 0,
             "lines");
    /* A line longer than the buffer is dropped whole: it runs as empty. */
    for (int i = 0; i < 100; i++) {
        TK_CHECK(!monitor_feed(&m, 'x'), "no line yet");
    }
    TK_CHECK(monitor_feed(&m, '\n') && m.line[0] == '\0', "long line dropped");
    TK_CHECK(!monitor_feed(&m, 'a') && monitor_feed(&m, '\r') && strcmp(m.line, "a") == 0,
             "next line fine");
}

static void case_commands(void)
{
    static foc_ctrl_t c;
    memset(&c, 0, sizeof c);
    c.state = FOC_STATE_IDLE;

    TK_CHECK(run("start", &c) == MONITOR_NO_ACTION && strcmp(out, "ok\r\n") == 0 &&
                 c.req.start == 1,
             "start: '%s'", out);
    run("  stop  ", &c);
    TK_CHECK(strcmp(out, "ok\r\n") == 0 && c.req.stop == 1, "stop: '%s'", out);
    run("ack", &c);
    TK_CHECK(strcmp(out, "ok\r\n") == 0 && c.req.ack == 1, "ack");
    run("speed 1500", &c);
    TK_CHECK(strcmp(out, "ok\r\n") == 0 && c.req.speed == monitor_rpm_to_speed(1500),
             "speed: '%s' %d", out, c.req.speed);
    run("speed -700", &c);
    TK_CHECK(c.req.speed == monitor_rpm_to_speed(-700) && c.req.speed < 0, "negative speed");
    const q15_t before = c.req.speed;
    run("speed", &c);
    TK_CHECK(strcmp(out, "err speed <rpm>\r\n") == 0 && c.req.speed == before, "no argument");
    run("speed 12x", &c);
    TK_CHECK(strncmp(out, "err", 3) == 0 && c.req.speed == before, "bad number");
    run("speed 1 2", &c);
    TK_CHECK(strncmp(out, "err", 3) == 0 && c.req.speed == before, "extra argument");
    run("start now", &c);
    TK_CHECK(strcmp(out, "err unknown command\r\n") == 0, "argument to start: '%s'", out);
    run("reboot", &c);
    TK_CHECK(strcmp(out, "err unknown command\r\n") == 0, "unknown");
    run("help", &c);
    TK_CHECK(strstr(out, "speed <rpm>") != NULL, "help: '%s'", out);
}

static void case_status_line(void)
{
    static foc_ctrl_t c;
    memset(&c, 0, sizeof c);
    c.state = FOC_STATE_RUN;
    c.est.speed = monitor_rpm_to_speed(1498);
    c.req.speed = monitor_rpm_to_speed(1500);
    c.samples.vdc = FOC_VDC_Q15(24.0);
    run("status", &c);
    char expect[128];
    const int32_t rpm = monitor_speed_to_rpm(c.est.speed);
    const int32_t ref = monitor_speed_to_rpm(c.req.speed);
    snprintf(expect, sizeof expect,
             "state=RUN fault=NONE first=NONE rpm=%d ref=%d vdc=", (int)rpm, (int)ref);
    TK_CHECK(strncmp(out, expect, strlen(expect)) == 0, "'%s' vs '%s'", out, expect);
    TK_CHECK(rpm >= 1497 && rpm <= 1498 && ref >= 1499 && ref <= 1500, "rpm %d ref %d",
             (int)rpm, (int)ref);
    TK_CHECK(strstr(out, "vdc=24.0\r\n") != NULL || strstr(out, "vdc=23.9\r\n") != NULL,
             "bus: '%s'", out);

    c.state = FOC_STATE_FAULT;
    c.faults.active = FOC_FAULT_OVERCURRENT | FOC_FAULT_OVERVOLTAGE;
    c.faults.first = FOC_FAULT_OVERVOLTAGE;
    run("status", &c);
    TK_CHECK(strstr(out, "state=FAULT") != NULL && strstr(out, "first=OVERVOLTAGE") != NULL,
             "fault: '%s'", out);
}

static void case_isr_and_clock_fault(void)
{
    static foc_ctrl_t c;
    memset(&c, 0, sizeof c);
    run("isr", &c);
    TK_CHECK(strcmp(out, "isr min=1200 avg=1500 max=2100 budget=4500 overruns=3 "
                         "unclean=7 spurious=1 breaks=2\r\n") == 0,
             "isr: '%s'", out);
    TK_CHECK(run("isr reset", &c) == MONITOR_RESET_ISR_STATS && strcmp(out, "ok\r\n") == 0,
             "isr reset");
    TK_CHECK(run("isr foo", &c) == MONITOR_NO_ACTION && strncmp(out, "err", 3) == 0,
             "isr foo");

    /* Clock fault: no controller; status says so, commands are refused. */
    run("status", NULL);
    TK_CHECK(strcmp(out, "state=CLOCKFAULT\r\n") == 0, "clock fault status: '%s'", out);
    run("start", NULL);
    TK_CHECK(strncmp(out, "err clock fault", 15) == 0, "start refused: '%s'", out);
}

static void case_rpm_conversion(void)
{
    const int32_t base = (int32_t)(SPEED_BASE_RPM + 0.5);
    TK_CHECK(monitor_rpm_to_speed(0) == 0, "0");
    TK_CHECK(monitor_rpm_to_speed(base) == 32767, "base saturates to 32767");
    TK_CHECK(monitor_rpm_to_speed(-base) == -32768, "-base");
    TK_CHECK(monitor_rpm_to_speed(10 * base) == 32767 &&
                 monitor_rpm_to_speed(-10 * base) == -32768,
             "clamped");
    for (int32_t rpm = -base + 1; rpm < base; rpm += 37) {
        const int32_t back = monitor_speed_to_rpm(monitor_rpm_to_speed(rpm));
        TK_CHECK(back - rpm <= 1 && rpm - back <= 1, "%d -> %d", (int)rpm, (int)back);
        if (back - rpm > 1 || rpm - back > 1) {
            break;
        }
    }
}

TK_CASES(TK_CASE(case_format), TK_CASE(case_parse), TK_CASE(case_feed_lines),
         TK_CASE(case_commands), TK_CASE(case_status_line),
         TK_CASE(case_isr_and_clock_fault), TK_CASE(case_rpm_conversion))
