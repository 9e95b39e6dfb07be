/*
 * Fuzz harness for the monitor (src/monitor.c, src/mon_link.c) and the
 * scope it drives (src/scope.c): bytes on the serial line, with the
 * controller running between frames (foc_fast_step every period, the
 * scope ticking, foc_slow_step every CONTROL_SLOW_DIVIDER periods) on a
 * plain port whose samples move with the input.
 *
 * Built like fuzz_controller.c (libFuzzer with `make fuzz-monitor`, or
 * with fuzz_main.c for the corpus test fuzz.monitor_corpus).
 *
 * The first input byte chooses the mode.  Even: the rest goes to the
 * monitor as it is (line noise).  Odd: the rest is a list of requests,
 * each a length byte then that many payload bytes, which the harness
 * frames itself (its own CRC-16 and COBS, written apart from the link's)
 * so that the fuzzer reaches the commands; a length byte with bit 7 set
 * also corrupts one byte of that encoded frame.
 *
 * Oracle (docs/monitor.md): everything the monitor sends is a sequence of
 * complete frames (COBS, a zero at the end, a good CRC), each a reply
 * whose byte 0 is a request's command | 0x80 and whose status byte is a
 * defined code, each sent as a zero, the encoded frame, a zero; a reply is sent only when a request's frame has just
 * ended; in framed mode every uncorrupted request gets exactly one reply
 * and a corrupted one at most one, and the dropped-frames counter counts
 * every other frame; in both modes a frame that is not a good one never
 * gets a reply (the harness decodes the input frames itself to know).
 * The controller's state stays within foc_state_t and every duty within
 * [0, 32767].  Plus ASan and UBSan.
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
#include "ref_frame.h"

#define SCOPE_SAMPLES 256u
#define PERIODS_PER_FRAME 40u
#define MAX_FRAMES 300u

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

void foc_port_pwm_enable_at_half(void)
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

/* ---------------------------------------------- the harness's framing -- */

/* COBS-decodes enc[0..n-1] (no delimiter) into out; the length, or -1 if
 * the encoding is broken. */
static int ref_uncobs(const uint8_t *enc, size_t n, uint8_t *out, size_t cap)
{
    size_t i = 0, o = 0;
    while (i < n) {
        const uint8_t code = enc[i++];
        if (code == 0 || i + code - 1u > n) {
            return -1;
        }
        for (uint8_t k = 1; k < code; k++) {
            if (o >= cap) {
                return -1;
            }
            out[o++] = enc[i++];
        }
        if (code != 0xFF && i < n) {
            if (o >= cap) {
                return -1;
            }
            out[o++] = 0;
        }
    }
    return (int)o;
}

/* A good frame: decodes, fits the link's buffer, command + CRC, CRC right. */
static int good_frame(const uint8_t *enc, size_t n, uint8_t *cmd)
{
    uint8_t raw[FOC_LINK_RX_MAX];
    const int len = ref_uncobs(enc, n, raw, sizeof raw);
    if (len < 3) {
        return 0;
    }
    const uint16_t crc = (uint16_t)(raw[len - 2] | (raw[len - 1] << 8));
    *cmd = raw[0];
    return crc == ref_crc(raw, (size_t)len - 2);
}

/* ------------------------------------------------------------- the run -- */

static foc_ctrl_t ctrl;
static foc_scope_t scope;
static int16_t scope_buf[SCOPE_SAMPLES];
static foc_mon_t mon;
static int trace = -1; /* FUZZ_TRACE=1: the frames on stderr */

static void run_periods(unsigned n, uint32_t seed)
{
    for (unsigned k = 0; k < n; k++) {
        seed = seed * 1103515245u + 12345u;
        samples.i_a = (q15_t)(int16_t)(seed >> 16);
        samples.i_b = (q15_t)(int16_t)(seed >> 8);
        samples.i_c = (q15_t)(-(int32_t)samples.i_a - samples.i_b);
        samples.theta_sensor = (uint16_t)(samples.theta_sensor + 300u);
        foc_fast_step(&ctrl);
        if (ticks % CONTROL_SLOW_DIVIDER == 0u) {
            foc_slow_step(&ctrl);
        }
        ticks++;
        if ((unsigned)ctrl.state > (unsigned)FOC_STATE_LAST) {
            fail("state outside the state machine");
        }
    }
}

/* The input frame being received (as the harness sees it). */
static uint8_t in_frame[512];
static size_t in_len;
static unsigned replies, good, bad;

