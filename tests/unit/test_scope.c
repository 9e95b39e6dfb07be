/*
 * Scope capture (foc/scope.h) on a controller whose fields the test sets
 * by hand, one PWM period per foc_scope_tick(): idle cost, trigger edges,
 * pre-trigger, decimation, ring wrap, the variable table, configuration
 * rules and the debug-output selection.
 */
#include <stdint.h>
#include <string.h>

#include "foc/config.h"
#include "foc/scope.h"
#include "testkit.h"

/* The one port function the scope's inline helper calls. */
static q15_t dac_out[2];
static unsigned dac_calls;

void foc_port_debug_out(q15_t ch1, q15_t ch2)
{
    dac_out[0] = ch1;
    dac_out[1] = ch2;
    dac_calls++;
}

#define BUF_LEN 64u
static foc_ctrl_t ctrl;
static int16_t buf[BUF_LEN + 2u]; /* two guard samples after the buffer */
static foc_scope_t scope;

static void setup(void)
{
    memset(&ctrl, 0, sizeof ctrl);
    for (unsigned i = 0; i < BUF_LEN + 2u; i++) {
        buf[i] = (int16_t)0x5A5A;
    }
    foc_scope_init(&scope, &ctrl, buf, BUF_LEN);
}

static void one_channel(foc_var_t v)
{
    TK_CHECK(foc_scope_set_channels(&scope, &v, 1u) == FOC_SCOPE_OK, "channels");
}

/* One period with the estimated speed at `v`. */
static void period_speed(int16_t v)
{
    ctrl.est.est_speed = v;
    foc_scope_tick(&scope);
}

static void case_idle_costs_nothing(void)
{
    setup();
    for (int i = 0; i < 1000; i++) {
        period_speed((int16_t)i);
    }
    TK_CHECK(foc_scope_state(&scope) == FOC_SCOPE_IDLE, "still idle");
    for (unsigned i = 0; i < BUF_LEN + 2u; i++) {
        TK_CHECK(buf[i] == (int16_t)0x5A5A, "buf[%u] written while idle", i);
    }
    foc_scope_tick(NULL); /* no scope attached: nothing at all */
}

static void case_immediate_fills_in_order(void)
{
    setup();
    one_channel(FOC_VAR_SPEED_EST);
    TK_CHECK(foc_scope_frames(&scope) == BUF_LEN, "frames %u", foc_scope_frames(&scope));
    TK_CHECK(foc_scope_arm(&scope) == FOC_SCOPE_OK, "arm");
    for (int i = 0; i < (int)BUF_LEN; i++) {
        TK_CHECK(foc_scope_state(&scope) == (i == 0 ? FOC_SCOPE_ARMED : FOC_SCOPE_TRIGGERED),
                 "state %d at %d", (int)foc_scope_state(&scope), i);
        period_speed((int16_t)(100 + i));
    }
    TK_CHECK(foc_scope_state(&scope) == FOC_SCOPE_DONE, "done after exactly %u", BUF_LEN);
    period_speed(-1); /* DONE: nothing more is written */
    for (uint16_t f = 0; f < BUF_LEN; f++) {
        TK_CHECK(foc_scope_value(&scope, f, 0) == 100 + f, "frame %u = %d", f,
                 foc_scope_value(&scope, f, 0));
    }
    TK_CHECK(buf[BUF_LEN] == (int16_t)0x5A5A && buf[BUF_LEN + 1u] == (int16_t)0x5A5A,
             "guard samples intact");
    TK_CHECK(foc_scope_value(&scope, BUF_LEN, 0) == 0, "frame out of range reads 0");
    TK_CHECK(foc_scope_value(&scope, 0, 1) == 0, "channel out of range reads 0");
}

/* Drives a rising ramp through `level` after `flat` periods below it, with
 * the ring wrapping several times first; checks the trigger frame, the
 * pre-trigger frames before it and the post-trigger frames after it. */
