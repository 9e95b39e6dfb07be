#include "foc/controller.h"
#include "foc/config.h"
#include "foc/sqrt.h"
#include "foc/svm.h"
#include "foc/trig.h"

/* Angle advance for the inverse Park: the voltage computed now is applied
 * during the next period, whose middle is 1.5 periods ahead. */
#define ADVANCE_GAIN Q15(1.5 * FOC_DTHETA_AT_BASE / 32768.0)

static const foc_dq_t zero_dq = { 0, 0 };
static const foc_ab_t zero_ab = { 0, 0 };
static const foc_duty_t half_duty = { 16384, 16384, 16384, 1 };

static void enter(foc_ctrl_t *c, foc_state_t s)
{
    /* A fault latched meanwhile by the fast step wins over any transition. */
    c->state = (c->faults.active != 0u) ? FOC_STATE_FAULT : s;
    c->state_ticks = 0;
}

static void outputs_off(foc_ctrl_t *c)
{
    foc_port_pwm_disable();
    c->v_dq = zero_dq;
    c->v_ab = zero_ab;
    c->v_ab_prev = zero_ab;
    c->i_ref = zero_dq;
}

static void trip(foc_ctrl_t *c, foc_fault_t fault)
{
    foc_port_pwm_disable();
    foc_faults_raise(&c->faults, fault);
    c->state = FOC_STATE_FAULT;
}

void foc_init(foc_ctrl_t *c)
{
    c->req.start = 0;
    c->req.stop = 0;
    c->req.ack = 0;
    c->req.speed = 0;
    foc_faults_clear(&c->faults);
    c->i_ab = zero_ab;
    c->i_dq = zero_dq;
    c->duty = half_duty;
    foc_cs_calib_start(&c->current_sense);
    foc_cc_init(&c->current_ctrl);
    foc_sc_init(&c->speed_ctrl);
    foc_fw_init(&c->fw);
    foc_bus_init(&c->bus, FOC_VDC_NOMINAL);
    c->est.kind = FOC_ESTIMATOR;
    c->samples.theta_sensor = 0;
    outputs_off(c);
    const foc_est_input_t rest = { zero_ab, zero_ab, 0, 0 };
    foc_est_reset(&c->est, &rest, 1);
    enter(c, FOC_STATE_IDLE);
}

/* The current loop, once per period in RUN and STOP. */
static void current_loop(foc_ctrl_t *c)
{
    c->i_ab = foc_cs_alphabeta(&c->current_sense, &c->samples);

    /* The voltage applied in the period that just ended was computed two
     * steps ago (the PWM unit applies duties one period late). */
    const foc_est_input_t in = { c->v_ab_prev, c->i_ab, c->i_ref.q,
                                 c->samples.theta_sensor };
    foc_est_step(&c->est, &in);
    c->v_ab_prev = c->v_ab;

    c->i_dq = foc_park_q15(c->i_ab, foc_sincos_q15(c->est.theta));
    c->v_dq = foc_cc_step(&c->current_ctrl, c->i_ref, c->i_dq, c->bus.v_max);

    const q15_t advance = foc_mul_q15(c->est.speed, ADVANCE_GAIN);
    const uint16_t theta_v = (uint16_t)(c->est.theta + (uint16_t)advance);
    c->v_ab = foc_ipark_q15(c->v_dq, foc_sincos_q15(theta_v));
    c->duty = foc_svm_q15(foc_bus_compensate(&c->bus, c->v_ab));
    foc_port_set_duties(&c->duty);
    foc_port_debug_out(c->i_dq.d, c->i_dq.q);
}

void foc_fast_step(foc_ctrl_t *c)
{
    foc_port_read_samples(&c->samples);
    if (foc_port_overcurrent_latched() != 0u) {
        trip(c, FOC_FAULT_OVERCURRENT);
        return;
    }
    switch (c->state) {
    case FOC_STATE_CALIB:
        foc_cs_calib_add(&c->current_sense, &c->samples);
        break;
    case FOC_STATE_RUN:
    case FOC_STATE_STOP:
        current_loop(c);
        break;
    default:
        break;
    }
}

/* CALIB -> RUN: every block restarts from rest, the bridge starts at zero
 * voltage, then the state changes (the fast step runs the loop from then). */