/* Takes everything the monitor has to send; checks it is at most one
 * complete, good reply to `cmd` (valid: a good request just ended). */
static void take(int request_ended, int request_good, uint8_t cmd)
{
    uint8_t enc[256];
    size_t n = 0;
    uint8_t b;
    while (foc_mon_tx(&mon, &b) != 0u) {
        if (n >= sizeof enc) {
            fail("reply longer than any reply can be");
        }
        enc[n++] = b;
    }
    if (n == 0) {
        if (request_good) {
            fail("a good request without a reply");
        }
        return;
    }
    if (!request_ended || !request_good) {
        fail("a reply without a good request");
    }
    if (n < 3 || enc[0] != 0 || enc[n - 1] != 0) {
        fail("reply not started and ended by a zero");
    }
    for (size_t i = 1; i + 1 < n; i++) {
        if (enc[i] == 0) {
            fail("more than one frame for one request");
        }
    }
    uint8_t raw[256];
    const int len = ref_uncobs(enc + 1, n - 2, raw, sizeof raw);
    if (len < 4 || len > (int)FOC_LINK_TX_MAX) {
        fail("reply frame malformed or too long");
    }
    if ((uint16_t)(raw[len - 2] | (raw[len - 1] << 8)) != ref_crc(raw, (size_t)len - 2)) {
        fail("reply CRC wrong");
    }
    if (raw[0] != (uint8_t)(cmd | 0x80u) || raw[1] > FOC_MON_E_NODATA) {
        fail("reply names another command or an undefined status");
    }
    if (raw[1] != FOC_MON_OK && len != 4) {
        fail("an error reply with data");
    }
    if (trace) {
        fprintf(stderr, "  cmd 0x%02x -> status %u, %d bytes\n", cmd, raw[1], len - 2);
    }
    replies++;
}

static void feed_byte(uint8_t b, unsigned *frames)
{
    foc_mon_rx(&mon, b);
    if (b != 0) {
        if (in_len < sizeof in_frame) {
            in_frame[in_len] = b;
        }
        in_len++;
        take(0, 0, 0);
        return;
    }
    uint8_t cmd = 0;
    const int is_good = in_len > 0 && in_len <= sizeof in_frame && good_frame(in_frame, in_len, &cmd);
    if (in_len > 0) {
        if (is_good) {
            good++;
        } else {
            bad++;
        }
    }
    take(1, is_good, cmd);
    in_len = 0;
    (*frames)++;
    run_periods(PERIODS_PER_FRAME, *frames);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (trace < 0) {
        trace = getenv("FUZZ_TRACE") != NULL;
    }
    memset(&samples, 0, sizeof samples);
    samples.phases = FOC_PHASE_A | FOC_PHASE_B;
    samples.vdc = FOC_VDC_NOMINAL;
    samples.temp = (q15_t)(FOC_OVERTEMP_CLEAR / 2);
    latch = 0;
    ticks = 0;
    in_len = 0;
    replies = good = bad = 0;
    foc_init(&ctrl);
    foc_scope_init(&scope, &ctrl, scope_buf, (uint16_t)SCOPE_SAMPLES);
    ctrl.scope = &scope;
    foc_mon_init(&mon, &ctrl, &scope);
    if (size == 0) {
        return 0;
    }
    unsigned frames = 0;
    if ((data[0] & 1u) == 0u) {
        for (size_t i = 1; i < size && frames < MAX_FRAMES; i++) {
            feed_byte(data[i], &frames);
        }
    } else {
        size_t i = 1;
        while (i < size && frames < MAX_FRAMES) {
            const uint8_t lb = data[i++];
            size_t n = lb & 0x3Fu;
            if (n > size - i) {
                n = size - i;
            }
            uint8_t raw[80], enc[96];
            memcpy(raw, &data[i], n);
            i += n;
            const uint16_t crc = ref_crc(raw, n);
            raw[n] = (uint8_t)(crc & 0xFF);
            raw[n + 1] = (uint8_t)(crc >> 8);
            const size_t m = ref_cobs(raw, n + 2, enc);
            if ((lb & 0x80u) != 0u && i < size) {
                enc[data[i] % m] ^= (uint8_t)(data[i] | 1u);
                i++;
            }
            for (size_t k = 0; k < m; k++) {
                feed_byte(enc[k], &frames);
            }
        }
    }
    if (replies != good) {
        fail("replies differ from the good requests");
    }
    if (mon.link.dropped != (bad > 65535u ? 65535u : bad)) {
        fail("the dropped-frames counter differs from the bad frames");
    }
    return 0;
}