static void rising_with_pretrigger(uint8_t pct, uint16_t flat)
{
    setup();
    const foc_var_t vars[2] = { FOC_VAR_SPEED_EST, FOC_VAR_IQ };
    TK_CHECK(foc_scope_set_channels(&scope, vars, 2u) == FOC_SCOPE_OK, "channels");
    TK_CHECK(foc_scope_set_trigger(&scope, FOC_VAR_SPEED_EST, FOC_TRIG_RISING, 1000) ==
                 FOC_SCOPE_OK, "trigger");
    TK_CHECK(foc_scope_set_pretrigger(&scope, pct) == FOC_SCOPE_OK, "pre");
    const uint16_t frames = BUF_LEN / 2u;
    uint16_t pre = (uint16_t)(frames * pct / 100u);
    pre = pre >= frames ? (uint16_t)(frames - 1u) : pre;
    TK_CHECK(foc_scope_pre_frames(&scope) == pre, "pre %u", foc_scope_pre_frames(&scope));
    TK_CHECK(foc_scope_arm(&scope) == FOC_SCOPE_OK, "arm");
    /* period n: speed = n (below 1000 while n < flat), iq = -n */
    int32_t n = 0;
    int32_t trigger_n = -1;
    while (foc_scope_state(&scope) != FOC_SCOPE_DONE && n < 5000) {
        const int16_t v = (int16_t)(n < flat ? n % 900 : 990 + 5 * (n - flat));
        ctrl.i_dq.q = (int16_t)-n;
        const foc_scope_state_t before = foc_scope_state(&scope);
        period_speed(v);
        if (before == FOC_SCOPE_ARMED && foc_scope_state(&scope) != FOC_SCOPE_ARMED) {
            trigger_n = n;
        }
        n++;
    }
    TK_CHECK(foc_scope_state(&scope) == FOC_SCOPE_DONE, "done");
    TK_CHECK(trigger_n == flat + 2, "trigger at period %ld (first >= 1000: %u)",
             (long)trigger_n, flat + 2u);
    TK_CHECK(n - 1 - trigger_n == frames - pre - 1, "%ld frames after the trigger",
             (long)(n - 1 - trigger_n));
    for (uint16_t f = 0; f < frames; f++) {
        const int32_t period = trigger_n + (int32_t)f - pre;
        TK_CHECK(foc_scope_value(&scope, f, 1) == (int16_t)-period, "frame %u iq %d, want %ld",
                 f, foc_scope_value(&scope, f, 1), (long)-period);
    }
    TK_CHECK(foc_scope_value(&scope, pre, 0) >= 1000, "trigger frame at/above level");
    if (pre > 0u) {
        TK_CHECK(foc_scope_value(&scope, (uint16_t)(pre - 1u), 0) < 1000, "frame before below");
    }
}

static void case_rising_pretrigger_and_wrap(void)
{
    rising_with_pretrigger(25u, 200u); /* armed 200 periods: ring of 32 wraps */
    rising_with_pretrigger(0u, 77u);
    rising_with_pretrigger(50u, 33u);
    rising_with_pretrigger(100u, 100u); /* trigger frame is the last one */
}

static void case_edges(void)
{
    static const struct {
        foc_trig_edge_t edge;
        int16_t seq[6];
        int fires_at; /* index in seq, -1: never */
    } cases[] = {
        { FOC_TRIG_RISING, { 0, 5, 9, 10, 11, 20 }, 3 },   /* 9 -> 10 crosses */
        { FOC_TRIG_RISING, { 10, 11, 10, 12, 20, 30 }, -1 }, /* never below */
        { FOC_TRIG_RISING, { 20, 15, 5, 0, -5, -20 }, -1 },
        { FOC_TRIG_FALLING, { 20, 15, 10, 9, 0, -5 }, 3 }, /* 10 -> 9 */
        { FOC_TRIG_FALLING, { 0, 5, 10, 20, 30, 40 }, -1 },
        { FOC_TRIG_EITHER, { 20, 15, 12, 11, 9, 5 }, 4 },
        { FOC_TRIG_EITHER, { -3, 0, 5, 10, 9, 5 }, 3 },
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        setup();
        one_channel(FOC_VAR_SPEED_EST);
        TK_CHECK(foc_scope_set_trigger(&scope, FOC_VAR_SPEED_EST, cases[c].edge, 10) ==
                     FOC_SCOPE_OK, "trigger");
        TK_CHECK(foc_scope_arm(&scope) == FOC_SCOPE_OK, "arm");
        int fired = -1;
        for (int i = 0; i < 6; i++) {
            period_speed(cases[c].seq[i]);
            if (fired < 0 && foc_scope_state(&scope) != FOC_SCOPE_ARMED) {
                fired = i;
            }
        }
        TK_CHECK(fired == cases[c].fires_at, "case %zu fired at %d, want %d", c, fired,
                 cases[c].fires_at);
    }
}

