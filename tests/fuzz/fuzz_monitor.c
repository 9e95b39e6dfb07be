/*
 * Fuzz harness for the text monitor (src/monitor.c) and the scope it
 * drives (src/scope.c): arbitrary bytes on the serial line, with the
 * controller running between lines (foc_fast_step every period, the scope
 * ticking, foc_slow_step every CONTROL_SLOW_DIVIDER periods) on a plain
 * port whose samples move with the input.
 *
 * Built like fuzz_controller.c (libFuzzer with `make fuzz-monitor`, or
 * with fuzz_main.c for the corpus test fuzz.monitor_corpus).
 *
 * Oracle (docs/monitor.md): every byte written is printable ASCII, CR or
 * LF, and every reply line ends with CR LF; a line of only spaces and tabs
 * gets no reply (beyond FOC_MON_LINE_MAX characters the protocol does not
 * say whether "blank" or "too long" wins: either is accepted); a line of
 * printable characters (no editing or control
 * bytes) with something else in it gets replies ending in exactly one final
 * line starting with "ok" or "err"; any line gets at most one final line;
 * a scope dump ends (foc_mon_poll returns 0 within the buffer's size in
 * lines).  The controller's state stays within foc_state_t and every duty
 * within [0, 32767].  Plus ASan and UBSan.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "foc/config.h"
#include "foc/controller.h"
#include "foc/monitor.h"
#include "foc/port.h"
#include "foc/scope.h"

#define SCOPE_SAMPLES 256u
#define PERIODS_PER_LINE 40u
#define MAX_LINES 200u

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void fail(const char *what)
{
    fprintf(stderr, "fuzz_monitor: oracle violated: %s\n", what);
    abort();
}

/* ------------------------------------------------------------ the port -- */

static foc_samples_t samples;
static uint8_t latch;

void foc_port_read_samples(foc_samples_t *s)
{
    *s = samples;
}

void foc_port_set_duties(const foc_duty_t *d)
{
    if (d->a < 0 || d->b < 0 || d->c < 0) {
        fail("negative duty");
    }
}

void foc_port_pwm_enable(void)
{
}

void foc_port_pwm_disable(void)
{
}

void foc_port_low_sides_on(void)
{
}

void foc_port_brake_resistor(uint8_t on)
{
    (void)on;
}

uint8_t foc_port_overcurrent_latched(void)
{
    return latch;
}

void foc_port_overcurrent_clear(void)
{
    latch = 0;
}

void foc_port_debug_out(q15_t ch1, q15_t ch2)
{
    (void)ch1;
    (void)ch2;
}

static uint32_t ticks;

uint32_t foc_port_timestamp(void)
{
    return ticks;
}

/* ------------------------------------------------------ the replies -- */

static struct {
    char line[512]; /* the reply line being written */
    size_t len;
    unsigned finals; /* final lines since the last input line end */
    unsigned lines;  /* reply lines since the last input line end */
    int after_cr;
} out;

static int trace = -1; /* FUZZ_TRACE=1: the replies on stderr */

static void write_out(const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        const unsigned char ch = (unsigned char)s[i];
        if (ch == '\n') {
            if (!out.after_cr) {
                fail("reply line not ended by CR LF");
            }
            out.after_cr = 0;
            out.lines++;
            if (trace) {
                fprintf(stderr, "  < %.*s\n", (int)out.len, out.line);
            }
            if ((out.len >= 2 && memcmp(out.line, "ok", 2) == 0) ||
                (out.len >= 3 && memcmp(out.line, "err", 3) == 0)) {
                out.finals++;
            }
            out.len = 0;
            continue;
        }
        if (out.after_cr) {
            fail("CR not followed by LF");
        }
        if (ch == '\r') {
            out.after_cr = 1;
            continue;
        }
        if (ch < 0x20u || ch > 0x7Eu) {
            fail("reply byte outside printable ASCII");
        }
        if (out.len < sizeof out.line) {
            out.line[out.len++] = (char)ch;
        }
    }
}

/* ------------------------------------------------------------- the run -- */

