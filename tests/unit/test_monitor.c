/*
 * Text monitor (foc/monitor.h) against a controller at rest: every
 * command's effect and reply, the errors, line handling (CR/LF/CR LF, case,
 * tabs, backspace, overlong lines, bad bytes, garbage), a scope capture read
 * out through the dump, and a dump aborted by a received byte.
 *
 * The port is stubbed here (the controller needs one to link); replies are
 * collected from the write callback.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "foc/config.h"
#include "foc/monitor.h"
#include "testkit.h"

/* ------------------------------------------------------- port stubs -- */
void foc_port_read_samples(foc_samples_t *s) { (void)s; }
void foc_port_set_duties(const foc_duty_t *d) { (void)d; }
void foc_port_pwm_enable(void) {}
void foc_port_pwm_disable(void) {}
void foc_port_low_sides_on(void) {}
void foc_port_brake_resistor(uint8_t on) { (void)on; }
uint8_t foc_port_overcurrent_latched(void) { return 0; }
void foc_port_overcurrent_clear(void) {}
void foc_port_debug_out(q15_t ch1, q15_t ch2) { (void)ch1; (void)ch2; }
uint32_t foc_port_timestamp(void) { return 0; }

/* ------------------------------------------------------------ set-up -- */
static char out[1 << 16];
static size_t out_len;
static unsigned write_calls;

static void collect(const char *s, size_t n)
{
    write_calls++;
    if (out_len + n < sizeof out) {
        memcpy(out + out_len, s, n);
        out_len += n;
        out[out_len] = '\0';
    }
}

static foc_ctrl_t ctrl;
static foc_scope_t scope;
static int16_t buf[40];
static foc_isr_timing_t timing;
static foc_monitor_t mon;

static void setup(void)
{
    foc_init(&ctrl);
    foc_scope_init(&scope, &ctrl, buf, (uint16_t)(sizeof buf / sizeof buf[0]));
    foc_isr_timing_init(&timing, 1000000u);
    foc_mon_init(&mon, &ctrl, &scope, &timing, collect);
    out_len = 0;
    out[0] = '\0';
}

static void feed(const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        foc_mon_feed(&mon, (uint8_t)s[i]);
    }
}

/* Sends `line` with CR LF, writes out any dump, returns everything sent. */
static const char *cmd(const char *line)
{
    out_len = 0;
    out[0] = '\0';
    feed(line, strlen(line));
    feed("\r\n", 2);
    while (foc_mon_poll(&mon) != 0u) {
    }
    return out;
}

/* x with `decimals` places, trailing zeros and point dropped: the
 * monitor's format for full scales and sample intervals. */
static const char *trimmed(double x, int decimals)
{
    static char s[4][48];
    static int next;
    char *r = s[next++ % 4];
    snprintf(r, sizeof s[0], "%.*f", decimals, x);
    char *e = r + strlen(r) - 1;
    while (strchr(r, '.') != NULL && (*e == '0' || *e == '.')) {
        *e-- = '\0';
    }
    return r;
}

/* The sample interval of decimation d, as the monitor prints it. */
static const char *dt_text(unsigned d)
{
    const double period_ps = floor(1e12 / PWM_FREQUENCY_HZ + 0.5);
    return trimmed(period_ps * d * 1e-12, 12);
}

static int starts(const char *s, const char *prefix)
{
    return strncmp(s, prefix, strlen(prefix)) == 0;
}

/* The reply is exactly `want` + CR LF. */
#define CHECK_REPLY(line, want)                                                \
    do {                                                                       \
        const char *r_ = cmd(line);                                            \
        TK_CHECK(strcmp(r_, want "\r\n") == 0, "'%s' -> '%s', want '%s'",      \
                 line, r_, want);                                              \
    } while (0)

/* -------------------------------------------------------------- cases -- */