/* The first frame after arming has no predecessor: no edge there, even if
 * the value before arming was below the level. */
static void case_edge_needs_two_frames(void)
{
    setup();
    one_channel(FOC_VAR_SPEED_EST);
    (void)foc_scope_set_trigger(&scope, FOC_VAR_SPEED_EST, FOC_TRIG_RISING, 10);
    period_speed(0);
    (void)foc_scope_arm(&scope);
    period_speed(50);
    TK_CHECK(foc_scope_state(&scope) == FOC_SCOPE_ARMED, "no trigger on the first frame");
    period_speed(0);
    period_speed(50);
    TK_CHECK(foc_scope_state(&scope) == FOC_SCOPE_TRIGGERED, "then it does");
}

/* A crossing before the pre-trigger frames are stored is not a trigger. */
static void case_crossing_during_pretrigger_ignored(void)
{
    setup();
    one_channel(FOC_VAR_SPEED_EST); /* 64 frames */
    (void)foc_scope_set_trigger(&scope, FOC_VAR_SPEED_EST, FOC_TRIG_RISING, 10);
    (void)foc_scope_set_pretrigger(&scope, 50u); /* 32 frames before */
    (void)foc_scope_arm(&scope);
    for (int i = 0; i < 32; i++) {
        period_speed(i % 2 == 0 ? 0 : 20); /* crossings in frames 1..31 */
        TK_CHECK(foc_scope_state(&scope) == FOC_SCOPE_ARMED, "armed at frame %d", i);
    }
    period_speed(0);
    period_speed(20); /* frame 33: 33 frames before it */
    TK_CHECK(foc_scope_state(&scope) == FOC_SCOPE_TRIGGERED, "trigger once 32 precede");
}

static void case_decimation(void)
{
    setup();
    one_channel(FOC_VAR_SPEED_EST);
    TK_CHECK(foc_scope_set_decimation(&scope, 3u) == FOC_SCOPE_OK, "decim");
    (void)foc_scope_set_trigger(&scope, FOC_VAR_SPEED_EST, FOC_TRIG_RISING, 100);
    (void)foc_scope_set_pretrigger(&scope, 25u); /* 16 frames */
    (void)foc_scope_arm(&scope);
    /* period n: value n; stored periods are 0, 3, 6, ...; 100 is crossed
     * between stored periods 99 and 102: the trigger is the frame of 102. */
    int n = 0;
    for (; n < 1000 && foc_scope_state(&scope) != FOC_SCOPE_DONE; n++) {
        period_speed((int16_t)n);
    }
    TK_CHECK(foc_scope_state(&scope) == FOC_SCOPE_DONE, "done");
    TK_CHECK(foc_scope_value(&scope, 16u, 0) == 102, "trigger frame %d",
             foc_scope_value(&scope, 16u, 0));
    for (uint16_t f = 0; f < 64u; f++) {
        TK_CHECK(foc_scope_value(&scope, f, 0) == 102 + 3 * ((int)f - 16), "frame %u = %d", f,
                 foc_scope_value(&scope, f, 0));
    }
    TK_CHECK(n - 1 == 102 + 3 * 47, "last frame at period %d", n - 1);
}

/* Angles are unsigned: 65535 is above 32768, and the wrap 65000 -> 100 is
 * a falling crossing of 180 deg. */
static void case_unsigned_angle_trigger(void)
{
    setup();
    one_channel(FOC_VAR_THETA_EST);
    TK_CHECK(foc_scope_set_trigger(&scope, FOC_VAR_THETA_EST, FOC_TRIG_RISING, 32768) ==
                 FOC_SCOPE_OK, "level 180 deg");
    TK_CHECK(foc_scope_set_trigger(&scope, FOC_VAR_THETA_EST, FOC_TRIG_RISING, 65536) ==
                 FOC_SCOPE_EINVAL, "level 360 deg out of range");
    TK_CHECK(foc_scope_set_trigger(&scope, FOC_VAR_THETA_EST, FOC_TRIG_RISING, -1) ==
                 FOC_SCOPE_EINVAL, "negative level for an angle");
    (void)foc_scope_set_trigger(&scope, FOC_VAR_THETA_EST, FOC_TRIG_RISING, 32768);
    (void)foc_scope_arm(&scope);
    static const uint16_t up[] = { 30000, 32767, 32768 };
    for (size_t i = 0; i < 3; i++) {
        ctrl.est.est_theta = up[i];
        foc_scope_tick(&scope);
    }
    TK_CHECK(foc_scope_state(&scope) == FOC_SCOPE_TRIGGERED, "32767 -> 32768 rises");

    setup();
    one_channel(FOC_VAR_THETA_EST);
    (void)foc_scope_set_trigger(&scope, FOC_VAR_THETA_EST, FOC_TRIG_FALLING, 32768);
    (void)foc_scope_arm(&scope);
    static const uint16_t wrap[] = { 60000, 65000, 100 };
    for (size_t i = 0; i < 3; i++) {
        ctrl.est.est_theta = wrap[i];
        foc_scope_tick(&scope);
        TK_CHECK((foc_scope_state(&scope) == FOC_SCOPE_ARMED) == (i < 2), "wrap at %zu", i);
    }
}

