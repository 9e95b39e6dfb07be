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
 *   pot       speed command (unless the monitor set one: "speed pot"
 *             gives it back)
 *   UART1     the text monitor (hal/dspic33fj/dspic_monitor.h)
 *   LED "run" the controller state (mclv_led_run)
 *   watchdog  cleared only while slow steps keep coming
 */
#include <xc.h>

#include "board.h"
#include "dspic33fj.h"
#include "dspic_monitor.h"
#include "foc/controller.h"
#include "mclv_ui.h"

#define TX_SIZE 256u /* power of two, at most 256 (uint8_t indices) */

static foc_ctrl_t ctrl;
static dspic_mon_t mon;
static mclv_button_t s2;
static mclv_button_t s3;
static uint8_t fw_range;
static uint8_t pot_source = 1;
static int32_t ref_rpm;

static char tx_buf[TX_SIZE];
static uint8_t tx_head;
static uint8_t tx_tail;

/* --------------------------------------------------------- serial out -- */
static void tx_puts(const char *s)
{
    while (*s != '\0') {
        const uint8_t next = (uint8_t)((tx_head + 1u) & (TX_SIZE - 1u));
        if (next == tx_tail) {
            return; /* full: the rest is dropped */
        }
        tx_buf[tx_head] = *s;
        tx_head = next;
        s++;
    }
}

static void tx_flush(void)
{
    while (tx_tail != tx_head && dspic_uart_write((uint8_t)tx_buf[tx_tail]) != 0u) {
        tx_tail = (uint8_t)((tx_tail + 1u) & (TX_SIZE - 1u));
    }
}

/* -------------------------------------------------------- speed command -- */
static int32_t range_max_rpm(void)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    return (fw_range != 0u) ? BOARD_POT_MAX_FW_RPM : BOARD_POT_MAX_RPM;
}

static void command_speed(int32_t rpm)
{
    const int32_t max = range_max_rpm();
    ref_rpm = (rpm > max) ? max : (rpm < -max) ? -max : rpm;
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    foc_cmd_speed(&ctrl, dspic_rpm_to_q15(ref_rpm, BOARD_SPEED_BASE_RPM));
}

/* ------------------------------------------------------------- monitor -- */
static uint32_t ticks_to_ns(uint16_t ticks)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    return (uint32_t)ticks * 1000u / (uint32_t)(BOARD_TIMESTAMP_HZ / 1000000uL);
}

/* Q15 of the current full scale -> mA (|q| x 4400 < 2^31). */
static int32_t q15_to_ma(q15_t q)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    return ((int32_t)q * (int32_t)(BOARD_CURRENT_FULL_SCALE_A * 1000.0 + 0.5)) / 32768;
}

static void send_status(void)
{
    char line[160];
    dspic_stats_t st;
    dspic_mon_status_t s;
    const q15_t vdc = ctrl.samples.vdc;
    dspic_fast_stats(&st);
    s.state = foc_state_name(ctrl.state);
    s.faults = ctrl.faults.active;
    s.first_fault = foc_fault_name(ctrl.faults.first);
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    s.speed_rpm = dspic_q15_to_rpm(ctrl.est.speed, BOARD_SPEED_BASE_RPM);
    s.ref_rpm = ref_rpm;
    s.id_ma = q15_to_ma(ctrl.i_dq.d);
    s.iq_ma = q15_to_ma(ctrl.i_dq.q);
    s.vdc_mv = (vdc < 0) ? 0u
                         /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
                         : ((uint32_t)vdc * (uint32_t)(BOARD_VDC_FULL_SCALE_V * 1000.0 + 0.5)) >> 15;
    s.isr_min_ns = (st.min == 0xFFFFu) ? 0u : ticks_to_ns(st.min);
    s.isr_avg_ns = ticks_to_ns(st.avg);
    s.isr_max_ns = ticks_to_ns(st.max);
    s.fw_range = fw_range;
    s.pot_source = pot_source;
    (void)dspic_mon_format_status(line, sizeof line, &s);
    tx_puts(line);
    tx_puts("\r\n");
}

static void monitor_command(const dspic_mon_cmd_t *cmd)
{
    switch (cmd->kind) {
    case DSPIC_MON_START:
        foc_cmd_start(&ctrl);
        break;
    case DSPIC_MON_STOP:
        foc_cmd_stop(&ctrl);
        break;
    case DSPIC_MON_ACK:
        foc_cmd_ack(&ctrl);
        break;
    case DSPIC_MON_SPEED:
        pot_source = 0;
        command_speed(cmd->rpm);
        break;
    case DSPIC_MON_SPEED_POT:
        pot_source = 1;
        break;
    case DSPIC_MON_STATUS:
        send_status();
        return;
    case DSPIC_MON_HELP:
        tx_puts(dspic_mon_help());
        tx_puts("\r\n");
        return;
    default:
        break;
    }
    tx_puts(dspic_mon_reply(cmd->kind));
    tx_puts("\r\n");
}

static void monitor_poll(void)
{
    uint8_t ch;
    while (dspic_uart_read(&ch) != 0u) {
        dspic_mon_cmd_t cmd;
        if (dspic_mon_feed(&mon, (char)ch, &cmd) != 0u) {
            monitor_command(&cmd);
        }
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
        fw_range = (uint8_t)(fw_range == 0u);
        if (pot_source == 0u) {
            command_speed(ref_rpm); /* re-clamped to the new range */
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
    dspic_mon_init(&mon);
    foc_init(&ctrl);
    dspic_start(&ctrl);
    dspic_watchdog_enable();

    {
        char line[48];
        size_t len = 0;
        line[0] = '\0';
        dspic_mon_put_str(line, sizeof line, &len, BOARD_NAME " reset=");
        dspic_mon_put_hex16(line, sizeof line, &len, dspic_reset_cause());
        tx_puts(line);
        tx_puts("\r\n");
    }

    last_ms = foc_port_timestamp();
    last_slow = dspic_slow_count();
    for (;;) {
        if (foc_port_timestamp() - last_ms >= BOARD_TICKS_PER_MS) {
            last_ms += BOARD_TICKS_PER_MS;
            ms++;
            ui_tick(ms);
        }
        monitor_poll();
        tx_flush();
        if (dspic_slow_count() != last_slow) {
            last_slow = dspic_slow_count();
            dspic_watchdog_clear();
        }
    }
}