static void case_start_stop_ack(void)
{
    setup();
    CHECK_REPLY("start", "ok");
    TK_CHECK(ctrl.req.start == 1u, "start requested");
    CHECK_REPLY("stop", "ok");
    TK_CHECK(ctrl.req.stop == 1u, "stop requested");
    CHECK_REPLY("ack", "ok");
    TK_CHECK(ctrl.req.ack == 1u, "ack requested");
    CHECK_REPLY("start now", "err too many arguments");
}

static void case_speed(void)
{
    setup();
    CHECK_REPLY("speed 1500", "ok");
    TK_CHECK(ctrl.req.speed == (q15_t)lround(1500.0 * 32768.0 / SPEED_BASE_RPM), "1500 rpm: %d",
             ctrl.req.speed);
    CHECK_REPLY("speed -750.5", "ok");
    TK_CHECK(ctrl.req.speed == (q15_t)lround(-750.5 * 32768.0 / SPEED_BASE_RPM), "-750.5: %d",
             ctrl.req.speed);
    CHECK_REPLY("speed +0.001", "ok");
    TK_CHECK(ctrl.req.speed == 0, "tiny rounds to 0");
    const q15_t kept = ctrl.req.speed;
    CHECK_REPLY("speed 1.2345", "err bad number: 1.2345");
    CHECK_REPLY("speed 123456", "err bad number: 123456");
    CHECK_REPLY("speed 12x", "err bad number: 12x");
    CHECK_REPLY("speed -", "err bad number: -");
    CHECK_REPLY("speed .", "err bad number: .");
    CHECK_REPLY("speed 1e3", "err bad number: 1e3");
    char line[64], want[80];
    snprintf(line, sizeof line, "speed %.0f", SPEED_BASE_RPM * 1.5);
    snprintf(want, sizeof want, "err out of range: %.0f\r\n", SPEED_BASE_RPM * 1.5);
    TK_CHECK(strcmp(cmd(line), want) == 0, "%s -> %s", line, out);
    CHECK_REPLY("speed", "err missing argument: speed <rpm>");
    CHECK_REPLY("speed 1 2", "err too many arguments");
    TK_CHECK(ctrl.req.speed == kept, "errors leave the command alone");
}

static void case_status(void)
{
    setup();
    ctrl.req.speed = 8192;
    ctrl.speed_ctrl.ramped = 4096;
    ctrl.est.speed = -100;
    ctrl.est.est_speed = 5000;
    ctrl.i_dq.d = 300;
    ctrl.i_dq.q = -1000;
    ctrl.samples.vdc = 14894;
    ctrl.faults.active = 0x0012u;
    ctrl.faults.first = (uint16_t)FOC_FAULT_OVERVOLTAGE;
    ctrl.state = FOC_STATE_FAULT;
    const char *r = cmd("status");
    char want[400];
    snprintf(want, sizeof want,
             "ok state=FAULT fault=%s faults=0x0012 est=%s speed_cmd_rpm=%.1f "
             "speed_ref_rpm=%.1f speed_rpm=%.1f speed_est_rpm=%.1f id_a=%.3f iq_a=%.3f "
             "vdc_v=%.2f\r\n",
             foc_fault_name(FOC_FAULT_OVERVOLTAGE), foc_est_name(ctrl.est.kind),
             8192 * SPEED_BASE_RPM / 32768, 4096 * SPEED_BASE_RPM / 32768,
             -100 * SPEED_BASE_RPM / 32768, 5000 * SPEED_BASE_RPM / 32768,
             300 * FOC_I_BASE_A / 32768, -1000 * FOC_I_BASE_A / 32768,
             14894 * FOC_VDC_BASE_V / 32768);
    TK_CHECK(strcmp(r, want) == 0, "status\n got: %s\nwant: %s", r, want);
    /* during start-up the reference is the forced speed */
    ctrl.state = FOC_STATE_OPENLOOP;
    ctrl.startup.speed = 2048;
    char ref[64];
    snprintf(ref, sizeof ref, " speed_ref_rpm=%.1f ", 2048 * SPEED_BASE_RPM / 32768);
    TK_CHECK(strstr(cmd("status"), ref) != NULL, "forced reference: %s", out);
    CHECK_REPLY("status please", "err too many arguments");
}

