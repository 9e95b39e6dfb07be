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
#include <math.h>
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
void foc_port_pwm_enable_at_half(void) {}
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
    TK_CHECK(ctrl.req.asked.start == 1u, "start requested");
    TK_CHECK(REQ(FOC_MON_STOP) == 2 && ctrl.req.asked.stop == 1u, "stop requested");
    TK_CHECK(REQ(FOC_MON_ACK) == 2 && ctrl.req.asked.ack == 1u, "ack requested");
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
    TK_CHECK(take_reply() == 0 && ctrl.req.asked.start == 0u, "bad CRC: no reply, not executed");
    /* a block that says 5 bytes but the frame ends after 2 */
    uint8_t raw[3] = { FOC_MON_START, 0, 0 };
    const uint16_t crc = ref_crc(raw, 1);
    uint8_t broken[] = { 0x06, FOC_MON_START, (uint8_t)crc, 0x00 };
    feed(broken, sizeof broken);
    TK_CHECK(take_reply() == 0 && ctrl.req.asked.start == 0u, "truncated COBS block dropped");
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
             ctrl.req.asked.commission == 0u, "commissioning refused outside IDLE");
}

/* var info / read / write of entry i, built at run time. */
static size_t info(uint8_t i)
{
    const uint8_t rq[2] = { FOC_MON_VAR_INFO, i };
    return request(rq, sizeof rq);
}

static size_t write16(uint8_t i, uint16_t v)
{
    const uint8_t rq[4] = { FOC_MON_VAR_WRITE, i, (uint8_t)(v & 0xFFu), (uint8_t)(v >> 8) };
    return request(rq, sizeof rq);
}

static int32_t read16(uint8_t i)
{
    const uint8_t rq[2] = { FOC_MON_VAR_READ, i };
    return (request(rq, sizeof rq) == 5 && reply[1] == 0) ? (int32_t)u16(3) : -1;
}

/* The parameter named `name`: its index, and its info (flags, max, full
 * scale); 0 if none. */
typedef struct {
    uint8_t index, flags;
    uint16_t max;
    double fs; /* physical value of 32768 counts */
} param_info_t;

static param_info_t find_param(const char *name)
{
    param_info_t p = { 0, 0, 0, 0.0 };
    for (uint8_t i = FOC_MON_PARAM_BASE; i < FOC_MON_PARAM_BASE + FOC_MON_PARAMS; i++) {
        if (info(i) > 16 && reply[1] == 0 && strcmp((const char *)&reply[15], name) == 0) {
            int64_t fs = 0;
            for (int k = 7; k >= 0; k--) {
                fs = fs * 256 + reply[7 + k];
            }
            p.index = i;
            p.flags = reply[4];
            p.max = u16(5);
            p.fs = (double)fs * 1e-9;
        }
    }
    return p;
}

/* A gain read through the monitor in its unit. */
static double gain_value(param_info_t p)
{
    return (double)read16(p.index) * p.fs / 32768.0;
}