static void start_run(foc_ctrl_t *c)
{
    const foc_est_input_t in = { zero_ab, zero_ab, 0, c->samples.theta_sensor };
    foc_est_reset(&c->est, &in, 1);
    foc_cc_reset(&c->current_ctrl);
    foc_sc_preset(&c->speed_ctrl, c->est.speed, 0);
    foc_fw_reset(&c->fw);
    c->i_ref = zero_dq;
    c->v_ab = zero_ab;
    c->v_ab_prev = zero_ab;
    c->duty = half_duty;
    foc_port_set_duties(&c->duty);
    foc_port_pwm_enable();
    enter(c, FOC_STATE_RUN);
}

/* Field weakening first (Id takes its share of the current limit), then
 * the speed PI within what is left. */
static void speed_loop(foc_ctrl_t *c)
{
    const q15_t v_mag = foc_mag_q15(c->v_dq.d, c->v_dq.q);
    c->i_ref.d = foc_fw_step(&c->fw, c->speed_ctrl.ramped, v_mag, c->bus.v_max);
    foc_est_set_fw(&c->est, c->fw.inv_kfi, c->fw.ls_scale);
    c->i_ref.q = foc_sc_step(&c->speed_ctrl, c->est.speed, c->i_ref.d);
}

static void state_machine(foc_ctrl_t *c)
{
    switch (c->state) {
    case FOC_STATE_IDLE:
        if (c->req.start != 0u) {
            foc_cs_calib_start(&c->current_sense);
            outputs_off(c);
            enter(c, FOC_STATE_CALIB);
        }
        break;
    case FOC_STATE_CALIB:
        if (c->req.stop != 0u) {
            enter(c, FOC_STATE_IDLE);
        } else if (c->current_sense.calibrated != 0u &&
                   c->state_ticks >= FOC_CALIB_TICKS) {
            start_run(c);
        }
        break;
    case FOC_STATE_RUN:
        /* Sensored start: hand over to the estimator above a speed. */
        if (c->est.use_sensor != 0u && c->est.kind != FOC_EST_SENSORED &&
            foc_abs_q15(c->est.speed) >= FOC_SENSORED_HANDOVER_SPEED) {
            c->est.use_sensor = 0;
        }
        c->speed_ctrl.target = c->req.speed;
        speed_loop(c);
        if (c->req.stop != 0u) {
            enter(c, FOC_STATE_STOP);
        }
        break;
    case FOC_STATE_STOP:
        c->speed_ctrl.target = 0;
        speed_loop(c);
        if (c->speed_ctrl.ramped == 0 && foc_abs_q15(c->est.speed) <= FOC_STOP_SPEED) {
            outputs_off(c);
            enter(c, FOC_STATE_IDLE);
        }
        break;
    case FOC_STATE_FAULT:
        outputs_off(c);
        if (c->req.ack != 0u) {
            foc_port_overcurrent_clear();
            if (foc_port_overcurrent_latched() == 0u) {
                foc_faults_clear(&c->faults);
                enter(c, FOC_STATE_IDLE);
            }
        }
        break;
    default:
        /* ALIGN, OPENLOOP, BRAKE are not entered yet: stop safely. */
        outputs_off(c);
        enter(c, FOC_STATE_IDLE);
        break;
    }
    /* Requests are one-shot: anything not acted on now is dropped. */
    c->req.start = 0;
    c->req.stop = 0;
    c->req.ack = 0;
}

void foc_slow_step(foc_ctrl_t *c)
{
    foc_bus_update(&c->bus, c->samples.vdc);
    if (c->state_ticks < UINT16_MAX) {
        c->state_ticks++;
    }
    state_machine(c);
}

void foc_cmd_start(foc_ctrl_t *c)
{
    c->req.start = 1;
}

void foc_cmd_stop(foc_ctrl_t *c)
{
    c->req.stop = 1;
}

void foc_cmd_ack(foc_ctrl_t *c)
{
    c->req.ack = 1;
}

void foc_cmd_speed(foc_ctrl_t *c, q15_t speed)
{
    c->req.speed = speed;
}

const char *foc_state_name(foc_state_t s)
{
    static const char *const names[] = {
        "IDLE", "CALIB", "ALIGN", "OPENLOOP", "RUN", "STOP", "BRAKE", "FAULT",
    };
    return ((unsigned)s < sizeof names / sizeof names[0]) ? names[s] : "?";
}
