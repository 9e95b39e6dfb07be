/*
 * dsPICDEM MCLV user interface, pure logic (no register access): push
 * button debouncing, what S2 asks of the controller, the potentiometer's
 * speed range, the LED patterns.  main.c samples the pins every
 * millisecond and applies the results.
 */
#ifndef MCLV_UI_H
#define MCLV_UI_H

#include <stdint.h>
#include "foc/controller.h"

/* A push button debounced by requiring MCLV_DEBOUNCE_MS equal samples
 * (one per millisecond) before the stable state changes. */
#define MCLV_DEBOUNCE_MS 20u

typedef struct {
    uint8_t stable;  /* debounced state, 1 = pressed */
    uint8_t count;   /* consecutive samples that differ from `stable` */
} mclv_button_t;

void mclv_button_init(mclv_button_t *b);

/* One sample (1 = pressed); returns 1 on the debounced press edge. */
uint8_t mclv_button_update(mclv_button_t *b, uint8_t pressed);

/* What a press of S2 requests in a controller state. */
typedef enum {
    MCLV_S2_START = 0, /* IDLE: start */
    MCLV_S2_STOP,      /* CALIB, ALIGN, OPENLOOP, RUN: stop */
    MCLV_S2_ACK,       /* FAULT: acknowledge */
    MCLV_S2_NOTHING    /* STOP, BRAKE: already stopping */
} mclv_s2_action_t;

mclv_s2_action_t mclv_s2_action(foc_state_t state);

/* Potentiometer (Q15 fraction of its travel, 0..32767) to a speed
 * command in rpm between min_rpm (pot at 0) and max_rpm (full travel),
 * linear, rounded down; min_rpm <= max_rpm, both 0..65535. */
int32_t mclv_pot_to_rpm(q15_t pot, int32_t min_rpm, int32_t max_rpm);

/* Mechanical rpm -> Q15 of a base speed (1..65535 rpm), rounded,
 * saturating at the base; 0 for a base out of range. */
q15_t mclv_rpm_to_q15(int32_t rpm, int32_t base_rpm);

/* The "run" LED (docs/boards/dspicdem_mclv.md): 1 = on, from the
 * controller state and a free-running millisecond count: off in IDLE,
 * on in RUN, blinking 4 Hz while starting or stopping, 10 Hz in FAULT. */
uint8_t mclv_led_run(foc_state_t state, uint16_t ms);

#endif /* MCLV_UI_H */