/* Every variable reads its own field. */
static void case_channel_table(void)
{
    setup();
    ctrl.samples.i_a = 1;
    ctrl.samples.i_b = 2;
    ctrl.samples.i_c = 3;
    ctrl.i_ab.alpha = 4;
    ctrl.i_ab.beta = 5;
    ctrl.i_dq.d = 6;
    ctrl.i_dq.q = 7;
    ctrl.i_ref.d = 8;
    ctrl.i_ref.q = 9;
    ctrl.v_dq.d = 10;
    ctrl.v_dq.q = 11;
    ctrl.v_ab.alpha = 12;
    ctrl.v_ab.beta = 13;
    ctrl.est.theta = 65000u;
    ctrl.est.est_theta = 15;
    ctrl.samples.theta_sensor = 16;
    ctrl.est.speed = 17;
    ctrl.est.est_speed = 18;
    ctrl.speed_ctrl.ramped = 19;
    ctrl.req.speed = 20;
    ctrl.startup.speed = 21;
    ctrl.samples.vdc = 22;
    ctrl.samples.temp = 23;
    ctrl.samples.pot = 24;
    ctrl.duty.a = 25;
    ctrl.duty.b = 26;
    ctrl.duty.c = 27;
    ctrl.state = FOC_STATE_RUN;
    ctrl.faults.active = 0x8001u;
    static const int32_t want[FOC_VAR_COUNT] = {
        1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 65000, 15, 16, 17, 18, 19, 20, 21,
        22, 23, 24, 25, 26, 27, FOC_STATE_RUN, 0x8001,
    };
    for (int v = 0; v < (int)FOC_VAR_COUNT; v++) {
        const foc_var_info_t *info = foc_var_info((foc_var_t)v);
        TK_CHECK(info != NULL && info->name != NULL && foc_var_scale(info)->unit != NULL, "info %d", v);
        TK_CHECK(foc_var_find(info->name) == v, "find %s", info->name);
        TK_CHECK(foc_var_scale(info)->full_scale_nano > 0, "%s full scale", info->name);
        one_channel((foc_var_t)v);
        (void)foc_scope_arm(&scope);
        foc_scope_tick(&scope); /* 64 frames: the first is frame 0 */
        while (foc_scope_state(&scope) != FOC_SCOPE_DONE) {
            foc_scope_tick(&scope);
        }
        const int16_t raw = foc_scope_value(&scope, 0, 0);
        const int32_t got = info->is_unsigned ? (int32_t)(uint16_t)raw : (int32_t)raw;
        TK_CHECK(got == want[v], "%s reads %ld, want %ld", info->name, (long)got, (long)want[v]);
        for (int w = 0; w < v; w++) {
            TK_CHECK(strcmp(foc_var_info((foc_var_t)w)->name, info->name) != 0, "unique %s",
                     info->name);
        }
    }
    TK_CHECK(foc_var_info(FOC_VAR_COUNT) == NULL, "past the table");
    TK_CHECK(foc_var_find("nope") == -1 && foc_var_find("") == -1 && foc_var_find("i") == -1,
             "unknown names");
    /* the full scales are the per-unit bases of config.h */
    TK_CHECK(foc_var_scale(foc_var_info(FOC_VAR_IQ))->full_scale_nano == (int64_t)(FOC_I_BASE_A * 1e9 + 0.5),
             "current base");
    TK_CHECK(foc_var_scale(foc_var_info(FOC_VAR_VQ))->full_scale_nano == (int64_t)(FOC_V_BASE_V * 1e9 + 0.5),
             "voltage base");
    TK_CHECK(foc_var_scale(foc_var_info(FOC_VAR_SPEED))->full_scale_nano ==
                 (int64_t)(SPEED_BASE_RPM * 1e9 + 0.5), "speed base");
    TK_CHECK(foc_var_scale(foc_var_info(FOC_VAR_THETA))->full_scale_nano == 180000000000LL &&
                 foc_var_info(FOC_VAR_THETA)->is_unsigned, "angle: 32768 = 180 deg");
    TK_CHECK(foc_var_scale(foc_var_info(FOC_VAR_STATE))->full_scale_nano == 32768000000000LL,
             "state: value = counts");
}