static void case_timing(void)
{
    setup();
    foc_isr_timing_add(&timing, 100u);
    foc_isr_timing_add(&timing, 200u);
    foc_isr_timing_add(&timing, 150u);
    /* running average x 64: 6400 -> 6500 -> 6549 */
    const unsigned avg = 6549u / 64u;
    char want[200];
    snprintf(want, sizeof want,
             "ok min_cycles=100 avg_cycles=%u max_cycles=200 count=3 clock_hz=1000000 "
             "load_pct=%.1f\r\n", avg, 100.0 * avg * PWM_FREQUENCY_HZ / 1e6);
    TK_CHECK(strcmp(cmd("timing"), want) == 0, "timing\n got: %s\nwant: %s", out, want);
    CHECK_REPLY("timing reset", "ok");
    TK_CHECK(timing.reset == 1u, "reset requested");
    foc_isr_timing_add(&timing, 500u);
    TK_CHECK(timing.min_cycles == 500u && timing.max_cycles == 500u && timing.count == 1u &&
                 timing.reset == 0u, "restarted by the next measurement");
    foc_isr_timing_add(&timing, 0xFFFFFFFFu);
    TK_CHECK(timing.max_cycles == (1UL << 25), "clamped");
    CHECK_REPLY("timing foo", "err usage: timing [reset]");
    foc_mon_init(&mon, &ctrl, &scope, NULL, collect);
    CHECK_REPLY("timing", "err no timing");
}

static void case_dac(void)
{
    setup();
    CHECK_REPLY("dac", "ok dac1=id dac2=iq");
    CHECK_REPLY("dac vq speed_est", "ok dac1=vq dac2=speed_est");
    ctrl.v_dq.q = 1234;
    ctrl.est.est_speed = -55;
    q15_t a = 0, b = 0;
    foc_scope_dac(&scope, &a, &b);
    TK_CHECK(a == 1234 && b == -55, "values %d %d", a, b);
    CHECK_REPLY("dac bogus iq", "err unknown variable: bogus");
    CHECK_REPLY("dac iq", "err usage: dac [<var1> <var2>]");
    CHECK_REPLY("dac", "ok dac1=vq dac2=speed_est");
    foc_mon_init(&mon, &ctrl, NULL, &timing, collect);
    CHECK_REPLY("dac", "err no scope");
    CHECK_REPLY("scope", "err no scope");
}

static void case_vars_and_help(void)
{
    setup();
    const char *r = cmd("vars");
    unsigned lines = 0;
    for (const char *p = r; (p = strstr(p, "var ")) != NULL; p += 4) {
        lines += (p == r || p[-1] == '\n');
    }
    TK_CHECK(lines == FOC_VAR_COUNT, "%u var lines", lines);
    char want[160];
    snprintf(want, sizeof want, "\r\nvar iq A %s s\r\n", trimmed(FOC_I_BASE_A, 9));
    TK_CHECK(strstr(r, want) != NULL, "iq line (%s)", want);
    snprintf(want, sizeof want, "\r\nvar speed rpm %s s\r\n", trimmed(SPEED_BASE_RPM, 9));
    TK_CHECK(strstr(r, want) != NULL, "speed line (%s)", want);
    TK_CHECK(strstr(r, "\r\nvar theta deg 180 u\r\n") != NULL, "theta line");
    TK_CHECK(strstr(r, "\r\nvar state - 32768 s\r\n") != NULL, "state line");
    snprintf(want, sizeof want, "ok vars=%u\r\n", (unsigned)FOC_VAR_COUNT);
    TK_CHECK(strlen(r) > strlen(want) && strcmp(r + strlen(r) - strlen(want), want) == 0,
             "ends with %s", want);

    r = cmd("help");
    static const char *const words[] = { "start", "stop", "speed <rpm>", "ack", "status",
                                         "timing", "dac", "vars", "scope ch", "scope decim",
                                         "scope trig", "scope pre", "scope arm", "help" };
    for (size_t i = 0; i < sizeof words / sizeof words[0]; i++) {
        TK_CHECK(strstr(r, words[i]) != NULL, "help mentions %s", words[i]);
    }
    TK_CHECK(strlen(r) > 4 && strcmp(r + strlen(r) - 4, "ok\r\n") == 0, "help ends with ok");
}

