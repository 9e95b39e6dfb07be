/*
 * Monitor (foc/monitor.h, foc/mon_link.h) against a controller at rest:
 * the CRC's check value, COBS frames written here independently of the
 * link's encoder (zero bytes in the payload and the CRC, blocks at the
 * buffer's end), every command's effect and reply, malformed frames
 * (bad CRC, broken COBS, too short, too long, a request while a reply is
 * being sent) dropped, counted and not executed, range-checked writes and
 * writes refused while the motor is driven, and a scope capture read back
 * in chunks equal to the samples the scope holds.
 */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "foc/config.h"
#include "foc/monitor.h"
#include "ref_frame.h"
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

static foc_ctrl_t ctrl;
static foc_scope_t scope;
static int16_t buf[40];
static foc_mon_t mon;

static void setup(void)
{
    foc_init(&ctrl);
    foc_scope_init(&scope, &ctrl, buf, (uint16_t)(sizeof buf / sizeof buf[0]));
    ctrl.scope = &scope;
    foc_mon_init(&mon, &ctrl, &scope);
}

static void feed(const uint8_t *p, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        foc_mon_rx(&mon, p[i]);
    }
}

/* Everything the monitor has to send, COBS-decoded and CRC-checked by the
 * test's own code; returns the payload length (0: nothing or bad). */
static uint8_t reply[256];
static size_t take_reply(void)
{
    uint8_t enc[300];
    size_t n = 0;
    uint8_t b;
    while (n < sizeof enc && foc_mon_tx(&mon, &b) != 0u) {
        enc[n++] = b;
    }
    if (n < 3 || enc[0] != 0 || enc[n - 1] != 0) {
        return 0; /* a zero first, a zero last */
    }
    size_t o = 0, i = 1;
    while (i < n - 1) {
        const uint8_t code = enc[i++];
        for (uint8_t k = 1; k < code && i < n - 1; k++) {
            if (enc[i] == 0) {
                return 0; /* a zero inside */
            }
            reply[o++] = enc[i++];
        }
        if (code != 0xFF && i < n - 1) {
            reply[o++] = 0;
        }
    }
    if (o < 4) {
        return 0;
    }
    const uint16_t crc = (uint16_t)(reply[o - 2] | (reply[o - 1] << 8));
    return (crc == ref_crc(reply, o - 2)) ? o - 2 : 0;
}

/* Sends a request (payload), returns the reply's payload length. */
static size_t request(const uint8_t *rq, size_t n)
{
    uint8_t raw[64], enc[80];
    memcpy(raw, rq, n);
    const uint16_t crc = ref_crc(rq, n);
    raw[n] = (uint8_t)(crc & 0xFF);
    raw[n + 1] = (uint8_t)(crc >> 8);
    feed(enc, ref_cobs(raw, n + 2, enc));
    return take_reply();
}

#define REQ(...)                                                               \
    ({                                                                         \
        static const uint8_t rq_[] = { __VA_ARGS__ };                          \
        request(rq_, sizeof rq_);                                              \
    })

static int16_t s16(size_t at) { return (int16_t)(reply[at] | (reply[at + 1] << 8)); }
static uint16_t u16(size_t at) { return (uint16_t)(reply[at] | (reply[at + 1] << 8)); }

/* -------------------------------------------------------------- cases -- */

static void case_crc_check_value(void)
{
    const uint8_t s[] = "123456789";
    TK_CHECK(foc_crc16(s, 9) == 0x29B1u, "CRC-16/CCITT-FALSE check value: 0x%04X",
             foc_crc16(s, 9));
    TK_CHECK(ref_crc(s, 9) == 0x29B1u, "the test's reference CRC");
}