static foc_ctrl_t ctrl;
static foc_scope_t scope;
static int16_t scope_buf[SCOPE_SAMPLES];
static foc_isr_timing_t timing;
static foc_monitor_t mon;

static void run_periods(unsigned n, uint32_t seed)
{
    for (unsigned k = 0; k < n; k++) {
        /* samples that move: currents and angle from a counter */
        seed = seed * 1103515245u + 12345u;
        samples.i_a = (q15_t)(int16_t)(seed >> 16);
        samples.i_b = (q15_t)(int16_t)(seed >> 8);
        samples.i_c = (q15_t)(-(int32_t)samples.i_a - samples.i_b);
        samples.theta_sensor = (uint16_t)(samples.theta_sensor + 300u);
        foc_fast_step(&ctrl);
        foc_scope_tick(&scope);
        foc_scope_debug_out(&scope, &ctrl);
        foc_isr_timing_add(&timing, seed & 0xFFFu);
        if (ticks % CONTROL_SLOW_DIVIDER == 0u) {
            foc_slow_step(&ctrl);
        }
        ticks++;
        if ((unsigned)ctrl.state > (unsigned)FOC_STATE_LAST) {
            fail("state outside the state machine");
        }
    }
}

/* What the line just ended looks like, by the protocol's rules. */
enum { LINE_BLANK, LINE_PLAIN, LINE_OTHER };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (trace < 0) {
        trace = getenv("FUZZ_TRACE") != NULL;
    }
    memset(&out, 0, sizeof out);
    memset(&samples, 0, sizeof samples);
    samples.phases = FOC_PHASE_A | FOC_PHASE_B;
    samples.vdc = FOC_VDC_NOMINAL;
    samples.temp = (q15_t)(FOC_OVERTEMP_CLEAR / 2);
    latch = 0;
    ticks = 0;
    foc_init(&ctrl);
    foc_scope_init(&scope, &ctrl, scope_buf, (uint16_t)SCOPE_SAMPLES);
    foc_isr_timing_init(&timing, 72000000u);
    foc_mon_init(&mon, &ctrl, &scope, &timing, write_out);

    int kind = LINE_BLANK;
    unsigned len = 0; /* bytes in the line so far */
    unsigned lines = 0;
    uint8_t prev = 0;
    for (size_t i = 0; i < size && lines < MAX_LINES; i++) {
        const uint8_t b = data[i];
        const int line_end = (b == '\r') || (b == '\n' && prev != '\r');
        const int lf_after_cr = (b == '\n' && prev == '\r');
        prev = b;
        if (!line_end && !lf_after_cr) {
            len++;
            if (b == ' ' || b == '\t') {
                /* blank so far stays blank */
            } else if (b >= 0x21u && b <= 0x7Eu) {
                if (kind == LINE_BLANK) {
                    kind = LINE_PLAIN;
                }
            } else {
                kind = LINE_OTHER;
            }
        }
        out.finals = 0;
        out.lines = 0;
        foc_mon_feed(&mon, b);
        if (!line_end) {
            if (out.finals > 0u && !lf_after_cr) {
                /* replies come only at line ends (a dump aborted by a byte
                 * ends with its own final line) */
                if (out.finals > 1u) {
                    fail("more than one final line for one byte");
                }
            }
            continue;
        }
        unsigned polls = 0;
        while (foc_mon_poll(&mon) != 0u) {
            if (++polls > SCOPE_SAMPLES + 16u) {
                fail("scope dump does not end");
            }
        }
        if (kind == LINE_BLANK && len <= FOC_MON_LINE_MAX && out.lines != 0u) {
            fail("reply to a blank line");
        }
        if (kind == LINE_PLAIN && out.finals != 1u) {
            fail("a command line without exactly one final ok/err line");
        }
        if (out.finals > 1u) {
            fail("more than one final line for one command");
        }
        if (out.len != 0u || out.after_cr) {
            fail("reply ends in the middle of a line");
        }
        kind = LINE_BLANK;
        len = 0;
        lines++;
        run_periods(PERIODS_PER_LINE, (uint32_t)i);
    }
    return 0;
}