static void case_scope_commands(void)
{
    setup();
    CHECK_REPLY("scope ch iq speed_est", "ok");
    CHECK_REPLY("scope decim 2", "ok");
    char want[200];
    snprintf(want, sizeof want, "ok level=%ld\r\n", lround(1500.0 * 32768.0 / SPEED_BASE_RPM));
    TK_CHECK(strcmp(cmd("scope trig speed_est rising 1500"), want) == 0, "%s", out);
    snprintf(want, sizeof want, "ok level=%ld\r\n", lround(0.5 * 32768.0 / FOC_I_BASE_A));
    TK_CHECK(strcmp(cmd("scope trig iq falling 0.5"), want) == 0, "%s", out);
    CHECK_REPLY("scope trig theta either 180", "ok level=32768");
    CHECK_REPLY("scope trig theta rising 360", "err out of range: 360");
    CHECK_REPLY("scope trig theta rising -1", "err out of range: -1");
    CHECK_REPLY("scope trig iq rising 99", "err out of range: 99");
    CHECK_REPLY("scope trig iq sideways 1", "err unknown edge: sideways");
    CHECK_REPLY("scope trig iq rising x", "err bad number: x");
    CHECK_REPLY("scope trig nothing rising 1", "err unknown variable: nothing");
    CHECK_REPLY("scope trig iq rising", "err usage: scope trig immediate | scope trig <var> "
                                        "rising|falling|either <level>");
    CHECK_REPLY("scope trig immediate", "ok");
    CHECK_REPLY("scope pre 25", "ok");
    CHECK_REPLY("scope pre 101", "err bad number: 101");
    CHECK_REPLY("scope decim 0", "err bad number: 0");
    CHECK_REPLY("scope decim 65536", "err bad number: 65536");
    CHECK_REPLY("scope decim", "err usage: scope decim <1..65535>");
    CHECK_REPLY("scope ch", "err usage: scope ch <var> [<var> [<var> [<var>]]]");
    CHECK_REPLY("scope ch iq bogus", "err unknown variable: bogus");
    CHECK_REPLY("scope ch ia ib ic id iq", "err too many arguments");
    CHECK_REPLY("scope fly", "err unknown scope command: fly");
    CHECK_REPLY("scope arm now", "err too many arguments");
    CHECK_REPLY("scope dump", "err scope not done: IDLE");
    snprintf(want, sizeof want,
             "ok state=IDLE channels=2 frames=20 pre=5 decim=2 dt_s=%s trigger=immediate "
             "vars=iq,speed_est\r\n", dt_text(2u));
    TK_CHECK(strcmp(cmd("scope"), want) == 0, "scope\n got: %s\nwant: %s", out, want);
    TK_CHECK(strcmp(cmd("scope state"), want) == 0, "scope state: %s", out);
    CHECK_REPLY("scope arm", "ok");
    CHECK_REPLY("scope ch iq", "err scope busy (scope stop first)");
    CHECK_REPLY("scope dump", "err scope not done: ARMED");
    CHECK_REPLY("scope stop", "ok");
    TK_CHECK(foc_scope_state(&scope) == FOC_SCOPE_IDLE, "stopped");
}