static void case_gains(void)
{
    setup();
    /* Every gain: writable, its range the mantissa's (a proportional
     * gain's up to 2.0: 65535; an integral gain's, an observer's: Q15 or
     * less), and the build's value reads back in its unit as userparms.h
     * gives it (within the mantissa's resolution, 2^-14 of full scale). */
    static const char *const pi_gains[] = { "speed_kp", "speed_ki", "current_kp", "current_ki",
                                            "fw_kp", "fw_ki" };
    static const char *const obs_gains[] = { "luen_pll_kp", "luen_pll_ki", "pll_track_gain",
                                             "flux_corr_min", "flux_corr_speed" };
    for (size_t k = 0; k < sizeof pi_gains / sizeof pi_gains[0]; k++) {
        const param_info_t p = find_param(pi_gains[k]);
        const uint16_t max = (k % 2u == 0u) ? 65535u : 32767u; /* kp, ki */
        TK_CHECK(p.index != 0 && p.flags == 3u && p.max == max && p.fs > 0.0,
                 "%s: index %u, writable while running, max %u", pi_gains[k], p.index, max);
    }
    for (size_t k = 0; k < sizeof obs_gains / sizeof obs_gains[0]; k++) {
        const param_info_t p = find_param(obs_gains[k]);
        TK_CHECK(p.index != 0 && p.flags == 1u && p.max <= 32767u && p.fs > 0.0,
                 "%s: index %u, writable only stopped", obs_gains[k], p.index);
    }
    const param_info_t kp = find_param("speed_kp");
    const param_info_t ki = find_param("speed_ki");
    const param_info_t ckp = find_param("current_kp");
    const param_info_t fkp = find_param("fw_kp");
    const param_info_t fmin = find_param("flux_corr_min");
    TK_CHECK(fabs(gain_value(kp) - SPEED_KP_A_PER_RPM) <= kp.fs / 16384.0, "speed_kp %g A/rpm",
             gain_value(kp));
    TK_CHECK(fabs(gain_value(ki) - SPEED_KI_A_PER_RPM_S) <= ki.fs / 16384.0,
             "speed_ki %g A/(rpm s)", gain_value(ki));
    TK_CHECK(fabs(gain_value(ckp) - CURRENT_KP_V_PER_A) <= ckp.fs / 16384.0, "current_kp %g V/A",
             gain_value(ckp));
    TK_CHECK(fabs(gain_value(fkp) - FW_VOLTAGE_KP_A_PER_V) <= fkp.fs / 16384.0, "fw_kp %g A/V",
             gain_value(fkp));
    TK_CHECK(fabs(gain_value(fmin) - FLUX_CORR_MIN_RAD_S) <= fmin.fs / 16384.0,
             "flux_corr_min %g rad/s", gain_value(fmin));

    /* A speed gain while running: range-checked, written, read back, and
     * the loop uses it: with kp = ki = 0 the output is the integrator's
     * preset whatever the error; with the build's gains it is not; with
     * kp at its largest, twice the full scale, the step is kp e exactly. */
    ctrl.state = FOC_STATE_RUN;
    const uint16_t kp0 = (uint16_t)read16(kp.index);
    const uint16_t ki0 = (uint16_t)read16(ki.index);
    TK_CHECK(write16(ki.index, 32768u) == 2 && reply[1] == FOC_MON_E_RANGE &&
             ctrl.speed_ctrl.gains.ki == (q15_t)ki0, "speed_ki 32768 refused");
    foc_speed_ctrl_t sc = ctrl.speed_ctrl;
    foc_sc_preset(&sc, 1000, 2000);
    sc.target = 1000;
    const q15_t iq_build = foc_sc_step(&sc, 700, 0);
    TK_CHECK(write16(kp.index, 0u) == 2 && reply[1] == 0 && write16(ki.index, 0u) == 2 &&
             reply[1] == 0 && read16(kp.index) == 0 && read16(ki.index) == 0,
             "speed_kp, speed_ki written while running, read back 0");
    sc = ctrl.speed_ctrl;
    foc_sc_preset(&sc, 1000, 2000);
    sc.target = 1000;
    const q15_t iq_zero = foc_sc_step(&sc, 700, 0);
    TK_CHECK(iq_build > 2000 && iq_zero == 2000, "speed PI output %d with the build's gains, %d "
             "with none", iq_build, iq_zero);
    TK_CHECK(write16(kp.index, 65535u) == 2 && reply[1] == 0 && read16(kp.index) == 65535,
             "speed_kp 65535 written");
    sc = ctrl.speed_ctrl;
    foc_sc_preset(&sc, 0, 0);
    sc.target = 0;
    const q15_t e = -8;
    const q15_t iq_max = foc_sc_step(&sc, (q15_t)-e, 0); /* error e, no integral */
    const double want = floor(65535.0 * ldexp(1.0, FOC_SPEED_KP_SHIFT) * e / 32768.0 + 0.5);
    TK_CHECK(iq_max == (q15_t)want, "speed PI at kp 65535: %d, want %.0f", iq_max, want);
    TK_CHECK(write16(kp.index, kp0) == 2 && reply[1] == 0 && write16(ki.index, ki0) == 2 &&
             reply[1] == 0 && ctrl.speed_ctrl.gains.kp == kp0 && ctrl.speed_ctrl.gains.ki == ki0,
             "speed gains restored");
    /* the current PI's: written while running, used by the inline step;
     * not below Kref (the reference path's gain Kp - Kref >= 0), whose
     * mantissa is computed here from the build's figures */
    const double kref_pu = MOTOR_LQ_H * (FOC_CURRENT_DIST_RAD_S - FOC_CURRENT_ZERO_RAD_S) *
                           FOC_I_BASE_A / FOC_V_BASE_V;
    const uint16_t kref_mant = (uint16_t)ceil(kref_pu / ldexp(1.0, FOC_CURRENT_KP_SHIFT) * 32768.0);
    const uint16_t ckp0 = (uint16_t)read16(ckp.index);
    TK_CHECK(kref_mant > 0u && write16(ckp.index, (uint16_t)(kref_mant - 1u)) == 2 &&
                 reply[1] == FOC_MON_E_RANGE && ctrl.current_ctrl.gains.kp == (int32_t)ckp0,
             "current_kp %u below Kref %u refused", kref_mant - 1u, kref_mant);
    TK_CHECK(write16(ckp.index, kref_mant) == 2 && reply[1] == 0 &&
             ctrl.current_ctrl.gains.kp == (int32_t)kref_mant, "current_kp at Kref written while running");

    /* An observer's gain: refused while running, written stopped, and the
     * estimator takes it at its next restart. */
    const param_info_t lkp = find_param("luen_pll_kp");
    const param_info_t track = find_param("pll_track_gain");
    TK_CHECK(write16(lkp.index, 1000u) == 2 && reply[1] == FOC_MON_E_RUNNING &&
             ctrl.est.gains.luen_kp != 1000, "luen_pll_kp refused while running");
    ctrl.state = FOC_STATE_IDLE;
    TK_CHECK(write16(track.index, (uint16_t)(track.max + 1u)) == 2 && reply[1] == FOC_MON_E_RANGE,
             "pll_track_gain beyond %u refused", track.max);
    TK_CHECK(write16(lkp.index, 1000u) == 2 && reply[1] == 0 && write16(track.index, 99u) == 2 &&
             reply[1] == 0 && write16(fmin.index, 777u) == 2 && reply[1] == 0,
             "observer gains written in IDLE");
    TK_CHECK(foc_est_select(&ctrl.est, FOC_EST_LUENBERGER) == 0, "luenberger built");
    foc_est_reset(&ctrl.est, 0, 0);
    TK_CHECK(ctrl.est.u.luenberger.pll_kp == 1000, "the observer runs with it after a restart");
    TK_CHECK(foc_est_select(&ctrl.est, FOC_EST_PLL) == 0, "pll built");
    foc_est_reset(&ctrl.est, 0, 0);
    TK_CHECK(ctrl.est.u.pll.track_gain == 99, "the PLL too");
    TK_CHECK(foc_est_select(&ctrl.est, FOC_EST_FLUX) == 0, "flux built");
    foc_est_reset(&ctrl.est, 0, 0);
    TK_CHECK(ctrl.est.u.flux.corr_min == 777, "the flux estimator too");
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
    TK_CHECK(mon.link.dropped > 100u, "random frames dropped: %u", mon.link.dropped);
}

TK_CASES(TK_CASE(case_crc_check_value), TK_CASE(case_start_stop_ack_speed),
         TK_CASE(case_identify_and_status), TK_CASE(case_malformed_dropped),
         TK_CASE(case_table_and_writes), TK_CASE(case_gains), TK_CASE(case_scope_capture),
         TK_CASE(case_random_bytes_never_crash))
