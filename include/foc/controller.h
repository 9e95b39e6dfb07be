/*
 * The controller: the per-PWM-period current loop and the slow-tick speed
 * loop and state machine, composed from the blocks in this directory.
 *
 * Entry points (called by the port):
 *   foc_fast_step()  once per PWM period, after the ADC conversion:
 *                    samples -> Clarke/Park -> estimator -> current PI ->
 *                    voltage limit -> inverse Park -> bus compensation ->
 *                    SVM -> duties for the next period.  Also checks the
 *                    hardware over-current latch every period.
 *   foc_slow_step()  every CONTROL_SLOW_DIVIDER periods, lower priority:
 *                    bus filter, speed ramp and PI, state machine.
 * Commands (from buttons, the monitor or focsim) only set requests, which
 * the slow step acts on: foc_cmd_start/stop/ack/speed.
 *
 * Concurrency: the fast step may preempt the slow step.  The slow step
 * writes the current references and state as single 16-bit stores (atomic
 * on both targets) and changes the state last, after preparing the blocks
 * the new state uses.
 *
 * States: IDLE -> CALIB (outputs off, current offsets measured) -> RUN ->
 * STOP (ramp down, outputs off) -> IDLE; any fault -> FAULT (outputs off)
 * until acknowledged.  ALIGN, OPENLOOP and BRAKE are reserved for the
 * sensorless start-up and braking.
 */
#ifndef FOC_CONTROLLER_H
#define FOC_CONTROLLER_H

#include <stdint.h>
#include "foc/bus.h"
#include "foc/current_ctrl.h"
#include "foc/current_sense.h"
#include "foc/estimator.h"
#include "foc/faults.h"
#include "foc/field_weakening.h"
#include "foc/port.h"
#include "foc/speed_ctrl.h"

typedef enum {
    FOC_STATE_IDLE = 0,
    FOC_STATE_CALIB,
    FOC_STATE_ALIGN,
    FOC_STATE_OPENLOOP,
    FOC_STATE_RUN,
    FOC_STATE_STOP,
    FOC_STATE_BRAKE,
    FOC_STATE_FAULT
} foc_state_t;

/* Requests from the application, consumed by the slow step. */
typedef struct {
    uint8_t start;
    uint8_t stop;
    uint8_t ack;
    q15_t speed;      /* speed command, Q15 of SPEED_BASE_RPM, signed */
} foc_requests_t;

typedef struct {
    foc_state_t state;
    foc_faults_t faults;
    foc_requests_t req;

    /* last period's measurements and commands (Q15 per-unit) */
    foc_samples_t samples;
    foc_ab_t i_ab;
    foc_dq_t i_dq;
    foc_dq_t i_ref;       /* written by the slow step */
    foc_dq_t v_dq;        /* voltage command, Q15 of the voltage base */
    foc_ab_t v_ab;        /* the same in the stator frame: applied during */
                          /* the next period */
    foc_ab_t v_ab_prev;   /* computed one step earlier: being applied now */
    foc_duty_t duty;

    foc_current_sense_t current_sense;
    foc_current_ctrl_t current_ctrl;
    foc_speed_ctrl_t speed_ctrl;
    foc_fw_t fw;
    foc_bus_t bus;
    foc_estimator_t est;

    uint16_t state_ticks; /* slow ticks spent in the present state */
} foc_ctrl_t;

/* Everything to rest: IDLE, no fault, outputs off. */
void foc_init(foc_ctrl_t *c);

void foc_fast_step(foc_ctrl_t *c);
void foc_slow_step(foc_ctrl_t *c);

void foc_cmd_start(foc_ctrl_t *c);
void foc_cmd_stop(foc_ctrl_t *c);
void foc_cmd_ack(foc_ctrl_t *c);
/* Speed command, Q15 of SPEED_BASE_RPM (mechanical), signed. */
void foc_cmd_speed(foc_ctrl_t *c, q15_t speed);

/* "IDLE", "CALIB", "ALIGN", "OPENLOOP", "RUN", "STOP", "BRAKE", "FAULT". */
const char *foc_state_name(foc_state_t s);

#endif /* FOC_CONTROLLER_H */