/* A capture made by ticking the scope, read back through the dump. */
static void case_scope_dump(void)
{
    setup();
    CHECK_REPLY("scope ch iq theta", "ok"); /* 20 frames */
    const long level = lround(0.1 * 32768.0 / FOC_I_BASE_A);
    char want[300];
    snprintf(want, sizeof want, "ok level=%ld\r\n", level);
    TK_CHECK(strcmp(cmd("scope trig iq rising 0.1"), want) == 0, "%s", out);
    CHECK_REPLY("scope pre 25", "ok");      /* 5 frames before */
    CHECK_REPLY("scope arm", "ok");
    /* period n: iq = 20 n (first >= level at n_trig), theta = 65535 - n */
    const int n_trig = (int)((level + 19) / 20);
    int n = 0;
    for (; n < 200 && foc_scope_state(&scope) != FOC_SCOPE_DONE; n++) {
        ctrl.i_dq.q = (q15_t)(20 * n);
        ctrl.est.theta = (uint16_t)(65535 - n);
        foc_scope_tick(&scope);
    }
    TK_CHECK(n - 1 == n_trig + 14, "done at period %d", n - 1);
    static char r[4096];
    snprintf(r, sizeof r, "%s", cmd("scope dump"));
    snprintf(want, sizeof want,
             "scope state=DONE channels=2 frames=20 pre=5 decim=1 dt_s=%s trigger=iq "
             "edge=rising level=%ld\r\nchan 0 iq A %s s\r\nchan 1 theta deg 180 u\r\n",
             dt_text(1u), level, trimmed(FOC_I_BASE_A, 9));
    TK_CHECK(starts(r, want), "header\n got: %.200s\nwant: %s", r, want);
    const char *p = strstr(r, "u\r\n");
    unsigned sum = 0;
    for (int k = -5; k < 15 && p != NULL; k++) {
        p += 3;
        const int period = n_trig + k;
        char line[64];
        snprintf(line, sizeof line, "%d %d %d\r\n", k, 20 * period, 65535 - period);
        TK_CHECK(starts(p, line), "frame %d: got %.30s, want %s", k, p, line);
        sum += (unsigned)(20 * period) + (unsigned)(65535 - period);
        p = strchr(p, '\n') - 2;
    }
    snprintf(want, sizeof want, "ok dump frames=20 sum=%u\r\n", sum % 65536u);
    TK_CHECK(p != NULL && strcmp(p + 3, want) == 0, "end: got %s want %s", p ? p + 3 : "", want);
    TK_CHECK(strcmp(cmd("scope dump"), r) == 0, "the same dump twice");
    TK_CHECK(foc_scope_state(&scope) == FOC_SCOPE_DONE, "still readable");
    CHECK_REPLY("scope arm", "ok");
}

/* Any byte but a line end aborts a dump in progress; the byte counts. */
static void case_dump_aborted(void)
{
    setup();
    CHECK_REPLY("scope arm", "ok");
    for (int i = 0; i < 40; i++) {
        foc_scope_tick(&scope);
    }
    out_len = 0;
    feed("scope dump\r\n", 12); /* the LF of CR LF does not abort */
    TK_CHECK(foc_mon_poll(&mon) == 1u && foc_mon_poll(&mon) == 1u, "dump started");
    feed("\r\n", 2);
    TK_CHECK(foc_mon_poll(&mon) == 1u, "line ends do not abort");
    feed("ack\r\n", 5);
    TK_CHECK(strstr(out, "err dump aborted\r\nok\r\n") != NULL, "aborted, then ack: %s", out);
    TK_CHECK(foc_mon_poll(&mon) == 0u, "nothing pending");
    TK_CHECK(ctrl.req.ack == 1u, "the byte that aborted counts");
}