static void case_start_stop_ack_speed(void)
{
    setup();
    TK_CHECK(REQ(FOC_MON_START) == 2 && reply[0] == (0x80 | FOC_MON_START) && reply[1] == 0,
             "start acknowledged");
    TK_CHECK(ctrl.req.start == 1u, "start requested");
    TK_CHECK(REQ(FOC_MON_STOP) == 2 && ctrl.req.stop == 1u, "stop requested");
    TK_CHECK(REQ(FOC_MON_ACK) == 2 && ctrl.req.ack == 1u, "ack requested");
    TK_CHECK(REQ(FOC_MON_SPEED, 0x00, 0x20) == 2 && ctrl.req.speed == 0x2000, "speed %d",
             ctrl.req.speed);
    TK_CHECK(REQ(FOC_MON_SPEED, 0x00, 0xE0) == 2 && ctrl.req.speed == -0x2000, "negative speed");
    TK_CHECK(REQ(FOC_MON_SPEED, 0x00) == 2 && reply[1] == FOC_MON_E_LENGTH, "speed needs 2 bytes");
    TK_CHECK(REQ(FOC_MON_START, 0x01) == 2 && reply[1] == FOC_MON_E_LENGTH,
             "start takes no argument");
    TK_CHECK(REQ(0x7E) == 2 && reply[1] == FOC_MON_E_COMMAND && reply[0] == 0xFE,
             "unknown command answered, not executed");
}

static void case_identify_and_status(void)
{
    setup();
    const size_t n = REQ(FOC_MON_IDENTIFY);
    TK_CHECK(n >= 36 && reply[1] == 0, "identify: %zu bytes", n);
    TK_CHECK(reply[2] == FOC_MON_PROTOCOL && u16(3) == FOC_MON_FW_VERSION, "versions");
    const uint32_t pwm = (uint32_t)(reply[6] | (reply[7] << 8) | (reply[8] << 16)) |
                         ((uint32_t)reply[9] << 24);
    TK_CHECK(pwm == (uint32_t)PWM_FREQUENCY_HZ, "pwm %u", (unsigned)pwm);
    TK_CHECK(reply[11] == MOTOR_POLE_PAIRS && reply[12] == FOC_VAR_COUNT &&
             reply[13] == FOC_MON_PARAMS, "pole pairs, table sizes");
    ctrl.faults.active = 0x0104u;
    ctrl.faults.first = 0x0004u;
    ctrl.i_dq.q = -1234;
    ctrl.samples.vdc = 20000;
    ctrl.est.est_speed = 777;
    mon.cpu_load_q15 = 12345u;
    mon.overruns = 3u;
    TK_CHECK(REQ(FOC_MON_STATUS) == 30 && reply[1] == 0, "status length");
    TK_CHECK(reply[2] == FOC_STATE_IDLE && u16(3) == 0x0104u && u16(5) == 0x0004u, "state, faults");
    TK_CHECK(s16(13) == 777 && s16(17) == -1234 && s16(19) == 20000, "speed_est, iq, vdc");
    TK_CHECK(u16(23) == 12345u && u16(25) == 3u && u16(27) == 0u, "load, overruns, dropped");
}

static void case_malformed_dropped(void)
{
    setup();
    uint8_t bad_crc[] = { 0x04, FOC_MON_START, 0x11, 0x22, 0x00 };
    feed(bad_crc, sizeof bad_crc);
    TK_CHECK(take_reply() == 0 && ctrl.req.start == 0u, "bad CRC: no reply, not executed");
    /* a block that says 5 bytes but the frame ends after 2 */
    uint8_t raw[3] = { FOC_MON_START, 0, 0 };
    const uint16_t crc = ref_crc(raw, 1);
    uint8_t broken[] = { 0x06, FOC_MON_START, (uint8_t)crc, 0x00 };
    feed(broken, sizeof broken);
    TK_CHECK(take_reply() == 0 && ctrl.req.start == 0u, "truncated COBS block dropped");
    uint8_t short_frame[] = { 0x02, 0x05, 0x00 };
    feed(short_frame, sizeof short_frame);
    TK_CHECK(take_reply() == 0, "a frame shorter than command + CRC dropped");
    uint8_t longf[40];
    memset(longf, 0x11, sizeof longf);
    longf[0] = 0x30;
    longf[39] = 0;
    feed(longf, sizeof longf);
    TK_CHECK(take_reply() == 0, "an overlong frame dropped");
    uint8_t empty[] = { 0x00, 0x00 };
    feed(empty, sizeof empty);
    TK_CHECK(REQ(FOC_MON_STATUS) == 30, "then a good request works");
    TK_CHECK(u16(27) == 4u, "4 frames dropped: %u", u16(27));
    /* a request arriving while the reply is being sent */
    uint8_t rq[4] = { FOC_MON_START }, enc[16];
    const uint16_t c2 = ref_crc(rq, 1);
    rq[1] = (uint8_t)c2;
    rq[2] = (uint8_t)(c2 >> 8);
    feed(enc, ref_cobs(rq, 3, enc));
    feed(enc, ref_cobs(rq, 3, enc)); /* the first reply not taken yet */
    TK_CHECK(take_reply() == 2, "the first answered");
    TK_CHECK(REQ(FOC_MON_STATUS) == 30 && u16(27) == 5u, "the second dropped and counted");
}

