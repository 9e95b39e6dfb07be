/*
 * dsPICDEM MCLV user interface logic (boards/dspicdem_mclv/mclv_ui.c):
 * debouncing, S2's request per state, the potentiometer's speed range,
 * the LED patterns.
 */
#include "mclv_ui.h"
#include "testkit.h"

/* Feeds n samples of one level; returns the number of press edges. */
static int hold(mclv_button_t *b, uint8_t pressed, int n)
{
    int edges = 0;
    for (int i = 0; i < n; i++) {
        edges += mclv_button_update(b, pressed);
    }
    return edges;
}

static void case_debounce(void)
{
    mclv_button_t b;
    mclv_button_init(&b);
    TK_CHECK(hold(&b, 0, 100) == 0, "released: nothing");
    /* contact bounce: never MCLV_DEBOUNCE_MS equal samples in a row */
    for (int i = 0; i < 50; i++) {
        TK_CHECK(hold(&b, 1, (int)MCLV_DEBOUNCE_MS - 1) == 0, "bounce %d", i);
        TK_CHECK(hold(&b, 0, 1) == 0, "bounce %d", i);
    }
    /* a clean press: exactly one edge, on the MCLV_DEBOUNCE_MS-th sample */
    TK_CHECK(hold(&b, 1, (int)MCLV_DEBOUNCE_MS - 1) == 0, "not yet");
    TK_CHECK(hold(&b, 1, 1) == 1, "press edge");
    TK_CHECK(hold(&b, 1, 1000) == 0, "held: no repeat");
    TK_CHECK(b.stable == 1, "stable pressed");
    /* release (no edge), then a second press */
    TK_CHECK(hold(&b, 0, (int)MCLV_DEBOUNCE_MS) == 0 && b.stable == 0, "release");
    TK_CHECK(hold(&b, 1, (int)MCLV_DEBOUNCE_MS) == 1, "second press");
    /* a release glitch while held does not repeat the press */
    TK_CHECK(hold(&b, 0, 3) == 0 && hold(&b, 1, 100) == 0, "glitch while held");
}

static void case_s2_actions(void)
{
    TK_CHECK(mclv_s2_action(FOC_STATE_IDLE) == MCLV_S2_START, "IDLE");
    TK_CHECK(mclv_s2_action(FOC_STATE_CALIB) == MCLV_S2_STOP, "CALIB");
    TK_CHECK(mclv_s2_action(FOC_STATE_ALIGN) == MCLV_S2_STOP, "ALIGN");
    TK_CHECK(mclv_s2_action(FOC_STATE_OPENLOOP) == MCLV_S2_STOP, "OPENLOOP");
    TK_CHECK(mclv_s2_action(FOC_STATE_RUN) == MCLV_S2_STOP, "RUN");
    TK_CHECK(mclv_s2_action(FOC_STATE_STOP) == MCLV_S2_NOTHING, "STOP");
    TK_CHECK(mclv_s2_action(FOC_STATE_BRAKE) == MCLV_S2_NOTHING, "BRAKE");
    TK_CHECK(mclv_s2_action(FOC_STATE_FAULT) == MCLV_S2_ACK, "FAULT");
}

static void case_pot_range(void)
{
    TK_CHECK(mclv_pot_to_rpm(0, 500, 2000) == 500, "pot at 0");
    TK_CHECK(mclv_pot_to_rpm(-5, 500, 2000) == 500, "below 0");
    TK_CHECK(mclv_pot_to_rpm(16384, 500, 2000) == 1250, "half");
    TK_CHECK(mclv_pot_to_rpm(32767, 500, 2000) == 1999, "full travel");
    TK_CHECK(mclv_pot_to_rpm(32767, 500, 3500) == 3499, "field-weakening range");
    TK_CHECK(mclv_pot_to_rpm(32767, 0, 65535) == 65533, "widest span");
    TK_CHECK(mclv_pot_to_rpm(20000, 800, 800) == 800, "empty span");
    int32_t prev = 0;
    for (int32_t p = 0; p <= 32767; p++) {
        const int32_t r = mclv_pot_to_rpm((q15_t)p, 500, 3500);
        TK_CHECK(r >= prev && r >= 500 && r < 3500, "pot %ld -> %ld", (long)p, (long)r);
        prev = r;
    }
}

static void case_leds(void)
{
    int on_run = 0;
    int on_idle = 0;
    int toggles_fault = 0;
    int toggles_start = 0;
    for (uint16_t ms = 0; ms < 1000u; ms++) {
        on_run += mclv_led_run(FOC_STATE_RUN, ms);
        on_idle += mclv_led_run(FOC_STATE_IDLE, ms);
        toggles_fault += mclv_led_run(FOC_STATE_FAULT, ms) != mclv_led_run(FOC_STATE_FAULT, (uint16_t)(ms + 1u));
        toggles_start +=
            mclv_led_run(FOC_STATE_OPENLOOP, ms) != mclv_led_run(FOC_STATE_OPENLOOP, (uint16_t)(ms + 1u));
    }
    TK_CHECK(on_run == 1000 && on_idle == 0, "steady: run %d idle %d", on_run, on_idle);
    TK_CHECK(toggles_fault == 20, "10 Hz in FAULT: %d toggles/s", toggles_fault);
    TK_CHECK(toggles_start == 8, "4 Hz while starting: %d toggles/s", toggles_start);
}

static void case_rpm_conversion(void)
{
    TK_CHECK(mclv_rpm_to_q15(3000, 6000) == 16384, "half base");
    TK_CHECK(mclv_rpm_to_q15(-3000, 6000) == -16384, "minus half base");
    TK_CHECK(mclv_rpm_to_q15(6000, 6000) == 32767, "base saturates");
    TK_CHECK(mclv_rpm_to_q15(-6000, 6000) == -32768, "minus base");
    TK_CHECK(mclv_rpm_to_q15(100000, 6000) == 32767, "far above");
    TK_CHECK(mclv_rpm_to_q15(INT32_MIN, 6000) == -32768, "INT32_MIN");
    TK_CHECK(mclv_rpm_to_q15(100, 0) == 0, "bad base");
    for (int32_t rpm = -5999; rpm <= 5999; rpm++) {
        const q15_t q = mclv_rpm_to_q15(rpm, 6000);
        const double exact = (double)rpm * 32768.0 / 6000.0;
        TK_CHECK(q - exact <= 0.5 && exact - q <= 0.5, "%ld rpm -> %d (%.2f)", (long)rpm, q, exact);
    }
}


TK_CASES(TK_CASE(case_rpm_conversion), TK_CASE(case_debounce), TK_CASE(case_s2_actions), TK_CASE(case_pot_range),
         TK_CASE(case_leds))