static void case_line_handling(void)
{
    setup();
    TK_CHECK(cmd("")[0] == '\0', "empty line: no reply");
    TK_CHECK(cmd("   ")[0] == '\0', "blank line: no reply");
    out_len = 0;
    feed("stop\r", 5);
    feed("ack\n", 4);
    feed("start\r\n\r\n", 9);
    TK_CHECK(strcmp(out, "ok\r\nok\r\nok\r\n") == 0, "CR, LF, CR LF: one reply each: %s", out);
    CHECK_REPLY("STATUS x", "err too many arguments");
    CHECK_REPLY("Scope  Ch\tIQ   Vq", "ok");
    TK_CHECK(scope.nch == 2u && scope.var[1] == FOC_VAR_VQ, "case and spacing ignored");
    CHECK_REPLY("stopx\x7f", "ok");      /* DEL erases */
    CHECK_REPLY("\x08\x08" "ack", "ok"); /* backspace at the start: nothing */
    CHECK_REPLY("st\x01op", "err bad character");
    CHECK_REPLY("st\xc3\xa9p", "err bad character");
    CHECK_REPLY("frobnicate", "err unknown command: frobnicate");
    CHECK_REPLY("a b c d e f g h", "err too many arguments");

    char line[200];
    memset(line, 'a', sizeof line);
    line[63] = '\0';
    char want[300];
    snprintf(want, sizeof want, "err unknown command: %s\r\n", line);
    TK_CHECK(strcmp(cmd(line), want) == 0, "63 characters fit");
    line[63] = 'a';
    line[64] = '\0';
    CHECK_REPLY(line, "err line too long (max 63 characters)");
    line[150] = '\0';
    CHECK_REPLY(line, "err line too long (max 63 characters)");
    CHECK_REPLY("ack", "ok"); /* and the next line is fine */
}

/* The same command, byte by byte with polls in between, or all at once. */
static void case_byte_by_byte(void)
{
    setup();
    static const char text[] = "scope trig speed_est rising 1500\r\n";
    const char *whole = cmd("scope trig speed_est rising 1500");
    char first[64];
    snprintf(first, sizeof first, "%s", whole);
    out_len = 0;
    unsigned calls = 0;
    for (size_t i = 0; i < sizeof text - 1; i++) {
        foc_mon_feed(&mon, (uint8_t)text[i]);
        calls += foc_mon_poll(&mon);
        TK_CHECK(out_len == 0 || i >= sizeof text - 3, "no reply before the line end (%zu)", i);
    }
    TK_CHECK(calls == 0 && strcmp(out, first) == 0, "same reply: %s", out);
    /* replies are written in few calls: one per line or 48 characters */
    write_calls = 0;
    (void)cmd("status");
    TK_CHECK(write_calls >= 1 && write_calls <= 6, "%u writes", write_calls);
}

/* Random bytes: every reply is one "ok"/"err" line, nothing else. */
static void case_garbage(void)
{
    setup();
    uint32_t x = 12345u;
    out_len = 0;
    unsigned line_ends = 0;
    for (int i = 0; i < 200000; i++) {
        x = x * 1103515245u + 12345u;
        uint8_t b = (uint8_t)(x >> 16);
        if ((x >> 8) % 40u == 0u) {
            b = '\n';
        }
        line_ends += (b == '\n' || b == '\r');
        foc_mon_feed(&mon, b);
        while (foc_mon_poll(&mon) != 0u) {
        }
        TK_CHECK(mon.len <= FOC_MON_LINE_MAX, "line length %u", mon.len);
        if (out_len > sizeof out / 2) {
            out_len = 0; /* keep the buffer from filling; lines are whole */
        }
    }
    (void)line_ends;
    unsigned replies = 0;
    for (const char *p = out; *p != '\0';) {
        TK_CHECK(starts(p, "ok") || starts(p, "err "), "reply line: %.40s", p);
        const char *e = strstr(p, "\r\n");
        TK_CHECK(e != NULL, "line ends with CR LF");
        if (e == NULL) {
            break;
        }
        p = e + 2;
        replies++;
    }
    TK_CHECK(replies > 100, "%u replies", replies);
}

TK_CASES(TK_CASE(case_start_stop_ack), TK_CASE(case_speed), TK_CASE(case_status),
         TK_CASE(case_timing), TK_CASE(case_dac), TK_CASE(case_vars_and_help),
         TK_CASE(case_scope_commands), TK_CASE(case_scope_dump), TK_CASE(case_dump_aborted),
         TK_CASE(case_line_handling), TK_CASE(case_byte_by_byte), TK_CASE(case_garbage))