static void case_table_and_writes(void)
{
    setup();
    TK_CHECK(REQ(FOC_MON_VAR_INFO, FOC_VAR_SPEED_EST) > 16 && reply[1] == 0, "var info");
    TK_CHECK(strcmp((const char *)&reply[15], "speed_est") == 0, "name %s", (const char *)&reply[15]);
    TK_CHECK(REQ(FOC_MON_VAR_INFO, 63) == 2 && reply[1] == FOC_MON_E_RANGE, "no entry 63");
    TK_CHECK(REQ(FOC_MON_VAR_INFO, FOC_MON_PARAM_BASE) > 16 &&
             strcmp((const char *)&reply[15], "speed_gain_shift") == 0, "first parameter");
    TK_CHECK(reply[4] == 3u, "writable while running");
    ctrl.i_dq.d = -321;
    TK_CHECK(REQ(FOC_MON_VAR_READ, FOC_VAR_ID) == 5 && s16(3) == -321, "read id");
    TK_CHECK(REQ(FOC_MON_VAR_WRITE, FOC_VAR_ID, 1, 0) == 2 && reply[1] == FOC_MON_E_READONLY,
             "variables are read-only");
    /* speed_gain_shift: 0..FOC_SPEED_HUNT_SHIFT_MAX, also while running */
    TK_CHECK(REQ(FOC_MON_VAR_WRITE, FOC_MON_PARAM_BASE, FOC_SPEED_HUNT_SHIFT_MAX + 1, 0) == 2 &&
             reply[1] == FOC_MON_E_RANGE && ctrl.speed_ctrl.gain_shift == 0u, "out of range refused");
    ctrl.state = FOC_STATE_RUN;
    TK_CHECK(REQ(FOC_MON_VAR_WRITE, FOC_MON_PARAM_BASE, 1, 0) == 2 && reply[1] == 0 &&
             ctrl.speed_ctrl.gain_shift == 1u, "gain shift written while running");
    TK_CHECK(REQ(FOC_MON_VAR_READ, FOC_MON_PARAM_BASE) == 5 && u16(3) == 1u, "read back");
    /* stop_mode (entry 2): only while stopped */
    TK_CHECK(REQ(FOC_MON_VAR_WRITE, FOC_MON_PARAM_BASE + 2, 1, 0) == 2 &&
             reply[1] == FOC_MON_E_RUNNING && ctrl.opt.stop_mode != STOP_MODE_COAST,
             "stop mode refused while running");
    ctrl.state = FOC_STATE_IDLE;
    TK_CHECK(REQ(FOC_MON_VAR_WRITE, FOC_MON_PARAM_BASE + 2, 1, 0) == 2 && reply[1] == 0 &&
             ctrl.opt.stop_mode == STOP_MODE_COAST, "stop mode written in IDLE");
    TK_CHECK(REQ(FOC_MON_VAR_WRITE, FOC_MON_PARAM_BASE + 2, 3, 0) == 2 &&
             reply[1] == FOC_MON_E_RANGE, "stop mode 3 refused");
    TK_CHECK(REQ(FOC_MON_VAR_WRITE, FOC_MON_PARAM_BASE + FOC_MON_PARAMS, 0, 0) == 2 &&
             reply[1] == FOC_MON_E_RANGE, "beyond the table");
    ctrl.state = FOC_STATE_RUN;
    TK_CHECK(REQ(FOC_MON_COMMISSION) == 2 && reply[1] == FOC_MON_E_RUNNING &&
             ctrl.req.commission == 0u, "commissioning refused outside IDLE");
}