static void case_configuration_rules(void)
{
    setup();
    const foc_var_t five[5] = { FOC_VAR_IA, FOC_VAR_IB, FOC_VAR_IC, FOC_VAR_ID, FOC_VAR_IQ };
    const foc_var_t bad = FOC_VAR_COUNT;
    TK_CHECK(foc_scope_set_channels(&scope, five, 0u) == FOC_SCOPE_EINVAL, "0 channels");
    TK_CHECK(foc_scope_set_channels(&scope, five, 5u) == FOC_SCOPE_EINVAL, "5 channels");
    TK_CHECK(foc_scope_set_channels(&scope, &bad, 1u) == FOC_SCOPE_EINVAL, "bad variable");
    TK_CHECK(foc_scope_set_channels(&scope, five, 3u) == FOC_SCOPE_OK, "3 channels");
    TK_CHECK(foc_scope_frames(&scope) == BUF_LEN / 3u, "frames = len / channels");
    TK_CHECK(foc_scope_set_decimation(&scope, 0u) == FOC_SCOPE_EINVAL, "decim 0");
    TK_CHECK(foc_scope_set_pretrigger(&scope, 101u) == FOC_SCOPE_EINVAL, "pre 101");
    TK_CHECK(foc_scope_set_trigger(&scope, FOC_VAR_IQ, FOC_TRIG_RISING, 32768) ==
                 FOC_SCOPE_EINVAL, "signed level 32768");
    TK_CHECK(foc_scope_set_trigger(&scope, FOC_VAR_IQ, (foc_trig_edge_t)7, 0) ==
                 FOC_SCOPE_EINVAL, "bad edge");
    TK_CHECK(foc_scope_set_trigger(&scope, FOC_VAR_COUNT, FOC_TRIG_RISING, 0) ==
                 FOC_SCOPE_EINVAL, "bad trigger variable");

    (void)foc_scope_set_trigger(&scope, FOC_VAR_IQ, FOC_TRIG_RISING, 100);
    TK_CHECK(foc_scope_arm(&scope) == FOC_SCOPE_OK, "arm");
    TK_CHECK(foc_scope_arm(&scope) == FOC_SCOPE_EBUSY, "arm twice");
    TK_CHECK(foc_scope_set_channels(&scope, five, 1u) == FOC_SCOPE_EBUSY, "busy channels");
    TK_CHECK(foc_scope_set_decimation(&scope, 2u) == FOC_SCOPE_EBUSY, "busy decim");
    TK_CHECK(foc_scope_set_pretrigger(&scope, 2u) == FOC_SCOPE_EBUSY, "busy pre");
    TK_CHECK(foc_scope_set_trigger(&scope, FOC_VAR_IQ, FOC_TRIG_IMMEDIATE, 0) ==
                 FOC_SCOPE_EBUSY, "busy trigger");
    TK_CHECK(foc_scope_set_dac(&scope, 0u, FOC_VAR_VQ) == FOC_SCOPE_OK, "DAC any time");
    foc_scope_stop(&scope);
    TK_CHECK(foc_scope_state(&scope) == FOC_SCOPE_IDLE, "stop -> idle");
    TK_CHECK(foc_scope_value(&scope, 0, 0) == 0, "nothing to read when idle");

    /* a finished capture survives stop and is discarded by a change */
    (void)foc_scope_set_trigger(&scope, FOC_VAR_IQ, FOC_TRIG_IMMEDIATE, 0);
    (void)foc_scope_arm(&scope);
    for (unsigned i = 0; i < BUF_LEN; i++) {
        foc_scope_tick(&scope);
    }
    TK_CHECK(foc_scope_state(&scope) == FOC_SCOPE_DONE, "done");
    foc_scope_stop(&scope);
    TK_CHECK(foc_scope_state(&scope) == FOC_SCOPE_DONE, "stop keeps a finished capture");
    TK_CHECK(foc_scope_set_decimation(&scope, 0u) == FOC_SCOPE_EINVAL &&
                 foc_scope_state(&scope) == FOC_SCOPE_DONE, "a refused change keeps it");
    TK_CHECK(foc_scope_set_decimation(&scope, 2u) == FOC_SCOPE_OK &&
                 foc_scope_state(&scope) == FOC_SCOPE_IDLE, "a change discards it");
    TK_CHECK(foc_scope_arm(&scope) == FOC_SCOPE_OK, "re-arm from idle");
    TK_CHECK(strcmp(foc_scope_state_name(FOC_SCOPE_TRIGGERED), "TRIGGERED") == 0 &&
                 strcmp(foc_scope_state_name((foc_scope_state_t)9), "?") == 0, "names");
}

