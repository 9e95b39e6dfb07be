/*
 * dsPICDEM MCLV + dsPIC33FJ32MC204: the application around the core.
 *
 * Interrupts do the control (hal/dspic33fj): foc_fast_step() at 20 kHz,
 * foc_slow_step() every CONTROL_SLOW_DIVIDER periods.  The main loop only
 * makes requests, once per millisecond of the 32-bit time base:
 *   S2        start in IDLE, stop while starting or running, acknowledge
 *             in FAULT
 *   S3        toggles the potentiometer's range: up to the nominal speed,
 *             or up to the maximum (field weakening); LED "fw" shows it
 *   pot       speed command, unless the monitor set one (then S3 gives
 *             the speed back to the pot instead of toggling the range)
 *   UART1     the core's monitor (foc/monitor.h, docs/monitor.md) with a
 *             scope of SCOPE_SAMPLES samples
 *   LED "run" the controller state (mclv_led_run)
 *   watchdog  cleared only while slow steps keep coming
 */
#include <xc.h>

#include "board.h"
#include "dspic33fj.h"
#include "foc/controller.h"
#include "foc/monitor.h"
#include "foc/scope.h"
#include "mclv_ui.h"

#define SCOPE_SAMPLES 128u /* the scope's buffer: 256 of the 2048 bytes */

static foc_ctrl_t ctrl;
static int16_t scope_buf[SCOPE_SAMPLES];
static foc_scope_t scope;
static foc_mon_t mon;
static mclv_button_t s2;
static mclv_button_t s3;
static uint8_t fw_range;
static uint8_t pot_source = 1;
static q15_t pot_speed;       /* the speed request the pot made last */
static uint8_t pending;       /* pending_byte waits for the transmitter */
static uint8_t pending_byte;

/* -------------------------------------------------------- speed command -- */
static int32_t range_max_rpm(void)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    return (fw_range != 0u) ? BOARD_POT_MAX_FW_RPM : BOARD_POT_MAX_RPM;
}

static void command_speed(int32_t rpm)
{
    const int32_t max = range_max_rpm();
    const int32_t ref_rpm = (rpm > max) ? max : (rpm < -max) ? -max : rpm;
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    foc_cmd_speed(&ctrl, mclv_rpm_to_q15(ref_rpm, BOARD_SPEED_BASE_RPM));
    pot_speed = ctrl.req.speed; /* as the core took it (raised to its minimum) */
}

/* ------------------------------------------------------------- monitor -- */
/* The port's figures for the monitor's status: the fast-step interrupt's
 * average share of the PWM period (Q15); its overruns are the slow
 * step's lost ticks (the fast step cannot overrun unseen: it would delay
 * the slow one). */
static void collect(void)
{
    dspic_stats_t st;
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const uint32_t period = (uint32_t)(BOARD_TIMESTAMP_HZ / BOARD_PWM_HZ);
    dspic_fast_stats(&st);
    mon.cpu_load_q15 = ((uint32_t)st.avg >= period)
                           ? 32767u
                           : (uint16_t)(((uint32_t)st.avg * 32768uL) / period);
    mon.overruns = dspic_slow_overruns();
}

/* Received bytes in, reply bytes out, never waiting on the UART. */
static void serve_monitor(void)
{
    uint8_t ch;
    while (dspic_uart_read(&ch) != 0u) {
        foc_mon_rx(&mon, ch);
    }
    while (pending != 0u || foc_mon_tx(&mon, &pending_byte) != 0u) {
        pending = 1u;
        if (dspic_uart_write(pending_byte) == 0u) {
            break; /* the transmitter is full: the same byte next time */
        }
        pending = 0u;
    }
    /* a speed the monitor commanded: the potentiometer lets go (S3 gives
     * the speed back to it) */
    if (pot_source != 0u && ctrl.req.speed != pot_speed) {
        pot_source = 0u;
    }
}

/* The reset banner: board name and RCON in hex (text before the first
 * frame; the monitor's leading zero ends it for the host). */