static void case_scope_capture(void)
{
    setup();
    /* id, iq; decim 1; immediate; pre 0 */
    TK_CHECK(REQ(FOC_MON_SCOPE_SET, 2, FOC_VAR_ID, FOC_VAR_IQ, 1, 0, 0, FOC_TRIG_IMMEDIATE, 0, 0,
                 0, 0, 0) == 2 && reply[1] == 0, "scope set: %u", reply[1]);
    TK_CHECK(REQ(FOC_MON_SCOPE_READ, 0, 0, 4) == 2 && reply[1] == FOC_MON_E_NODATA, "no data yet");
    TK_CHECK(REQ(FOC_MON_SCOPE_ARM) == 2 && reply[1] == 0, "armed");
    TK_CHECK(REQ(FOC_MON_SCOPE_SET, 1, FOC_VAR_ID, 1, 0, 0, 0, 0, 0, 0, 0, 0) == 2 &&
             reply[1] == FOC_MON_E_BUSY, "no change while capturing");
    for (int k = 0; k < 30; k++) {
        ctrl.i_dq.d = (q15_t)(100 * k - 1000);
        ctrl.i_dq.q = (q15_t)(-7 * k);
        foc_scope_tick(&scope);
    }
    TK_CHECK(REQ(FOC_MON_SCOPE_STATE) > 20 && reply[2] == FOC_SCOPE_DONE && u16(17) == 20,
             "done, 20 frames");
    int16_t got[40];
    for (unsigned first = 0; first < 40; first += 16) {
        const uint8_t n = (uint8_t)((40 - first) < 16 ? 40 - first : 16);
        const uint8_t rq[4] = { FOC_MON_SCOPE_READ, (uint8_t)first, 0, n };
        TK_CHECK(request(rq, 4) == 5u + 2u * n && reply[1] == 0, "chunk at %u", first);
        for (unsigned i = 0; i < n; i++) {
            got[first + i] = s16(5 + 2 * i);
        }
    }
    for (unsigned f = 0; f < 20; f++) {
        TK_CHECK(got[2 * f] == 100 * (int)f - 1000 && got[2 * f + 1] == -7 * (int)f,
                 "frame %u: %d %d", f, got[2 * f], got[2 * f + 1]);
    }
    TK_CHECK(REQ(FOC_MON_SCOPE_READ, 39, 0, 2) == 2 && reply[1] == FOC_MON_E_RANGE,
             "past the end refused");
    TK_CHECK(REQ(FOC_MON_SCOPE_READ, 0, 0, 17) == 2 && reply[1] == FOC_MON_E_RANGE,
             "chunk too large");
    TK_CHECK(REQ(FOC_MON_SCOPE_SET, 2, FOC_VAR_ID, FOC_VAR_COUNT, 1, 0, 0, 0, 0, 0, 0, 0, 0) == 2 &&
             reply[1] == FOC_MON_E_RANGE, "unknown channel variable");
    foc_mon_init(&mon, &ctrl, NULL);
    TK_CHECK(REQ(FOC_MON_SCOPE_ARM) == 2 && reply[1] == FOC_MON_E_NOSCOPE, "no scope");
}

static void case_random_bytes_never_crash(void)
{
    setup();
    uint32_t x = 12345u;
    for (int i = 0; i < 200000; i++) {
        x = x * 1664525u + 1013904223u;
        foc_mon_rx(&mon, (uint8_t)(x >> 24));
        uint8_t b;
        while (foc_mon_tx(&mon, &b) != 0u) {
        }
    }
    TK_CHECK(ctrl.req.start == 0u || ctrl.req.start == 1u, "survived");
    TK_CHECK(mon.link.dropped > 100u, "random frames dropped: %u", mon.link.dropped);
}

TK_CASES(TK_CASE(case_crc_check_value), TK_CASE(case_start_stop_ack_speed),
         TK_CASE(case_identify_and_status), TK_CASE(case_malformed_dropped),
         TK_CASE(case_table_and_writes), TK_CASE(case_scope_capture),
         TK_CASE(case_random_bytes_never_crash))