/* A buffer smaller than one frame cannot capture; the DAC still works. */
static void case_tiny_buffers(void)
{
    memset(&ctrl, 0, sizeof ctrl);
    foc_scope_init(&scope, &ctrl, NULL, 100u);
    TK_CHECK(foc_scope_frames(&scope) == 0u && foc_scope_arm(&scope) == FOC_SCOPE_EINVAL,
             "no buffer");
    foc_scope_init(&scope, &ctrl, buf, 3u);
    const foc_var_t four[4] = { FOC_VAR_IA, FOC_VAR_IB, FOC_VAR_IC, FOC_VAR_ID };
    (void)foc_scope_set_channels(&scope, four, 4u);
    TK_CHECK(foc_scope_arm(&scope) == FOC_SCOPE_EINVAL, "3 samples, 4 channels");
    (void)foc_scope_set_channels(&scope, four, 3u);
    (void)foc_scope_set_pretrigger(&scope, 100u);
    TK_CHECK(foc_scope_pre_frames(&scope) == 0u, "one frame: no pre-trigger");
    ctrl.samples.i_a = 7;
    TK_CHECK(foc_scope_arm(&scope) == FOC_SCOPE_OK, "one frame");
    foc_scope_tick(&scope);
    TK_CHECK(foc_scope_state(&scope) == FOC_SCOPE_DONE && foc_scope_value(&scope, 0, 0) == 7,
             "done in one period");
}

static void case_dac_selection(void)
{
    setup();
    ctrl.i_dq.d = 11;
    ctrl.i_dq.q = 22;
    ctrl.v_dq.q = 33;
    ctrl.state = FOC_STATE_FAULT;
    dac_calls = 0;
    foc_scope_debug_out(NULL, &ctrl);
    TK_CHECK(dac_calls == 1 && dac_out[0] == 11 && dac_out[1] == 22, "no scope: id, iq");
    foc_scope_debug_out(&scope, &ctrl);
    TK_CHECK(dac_out[0] == 11 && dac_out[1] == 22, "default id, iq");
    TK_CHECK(foc_scope_set_dac(&scope, 0u, FOC_VAR_VQ) == FOC_SCOPE_OK &&
                 foc_scope_set_dac(&scope, 1u, FOC_VAR_STATE) == FOC_SCOPE_OK, "select");
    TK_CHECK(foc_scope_set_dac(&scope, 2u, FOC_VAR_VQ) == FOC_SCOPE_EINVAL &&
                 foc_scope_set_dac(&scope, 0u, FOC_VAR_COUNT) == FOC_SCOPE_EINVAL, "bad");
    foc_scope_debug_out(&scope, &ctrl);
    TK_CHECK(dac_out[0] == 33 && dac_out[1] == FOC_STATE_FAULT, "vq, state: %d %d",
             dac_out[0], dac_out[1]);
    q15_t a = 0, b = 0;
    ctrl.state = FOC_STATE_RUN;
    foc_scope_dac(&scope, &a, &b);
    TK_CHECK(a == 33 && b == FOC_STATE_RUN, "pull: %d %d", a, b);
}

TK_CASES(TK_CASE(case_idle_costs_nothing), TK_CASE(case_immediate_fills_in_order),
         TK_CASE(case_rising_pretrigger_and_wrap), TK_CASE(case_edges),
         TK_CASE(case_edge_needs_two_frames), TK_CASE(case_crossing_during_pretrigger_ignored),
         TK_CASE(case_decimation), TK_CASE(case_unsigned_angle_trigger),
         TK_CASE(case_channel_table), TK_CASE(case_configuration_rules),
         TK_CASE(case_tiny_buffers), TK_CASE(case_dac_selection))