static void banner(void)
{
    static const char hex[] = "0123456789abcdef";
    const char *s = BOARD_NAME " reset=0x";
    const uint16_t rcon = dspic_reset_cause();
    while (*s != '\0') {
        while (dspic_uart_write((uint8_t)*s) == 0u) {
        }
        s++;
    }
    uint16_t shift = 16u;
    while (shift != 0u) {
        shift = (uint16_t)(shift - 4u);
        const uint16_t d = (uint16_t)((uint16_t)(rcon >> shift) & 0xFu);
        while (dspic_uart_write((uint8_t)hex[d]) == 0u) {
        }
    }
    while (dspic_uart_write((uint8_t)'\r') == 0u) {
    }
    while (dspic_uart_write((uint8_t)'\n') == 0u) {
    }
}

/* ------------------------------------------------------- buttons, LEDs -- */
static void pins_init(void)
{
    TRISA = (uint16_t)(TRISA | BOARD_S2_PORTA_MASK);
    TRISB = (uint16_t)(TRISB | BOARD_S3_PORTB_MASK);
    LATA = (uint16_t)(LATA & (uint16_t)~(BOARD_LED_RUN_LATA_MASK | BOARD_LED_FW_LATA_MASK));
    TRISA = (uint16_t)(TRISA & (uint16_t)~(BOARD_LED_RUN_LATA_MASK | BOARD_LED_FW_LATA_MASK));
}

static void led_set(uint16_t mask, uint8_t on)
{
    LATA = (on != 0u) ? (uint16_t)(LATA | mask) : (uint16_t)(LATA & (uint16_t)~mask);
}

static void ui_tick(uint16_t ms)
{
    const foc_state_t state = ctrl.state;
    const uint8_t s2_down = (uint8_t)((PORTA & BOARD_S2_PORTA_MASK) == 0u);
    const uint8_t s3_down = (uint8_t)((PORTB & BOARD_S3_PORTB_MASK) == 0u);

    if (mclv_button_update(&s2, s2_down) != 0u) {
        switch (mclv_s2_action(state)) {
        case MCLV_S2_START:
            foc_cmd_start(&ctrl);
            break;
        case MCLV_S2_STOP:
            foc_cmd_stop(&ctrl);
            break;
        case MCLV_S2_ACK:
            foc_cmd_ack(&ctrl);
            break;
        default:
            break;
        }
    }
    if (mclv_button_update(&s3, s3_down) != 0u) {
        if (pot_source == 0u) {
            pot_source = 1u; /* the speed back to the pot */
        } else {
            fw_range = (uint8_t)(fw_range == 0u);
        }
    }
    if (pot_source != 0u) {
        command_speed(mclv_pot_to_rpm(ctrl.samples.pot, BOARD_POT_MIN_RPM, range_max_rpm()));
    }
    led_set(BOARD_LED_RUN_LATA_MASK, mclv_led_run(state, ms));
    led_set(BOARD_LED_FW_LATA_MASK, fw_range);
}

/* ---------------------------------------------------------------- main -- */
int main(void)
{
    uint32_t last_ms;
    uint16_t ms = 0;
    uint16_t last_slow;

    dspic_init();
    pins_init();
    mclv_button_init(&s2);
    mclv_button_init(&s3);
    foc_init(&ctrl);
    foc_scope_init(&scope, &ctrl, scope_buf, (uint16_t)SCOPE_SAMPLES);
    ctrl.scope = &scope;
    foc_mon_init(&mon, &ctrl, &scope);
    banner();
    dspic_start(&ctrl);
    dspic_watchdog_enable();

    last_ms = foc_port_timestamp();
    last_slow = dspic_slow_count();
    for (;;) {
        if (foc_port_timestamp() - last_ms >= BOARD_TICKS_PER_MS) {
            last_ms += BOARD_TICKS_PER_MS;
            ms++;
            ui_tick(ms);
        }
        collect();
        serve_monitor();
        if (dspic_slow_count() != last_slow) {
            last_slow = dspic_slow_count();
            dspic_watchdog_clear();
        }
    }
}
