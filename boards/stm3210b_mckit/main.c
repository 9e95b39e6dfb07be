/*
 * STM3210B-MCKIT firmware: clocks, the FOC port, watchdog, buttons, LEDs
 * and the core's monitor (foc/monitor.h, docs/monitor.md) on USART1.  All
 * control runs in the port's interrupts; the main loop only serves the
 * operator.
 *
 *   Key button (PB9)      start when idle, stop otherwise
 *   Joystick select (PD12) acknowledge a fault
 *   LD1 on while the motor is driven, blinking when idle; LD2 fault;
 *   LD3 current-offset calibration; LD4 crystal did not start.
 */
#include <stddef.h>

#include "board.h"
#include "foc/controller.h"
#include "foc/monitor.h"
#include "foc/scope.h"
#include "stm32_clock.h"
#include "stm32_gpio.h"
#include "stm32_iwdg.h"
#include "stm32_port.h"
#include "stm32_usart.h"
#include "stm32_vectors.h"
#include "stm32f10x_regs.h"

#define BUTTON_POLL_TICKS 16u /* slow ticks between button polls (~8 ms) */
#define BUTTON_STABLE_POLLS 3u
#define BLINK_POLLS 64u
#define SCOPE_SAMPLES 1024u   /* the monitor's scope buffer: 2 KB of the 20 */

typedef struct {
    GPIO_TypeDef *port;
    uint32_t pin;
    uint8_t down_polls;
} button_t;

static foc_ctrl_t ctrl;
static int16_t scope_buf[SCOPE_SAMPLES];
static foc_scope_t scope;
static foc_mon_t monitor;

/* 1 once per press: the button read low for BUTTON_STABLE_POLLS polls. */
static uint8_t button_pressed(button_t *b)
{
    if (stm32_gpio_read(b->port, b->pin) != 0u) {
        b->down_polls = 0;
        return 0;
    }
    if (b->down_polls < BUTTON_STABLE_POLLS) {
        b->down_polls++;
        return (uint8_t)(b->down_polls == BUTTON_STABLE_POLLS);
    }
    return 0;
}

static void leds_init(void)
{
    RCC->APB2ENR |= RCC_APB2ENR_IOPBEN | RCC_APB2ENR_IOPCEN | RCC_APB2ENR_IOPDEN;
    stm32_gpio_mode(BOARD_LED_PORT, BOARD_LED_RUN, STM32_GPIO_OUT_PP_2MHZ);
    stm32_gpio_mode(BOARD_LED_PORT, BOARD_LED_FAULT, STM32_GPIO_OUT_PP_2MHZ);
    stm32_gpio_mode(BOARD_LED_PORT, BOARD_LED_CALIB, STM32_GPIO_OUT_PP_2MHZ);
    stm32_gpio_mode(BOARD_LED_PORT, BOARD_LED_CLOCK, STM32_GPIO_OUT_PP_2MHZ);
}

static void leds_show(foc_state_t s, uint32_t polls)
{
    const uint8_t driven = (uint8_t)(s == FOC_STATE_ALIGN || s == FOC_STATE_OPENLOOP ||
                                     s == FOC_STATE_RUN || s == FOC_STATE_STOP ||
                                     s == FOC_STATE_BRAKE);
    const uint8_t blink = (uint8_t)((polls / BLINK_POLLS) & 1u);
    stm32_gpio_write(BOARD_LED_PORT, BOARD_LED_RUN,
                     (uint8_t)(driven || (s == FOC_STATE_IDLE && blink)));
    stm32_gpio_write(BOARD_LED_PORT, BOARD_LED_FAULT, (uint8_t)(s == FOC_STATE_FAULT));
    stm32_gpio_write(BOARD_LED_PORT, BOARD_LED_CALIB, (uint8_t)(s == FOC_STATE_CALIB));
}

/* The port's figures for the monitor's status: the control interrupt's
 * average share of the PWM period (Q15) and its overruns. */
static void collect(void)
{
    stm32_isr_stats_t st;
    stm32_port_isr_stats(&st);
    const uint32_t period = stm32_port_period_cycles();
    monitor.cpu_load_q15 = (period == 0u) ? FOC_MON_LOAD_UNKNOWN
                           : (st.avg >= period) ? 32767u
                                                : (uint16_t)((st.avg * 32768u) / period);
    monitor.overruns = (st.overruns > 0xFFFFu) ? 0xFFFFu : (uint16_t)st.overruns;
}

/* Received bytes in, reply bytes out, never waiting on the USART. */
static void serve_monitor(void)
{
    int ch;
    uint8_t b;
    while ((ch = stm32_usart_getc()) >= 0) {
        foc_mon_rx(&monitor, (uint8_t)ch);
    }
    while (stm32_usart_tx_ready() != 0u && foc_mon_tx(&monitor, &b) != 0u) {
        stm32_usart_putc(b);
    }
}

/* The crystal did not start: nothing may switch; say so and wait. */
static void clock_fault(void)
{
    stm32_gpio_write(BOARD_LED_PORT, BOARD_LED_CLOCK, 1u);
    stm32_usart_write("\r\nclock fault: the crystal did not start, motor disabled\r\n");
    for (;;) {
        serve_monitor(); /* the controller is idle: status says so */
    }
}

int main(void)
{
    const uint8_t clock_ok = stm32_clock_init();
    leds_init();
    stm32_usart_init(stm32_clock_hz(), BOARD_USART_BAUD);
    foc_init(&ctrl);
    foc_scope_init(&scope, &ctrl, scope_buf, (uint16_t)SCOPE_SAMPLES);
    ctrl.scope = &scope;
    foc_mon_init(&monitor, &ctrl, &scope);
    if (!clock_ok) {
        clock_fault();
    }

    const uint8_t timer_ok = stm32_port_init(&ctrl);
    stm32_iwdg_start(BOARD_IWDG_TIMEOUT_MS);
    stm32_usart_write(timer_ok ? "\r\nfoc stm3210b-mckit ready\r\n"
                               : "\r\ntimer fault: PWM update not at the bottom of the "
                                 "count, motor disabled\r\n");

    button_t key = { BOARD_KEY_PORT, BOARD_KEY_PIN, 0u };
    button_t sel = { BOARD_SEL_PORT, BOARD_SEL_PIN, 0u };
    uint32_t last_poll = stm32_port_slow_ticks();
    uint32_t polls = 0;
    for (;;) {
        collect();
        serve_monitor();
        const uint32_t now = stm32_port_slow_ticks();
        if (now - last_poll < BUTTON_POLL_TICKS) {
            continue;
        }
        last_poll = now;
        polls++;
        const foc_state_t s = ctrl.state;
        if (button_pressed(&key) != 0u) {
            if (s == FOC_STATE_IDLE) {
                foc_cmd_start(&ctrl);
            } else {
                foc_cmd_stop(&ctrl);
            }
        }
        if (button_pressed(&sel) != 0u) {
            foc_cmd_ack(&ctrl);
        }
        leds_show(s, polls);
    }
}
