#include "foc/controller.h"
#include "foc/config.h"
#include "foc/deadtime.h"
#include "foc/mtpa.h"
#include "foc/scope.h"
#include "foc/sqrt.h"
#include "foc/svm.h"

#ifdef OPEN_LOOP_FUNCTIONING
#define OPEN_LOOP_ONLY 1u
#else
#define OPEN_LOOP_ONLY 0u
#endif
#ifdef TUNING
#define TUNING_RAMP 1u
#else
#define TUNING_RAMP 0u
#endif

static const foc_dq_t zero_dq = { 0, 0 };
static const foc_ab_t zero_ab = { 0, 0 };
static const foc_duty_t half_duty = { 16384, 16384, 16384, 1 };

static void enter(foc_ctrl_t *c, foc_state_t s)
{
    /* A fault latched meanwhile by the fast step wins over any transition. */
    c->state = (c->faults.active != 0u) ? FOC_STATE_FAULT : s;
    c->state_ticks = 0;
}

/* Bridge off and no current asked; the fast step's voltages are zeroed
 * by the next start's RESTART. */
static void outputs_off(foc_ctrl_t *c)
{
    foc_port_pwm_disable();
    c->i_ref = zero_dq;
}

/* Bridge off, back to IDLE (a start-up, stop or brake that ends). */
static void to_idle(foc_ctrl_t *c)
{
    c->comm.step = (uint8_t)FOC_COMM_STEP_NONE; /* (a MECH abandoned) */
    outputs_off(c);
    enter(c, FOC_STATE_IDLE);
}

/* Posts work for the fast step's next period (controller.h); a restart
 * also restarts the estimator's slow share, which the slow step owns. */
static void post(foc_ctrl_t *c, foc_post_t what)
{
    if (what == FOC_POST_RESTART || what == FOC_POST_CATCH) {
        foc_est_track_reset(&c->est);
    }
    c->post = (uint8_t)what;
}

/* The posted work, at the start of a fast step. */
static void take_post(foc_ctrl_t *c)
{
    if (c->post == (uint8_t)FOC_POST_RESTART || c->post == (uint8_t)FOC_POST_CATCH) {
        foc_est_reset(&c->est, c->samples.theta_sensor, c->post_on_sensor);
        foc_cc_reset(&c->current_ctrl);
        c->v_dq = zero_dq;
        c->v_ab = zero_ab;
        c->v_ab_prev = zero_ab;
        c->i_ref_slewed = zero_dq;
        c->duty = half_duty;
        foc_port_set_duties(&c->duty);
        /* CATCH: the probe begins with the bridge off */
        c->probe = (uint8_t)(c->post == (uint8_t)FOC_POST_CATCH);
        if (c->probe != 0u) {
            foc_port_pwm_disable();
        } else if (c->state != FOC_STATE_IDLE && c->state != FOC_STATE_FAULT) {
            foc_port_pwm_enable();
        } else {
            /* IDLE, FAULT: the bridge stays off */
        }
    } else {
        foc_cc_preset(&c->current_ctrl, c->post_v, c->est.speed);
        c->i_ref_slewed = c->i_ref;
        c->est.use_sensor = 0;
    }
    c->post = (uint8_t)FOC_POST_NONE;
}

static int32_t speed_squared(q15_t s)
{
    return (int32_t)s * s; /* Q30 */
}

/* Raises every fault in `faults` (lowest bit first, so the first fault
 * recorded is deterministic) and turns the outputs off, or, with
 * FAULT_BRAKE and a rotor slow enough for the short-circuit current to stay
 * within the limit, shorts the windings (never for an over-current). */
static void trip(foc_ctrl_t *c, uint16_t faults)
{
    const uint8_t brake = (uint8_t)(c->opt.fault_brake != 0u &&
                                    (faults & (uint16_t)FOC_FAULT_OVERCURRENT) == 0u &&
                                    (c->faults.active & (uint16_t)FOC_FAULT_OVERCURRENT) == 0u &&
                                    speed_squared(c->est.speed) <= FOC_SHORT_SAFE_SPEED2);
    if (brake != 0u) {
        foc_port_low_sides_on();
    } else {
        foc_port_pwm_disable();
    }
    c->shorting = brake;
    if (c->comm.step == (uint8_t)FOC_COMM_STEP_MECH) {
        /* a fault in commissioning's run ends it */
        c->comm.step = (uint8_t)FOC_COMM_STEP_NONE;
        c->comm.failed_step = (uint8_t)FOC_COMM_STEP_MECH;
        faults |= (uint16_t)FOC_FAULT_COMMISSION_FAILED;
    }
    for (uint16_t bit = 1u; bit != 0u && bit <= faults; bit = (uint16_t)(bit << 1)) {
        if ((faults & bit) != 0u) {
            foc_faults_raise(&c->faults, (foc_fault_t)bit);
        }
    }
    c->state = FOC_STATE_FAULT;
    c->state_ticks = 0;
}

/* The counters and flags of one run (start-up, hand-over, stall, brake). */
static void reset_run_state(foc_ctrl_t *c)
{
    c->converged_ticks = 0;
    c->shorting = 0;
    c->speed_limited = 0;
    c->handover_id = 0;
    c->start_ticks = 0;
    c->reversal_speed = 0;
    c->unsteady_ticks = 0;
    c->too_slow_ticks = 0;
    c->emf_low_ticks = 0;
    c->lprobe_req = 0;
    foc_sup_run_reset(&c->sup);
}

void foc_init(foc_ctrl_t *c)
{
    c->req.asked.start = 0;
    c->req.asked.stop = 0;
    c->req.asked.ack = 0;
    c->req.asked.commission = 0;
    c->seen = c->req.asked;
    c->pending = c->req.asked;
    c->req.speed = 0;
    c->opt.stop_mode = STOP_MODE;
    c->opt.open_loop_only = OPEN_LOOP_ONLY;
    c->opt.tuning = TUNING_RAMP;
    c->opt.sensored_start = 0;
    c->opt.deadtime_comp = (uint8_t)(DEADTIME_COMPENSATION != 0);
    c->dt_voltage = FOC_DT_VOLTAGE;
    c->opt.fault_brake = (uint8_t)(FAULT_BRAKE != 0);
    c->opt.rs_adapt = (uint8_t)(RS_ADAPTATION != 0);
    c->opt.min_speed = FOC_SENSORLESS_MIN_SPEED;
    foc_faults_clear(&c->faults);
    c->i_ab = zero_ab;
    c->i_dq = zero_dq;
    c->duty = half_duty;
    c->probe = 0;
    foc_cs_calib_start(&c->current_sense, FOC_CALIB_PERIODS_LOG2);
    foc_gb_init(&c->gb);
    foc_cc_init(&c->current_ctrl);
    foc_sc_init(&c->speed_ctrl);
    foc_fw_init(&c->fw);
    foc_bus_init(&c->bus, FOC_VDC_NOMINAL);
    foc_protection_init(&c->protection);
    foc_sup_init(&c->sup);
    foc_comm_init(&c->comm);
    foc_speed_stats_reset(&c->speed_stats);
    foc_startup_begin(&c->startup, 1);
    c->est.kind = (uint8_t)FOC_ESTIMATOR;
    c->samples.theta_sensor = 0;
    c->scope = NULL;
    c->forced_iq_max = FOC_CURRENT_LIMIT;
    c->post = (uint8_t)FOC_POST_NONE;
    c->post_on_sensor = 0;
    c->post_v = zero_dq;
    c->i_ref_slewed = zero_dq;
    c->advance_sc = foc_sincos_q15(0);
    c->v_dq = zero_dq;
    c->v_ab = zero_ab;
    c->v_ab_prev = zero_ab;
    c->direction = 1;
    reset_run_state(c);
    outputs_off(c);
    c->est.rs_ratio = FOC_RATIO_ONE_Q14;
    foc_est_gains_init(&c->est.gains);
    c->est.ls_ratio = FOC_RATIO_ONE_Q14;
    c->lprobe = 0;
    foc_est_reset(&c->est, 0, 1);
    foc_est_track_reset(&c->est);
    enter(c, FOC_STATE_IDLE);
}

/* The q voltage of a rotor locked to the forced frame: w (psi + Ld id). */
static q15_t forced_vq(q15_t speed, q15_t id)
{
    const q15_t emf = foc_mul_q15_shift(speed, FOC_EMF_PER_SPEED_MANT, FOC_EMF_PER_SPEED_SHIFT);
    const q15_t coupling = foc_mul_q15_shift(foc_mul_q15(speed, id), FOC_XD_MANT, FOC_XD_SHIFT);
    return foc_add_q15(emf, coupling);
}

/* 1 when the sampled current is beyond its trip level (each square
 * <= 2^30: the sum fits 32 bits unsigned). */
static FOC_ALWAYS_INLINE uint8_t current_lost(foc_ab_t i)
{
    return (uint8_t)((uint32_t)((int32_t)i.alpha * i.alpha) + (uint32_t)((int32_t)i.beta * i.beta) >
                     /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
                     FOC_CURRENT_TRIP_SQ_Q30);
}

/* The voltage the bridge applied in the period that just ended (stator
 * frame): computed two steps ago (`v_prev`: the PWM unit applies duties
 * one period late), plus part of the last command `v_last` where the
 * duties are loaded mid-way between two samples (SAMPLE_DELAY_PERIODS <
 * 1.5), plus the dead-time error for the current that flowed (the mean of
 * the samples `i_last` and `i_now`). */
static FOC_ALWAYS_INLINE foc_ab_t applied_voltage(const foc_ctrl_t *c, foc_ab_t v_prev, foc_ab_t v_last,
                                       foc_ab_t i_last, foc_ab_t i_now)
{
    foc_ab_t v = v_prev;
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    if (FOC_V_NEW_WEIGHT != 0) {
        /* cppcheck-suppress [misra-c2012-10.1, misra-c2012-10.8] ; D1 Q-format shift, D2 compile-time constant */
        v.alpha = (q15_t)(v.alpha + ((((int32_t)v_last.alpha - v.alpha) * FOC_V_NEW_WEIGHT) >> 15));
        /* cppcheck-suppress [misra-c2012-10.1, misra-c2012-10.8] ; D1 Q-format shift, D2 compile-time constant */
        v.beta = (q15_t)(v.beta + ((((int32_t)v_last.beta - v.beta) * FOC_V_NEW_WEIGHT) >> 15));
    }
    if (c->opt.deadtime_comp != 0u) {
        /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
        const foc_ab_t i_mid = { (q15_t)(((int32_t)i_last.alpha + i_now.alpha) >> 1),
                                 /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
                                 (q15_t)(((int32_t)i_last.beta + i_now.beta) >> 1) };
        const foc_ab_t err = foc_deadtime_error_ab(foc_iclarke_q15(i_mid), c->dt_voltage);
        v.alpha = foc_add_q15(v.alpha, err.alpha);
        v.beta = foc_add_q15(v.beta, err.beta);
    }
    return v;
}

/* c->v_dq to the bridge on the angle sc_v: inverse Park, the dead-time
 * correction of the reference's current, bus compensation, SVM. */
static FOC_ALWAYS_INLINE void apply_voltage(foc_ctrl_t *c, foc_sincos_t sc_v)
{
    c->v_ab = foc_ipark_q15(c->v_dq, sc_v);
    if (c->opt.deadtime_comp != 0u) {
        /* cancel the dead-time error of the next period's current: the
         * reference turned on by 1.5 periods of rotation */
        const foc_ab_t corr = foc_deadtime_correction_ab(
            foc_iclarke_q15(foc_ipark_q15(c->i_ref_slewed, sc_v)), c->dt_voltage);
        c->v_ab.alpha = foc_add_q15(c->v_ab.alpha, corr.alpha);
        c->v_ab.beta = foc_add_q15(c->v_ab.beta, corr.beta);
    }
    c->duty = foc_svm_q15(foc_bus_compensate(&c->bus, c->v_ab));
    foc_port_set_duties(&c->duty);
    foc_scope_debug_out(c->scope, c);
}

/* current_loop's frame: the angle it runs on. */
#define FRAME_ESTIMATE 0u /* the estimate just made */
#define FRAME_FORCED 1u   /* the start-up's forced angle (ALIGN, OPENLOOP) */
#define FRAME_PROBE 2u    /* CATCH's inductance probe: the estimate at its */
                          /* start turned at the caught speed (startup) */
#define FRAME_PULSE 3u    /* COMMISSION's inductance pulses: the standing */
                          /* forced frame, both PIs held (comm_pulse) */

/* The inductance probe, period `c->lprobe` of FOC_LPROBE_PERIODS
 * (config.h), in place of the d PI (and in CATCH of the q PI too), which
 * it leaves as it was: the d voltage that holds the d current (the d PI's
 * integrator: its output carries the proportional part of any ripple,
 * volts on a winding whose L is half the parameter's) stepped down by
 * FOC_LPROBE_DV, then up, then back.  Down takes the rotor held by the
 * alignment current in ALIGN towards zero current, a turning rotor's
 * -FOC_LPROBE_DI in CATCH away from it: the current keeps its sign, so
 * the dead-time compensation its reference drives stays right.  The
 * largest deviation from the reference (held meanwhile: current_loop)
 * is kept for identify_ls: on d in ALIGN (a rotor still swinging on its
 * alignment puts its back-EMF on q), in magnitude in CATCH, where the
 * q voltage is held and the rotation turns the deviation, dV t / L, off
 * the d axis (to second order in the angle turned). */
/* CATCH's probe: a constant voltage error e in the held voltages (their
 * share of the back-EMF, held in a frame a little off the probe's) adds
 * e t / L to the response of both halves, so that down then up leaves
 * 2 e N T / L where the up half ends: the dip less half of that, N periods
 * after it, is the step's own.  (The dip alone measured the Hurst075 at
 * 1.5 x its inductance, caught at 1000 rpm, 2.8 +- 2 % high over eight
 * catch angles, 6.8 % at 2000 rpm.) */
static void l_probe_caught(foc_ctrl_t *c, uint8_t k, foc_dq_t dev)
{
    const q15_t mag = foc_mag_q15(dev.d, dev.q);
    if (k == 1u || (c->lprobe_dip_k != 0u && mag > c->lprobe_peak)) {
        c->lprobe_peak = mag;
        c->lprobe_dip = dev;
        c->lprobe_dip_k = k;
    } else if (c->lprobe_dip_k != 0u && k == (uint8_t)(c->lprobe_dip_k + FOC_LPROBE_N)) {
        c->lprobe_peak = foc_mag_q15(foc_sub_q15(c->lprobe_dip.d, (q15_t)(dev.d / 2)),
                                     foc_sub_q15(c->lprobe_dip.q, (q15_t)(dev.q / 2)));
        c->lprobe_dip_k = 0;
    } else {
        /* between the two */
    }
}

static void l_probe(foc_ctrl_t *c, uint8_t frame, q15_t v_max)
{
    const uint8_t k = c->lprobe;
    const q15_t dev_d = foc_sub_q15(c->i_dq.d, c->i_ref_slewed.d);
    if (frame == FRAME_FORCED) {
        const q15_t dev = foc_abs_q15(dev_d);
        if (k == 1u || dev > c->lprobe_peak) {
            c->lprobe_peak = dev;
        }
    } else {
        const foc_dq_t dev = { dev_d, foc_sub_q15(c->i_dq.q, c->i_ref_slewed.q) };
        l_probe_caught(c, k, dev);
    }
    const q15_t dv = (k <= FOC_LPROBE_N) ? (q15_t)-FOC_LPROBE_DV : (k <= 2u * FOC_LPROBE_N) ? FOC_LPROBE_DV : 0;
    const q15_t vd = foc_add_q15((q15_t)(c->current_ctrl.pi_d.integ / 32768), dv);
    c->v_dq.d = (vd > v_max) ? v_max : (vd < (q15_t)-v_max) ? (q15_t)-v_max : vd;
}

/* COMMISSION's inductance pulses (commission.h), in place of both current
 * PIs, which they leave as they were: the PIs' integrators' voltages
 * plus foc_comm_pulse's square wave on the pulsed axis, within +-v_max. */
FOC_COLD static void comm_pulse(foc_ctrl_t *c, q15_t v_max)
{
    const uint8_t on_d = (uint8_t)(c->comm.mode == (uint8_t)FOC_COMM_MODE_PULSE_D);
    const q15_t dv = (on_d != 0u) ? foc_comm_pulse(&c->comm, c->i_dq.d, c->i_ref_slewed.d)
                                  : foc_comm_pulse(&c->comm, c->i_dq.q, c->i_ref_slewed.q);
    const int32_t vd = c->current_ctrl.pi_d.integ / 32768 + ((on_d != 0u) ? dv : 0);
    const int32_t vq = c->current_ctrl.pi_q.integ / 32768 + ((on_d != 0u) ? 0 : dv);
    c->v_dq.d = (q15_t)((vd > v_max) ? v_max : (vd < -v_max) ? -v_max : vd);
    c->v_dq.q = (q15_t)((vq > v_max) ? v_max : (vq < -v_max) ? -v_max : vq);
}

/* 1 while the inductance probe drives the d voltage (its periods
 * 1..FOC_LPROBE_PERIODS). */
static inline uint8_t lprobe_running(const foc_ctrl_t *c)
{
    return (uint8_t)(c->lprobe != 0u && c->lprobe <= FOC_LPROBE_PERIODS);
}

/* The fast step's count of the probe's periods, while the slow step asks
 * for it (FOC_LPROBE_GO); back to 0 once it no longer does. */
static inline void lprobe_count(foc_ctrl_t *c)
{
    if (c->lprobe_req != FOC_LPROBE_GO) {
        c->lprobe = 0;
    } else if (c->lprobe < FOC_LPROBE_DONE) {
        c->lprobe++;
    } else {
        /* done: the count stays */
    }
}

/* The current loop on the forced angle (start-up) or the estimate: every
 * period in ALIGN, OPENLOOP, CATCH (after its probe), RUN, STOP and BRAKE
 * (until the windings are shorted);
 * in the forced frame of the start-up the q axis is voltage-driven
 * (foc_cc_q_forced: damping).  The estimator runs on every period so that
 * it has converged by the hand-over.  The inductance probe (l_probe) runs
 * on the start-up's frame or the probe's, never the estimate's. */
static void current_loop(foc_ctrl_t *c, uint8_t frame)
{
    /* The slow step's references, stepped once per slow tick, approached
     * by FOC_IREF_STEP_BITS per period on the estimated angle: a torque
     * reversal spread over a slow tick does not make the current loop
     * overshoot. */
    const uint8_t probing =
        (uint8_t)(frame != FRAME_ESTIMATE && (frame == FRAME_PULSE || lprobe_running(c)));
    foc_dq_t step = zero_dq; /* the references' steps, for the current PIs */
    if (probing == 0u) { /* (held in the probe: it measures from them) */
        step.d = (q15_t)FOC_SAT_BITS((int32_t)c->i_ref.d - c->i_ref_slewed.d, FOC_IREF_STEP_BITS);
        if (frame == FRAME_ESTIMATE) {
            /* beyond the maximum speed no current that drives the rotor
             * further, at once: the speed loop acts a slow tick and its
             * filter later (a load let go at the maximum speed) */
            const q15_t iq_ref = (foc_abs_q15(c->est.speed) > FOC_DRIVE_CUT_SPEED &&
                                  (c->i_ref.q < 0) == (c->est.speed < 0))
                                     ? 0
                                     : c->i_ref.q;
            step.q = (q15_t)FOC_SAT_BITS((int32_t)iq_ref - c->i_ref_slewed.q, FOC_IREF_STEP_BITS);
            c->i_ref_slewed.d = (q15_t)(c->i_ref_slewed.d + step.d);
            c->i_ref_slewed.q = (q15_t)(c->i_ref_slewed.q + step.q);
        } else {
            /* the start-up ramps its own (the PIs take its steps within
             * the slew's); the forced q axis is voltage-driven */
            c->i_ref_slewed = c->i_ref;
        }
    }
    const foc_ab_t i_last = c->i_ab;
    c->i_ab = foc_cs_alphabeta(&c->current_sense, &c->gb, &c->samples, c->i_ab);
    if (current_lost(c->i_ab) != 0u) {
        trip(c, (uint16_t)FOC_FAULT_OVERCURRENT); /* the current lost */
        return;
    }

    const foc_ab_t v_applied = applied_voltage(c, c->v_ab_prev, c->v_ab, i_last, c->i_ab);
    /* cppcheck-suppress misra-c2012-9.2 ; F analyser false positive */
    const foc_est_input_t in = { v_applied, c->i_ab, c->i_ref_slewed.q, c->samples.theta_sensor };
    foc_est_step(&c->est, &in);
    c->v_ab_prev = c->v_ab;

    /* The angle of this sample: the estimate just made, or forced. */
    const uint16_t theta =
        (frame == FRAME_ESTIMATE) ? c->est.theta : foc_startup_angle(&c->startup);
    const foc_sincos_t sc = foc_sincos_q15(theta);
    c->i_dq = foc_park_q15(c->i_ab, sc);
    /* d first, with the whole voltage: AN1292's d-axis priority */
    const q15_t v_max = c->bus.v_max;
    if (probing != 0u) {
        if (frame == FRAME_PULSE) {
            comm_pulse(c, v_max);
        } else {
            l_probe(c, frame, v_max);
        }
    } else {
        c->v_dq.d = foc_cc_d_axis(&c->current_ctrl, c->i_ref_slewed.d, c->i_dq.d, v_max, step.d);
    }
    if (frame == FRAME_ESTIMATE) {
        foc_cc_emf_feedforward(&c->current_ctrl, c->est.speed, FOC_EMF_PER_SPEED_MANT,
                               FOC_EMF_PER_SPEED_SHIFT, FOC_RS_ILIM_V);
        c->v_dq.q = foc_cc_q_axis(&c->current_ctrl, c->i_ref_slewed.q, c->i_dq.q, c->v_dq.d, v_max, step.q);
    } else if (frame == FRAME_FORCED) {
        /* the q swing current may use what the d current leaves */
        c->v_dq.q = foc_cc_q_forced(&c->current_ctrl, forced_vq(c->startup.speed, c->i_ref_slewed.d), c->i_dq.q,
                                    c->forced_iq_max, c->v_dq.d, v_max, c->est.speed);
    } else {
        /* FRAME_PROBE: the q voltage held; FRAME_PULSE: comm_pulse's */
    }

    apply_voltage(c, foc_sincos_sum(sc, c->advance_sc));
}

/* COMMISSION's period: the offsets' sums with the bridge off, the pulses,
 * or the forced-frame current loop and the sums.  The voltage summed is
 * the one the bridge applied in the period that just ended, dead time
 * included (in the spin the current's angle in the forced frame is not
 * the reference's, so the compensation, made for the reference, leaves
 * an error: 1 V of the Hurst075's 2 V of back-EMF at half flux), turned
 * into the forced frame at that period's middle; at standstill what the
 * bridge model misses is the same at Rs's two levels and cancels. */
FOC_COLD static void commission_fast(foc_ctrl_t *c)
{
    const uint8_t mode = c->comm.mode;
    if (mode == (uint8_t)FOC_COMM_MODE_OFF) {
        foc_cs_calib_add(&c->current_sense, &c->samples);
    } else if (mode == (uint8_t)FOC_COMM_MODE_PULSE_D || mode == (uint8_t)FOC_COMM_MODE_PULSE_Q) {
        current_loop(c, FRAME_PULSE);
    } else {
        const foc_ab_t i_last = c->i_ab;
        const foc_ab_t v_prev = c->v_ab_prev;
        const foc_ab_t v_last = c->v_ab;
        const uint16_t before = foc_startup_angle(&c->startup);
        foc_startup_fast(&c->startup);
        current_loop(c, FRAME_FORCED);
        const uint16_t mid = (uint16_t)(before + (uint16_t)(foc_startup_angle(&c->startup) - before) / 2u);
        const foc_ab_t v = applied_voltage(c, v_prev, v_last, i_last, c->i_ab);
        foc_comm_sum(&c->comm, foc_park_q15(v, foc_sincos_q15(mid)), c->i_dq);
    }
}

/* Angle of the short-circuit current i = -(1/L) integral of E over one
 * short: the EMF's angle + 180 deg, at the middle of the short (half the
 * short's length before the sample that ends it).  The rotor (E on its q
 * axis: 90 deg ahead of it in the direction of rotation) is 90 deg past
 * the current in that direction, plus that half short of rotation to the
 * sample, plus a period: the estimator's next step is two samples on, and
 * it advances its angle a period before it corrects it (one period behind,
 * 10 deg at the servo's 4000 rpm, the flux estimator lost the rotor).
 * `current` is the current's angle, `turn` the angle turned per period. */
static uint16_t probe_rotor_angle(uint16_t current, int32_t turn)
{
    const int32_t quarter = (turn < 0) ? (int32_t)-16384 : (int32_t)16384;
    /* cppcheck-suppress misra-c2012-10.8 ; D3 modular angle */
    return (uint16_t)((int32_t)current + quarter + turn * (FOC_PROBE_ADVANCE_X4 + 4) / 4);
}

/* Squared magnitude of a current, Q30 / 4 (<= 2^29). */
static int32_t probe_mag2(foc_ab_t i)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    return (int32_t)(((uint32_t)((int32_t)i.alpha * i.alpha) + (uint32_t)((int32_t)i.beta * i.beta)) >> 2);
}

/* The second short's sample `i`, FOC_PROBE_SPACING periods after the
 * first's (in c->i_ab): the rotor's angle and speed preset the estimator,
 * its back-EMF the current controller.  0 (nothing preset) unless the two
 * agree on a rotor turning at least at STARTUP_MIN_SPEED_RPM: currents no
 * more than a factor 2 apart (a current left from before the start, or an
 * EMF beyond the bus driving current through the diodes, does not look
 * like two equal shorts). */
static uint8_t probe_take(foc_ctrl_t *c, foc_ab_t i)
{
    const int32_t m1 = probe_mag2(c->i_ab);
    const int32_t m2 = probe_mag2(i);
    const uint16_t angle = foc_atan2_q15(i.beta, i.alpha);
    const int32_t turn = (int32_t)foc_angle_diff(angle, foc_atan2_q15(c->i_ab.beta, c->i_ab.alpha)) /
                         /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
                         (int32_t)FOC_PROBE_SPACING; /* per period */
    const q15_t speed = foc_mul_q15_shift((q15_t)turn, FOC_PROBE_SPEED_MANT, FOC_PROBE_SPEED_SHIFT);
    /* a factor 2 in magnitude is 4 in the squares (each <= 2^29: compared
     * as a quarter, 4 x 2^29 would overflow) */
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    if ((m1 >> 2) > m2 || (m2 >> 2) > m1 || foc_abs_q15(speed) < FOC_STARTUP_MIN_SPEED) {
        return 0;
    }
    const foc_dq_t emf = { 0, forced_vq(speed, 0) };
    foc_est_preset(&c->est, probe_rotor_angle(angle, turn), speed);
    foc_cc_preset(&c->current_ctrl, emf, speed);
    c->i_ab = zero_ab; /* what the estimator starts from */
    return 1;
}

/* CATCH's first periods, the flying start's probe: zero voltage on a
 * turning rotor shorts its back-EMF through the windings, and a current
 * loop started from zero voltage lets that current grow for the periods
 * it needs to find the EMF (1.35-1.44 x the limit on the servo caught at
 * 3500 rpm, tests/torture/regress/4c).  So, twice: the bridge off for
 * FOC_PROBE_OFF_PERIODS (a current left from before returns to zero
 * through the diodes), then zero vector from half a period after a
 * sample to the next sample, or the one after (FOC_PROBE_LONG, config.h),
 * after which the bridge is off at once.  Each short's current gives the
 * EMF's angle, the angle turned between the two, FOC_PROBE_SPACING
 * periods apart, the speed.
 * Then the estimator and the current controller are preset to the
 * rotor's angle, speed and back-EMF while the current returns to zero,
 * and the bridge takes the rotor holding zero current from the first
 * period.  A first short with too little current, or shorts that
 * disagree, leave CATCH to start from rest, the bridge on.
 * probe: periods since the restart.  Returns whether the current loop
 * runs this period, and whether the bridge is enabled after it. */
/* What catch_probe() leaves to the fast step: nothing, the current loop,
 * or the current loop and then the bridge enabled. */
#define PROBE_BUSY 0u
#define PROBE_LOOP 1u
#define PROBE_LOOP_ENABLE 2u

FOC_COLD static uint8_t catch_probe(foc_ctrl_t *c)
{
    /* the current sense's out-of-line copy: the per-period path keeps
     * the inline one to itself */
    const foc_ab_t i = foc_cs_read(&c->current_sense, &c->gb, &c->samples, c->i_ab);
    const uint8_t k = c->probe;
    c->probe = (uint8_t)(k + 1u);
    const uint8_t second = (uint8_t)(k >= FOC_PROBE_OFF_PERIODS + FOC_PROBE_SPACING);
    const uint8_t j = (uint8_t)(k - FOC_PROBE_OFF_PERIODS - (second != 0u ? FOC_PROBE_SPACING : 0u));
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    if (k < FOC_PROBE_OFF_PERIODS || j > (uint8_t)(FOC_PROBE_END + 2u)) {
        return PROBE_BUSY; /* bridge off */
    }
    if (j == 0u) {
        foc_port_pwm_enable_at_half(); /* duties 1/2: the short */
    } else if (j == FOC_PROBE_END) {
        foc_port_pwm_disable(); /* i: the short's end */
    } else {
        /* the bridge stays as it is */
    }
    if (second == 0u) {
        if (j == FOC_PROBE_END) {
            c->i_ab = i;
            if (probe_mag2(i) < FOC_PROBE_MIN_MAG2) {
                c->probe = 0; /* slow: CATCH from rest */
                foc_port_pwm_enable();
            }
        }
    } else if (j == FOC_PROBE_END) {
        if (probe_take(c, i) == 0u) {
            c->probe = 0; /* no agreement: CATCH from rest */
            c->i_ab = i;
            foc_port_pwm_enable();
        }
    } else if (j == (uint8_t)(FOC_PROBE_END + 2u)) {
        /* the current is back to zero: the controller takes the rotor */
        c->probe = 0;
        return PROBE_LOOP_ENABLE;
    } else {
        /* between the samples */
    }
    return PROBE_BUSY;
}

void foc_fast_step(foc_ctrl_t *c)
{
    foc_port_read_samples(&c->samples);
    foc_bus_check_step(&c->bus, c->samples.vdc);
    if (foc_port_overcurrent_latched() != 0u) {
        /* First, before any posted restart could enable the bridge again.
         * Once: the trip time starts the minimum time before an ack. */
        if ((c->faults.active & (uint16_t)FOC_FAULT_OVERCURRENT) == 0u) {
            trip(c, (uint16_t)FOC_FAULT_OVERCURRENT);
        }
        foc_scope_tick(c->scope);
        return;
    }
    if (c->post != (uint8_t)FOC_POST_NONE) {
        const uint8_t restart = (uint8_t)(c->post != (uint8_t)FOC_POST_HANDOVER);
        take_post(c);
        if (restart != 0u) {
            /* the restart's period applies zero voltage (duties 1/2) and
             * leaves the current loop to the next: one period's work */
            foc_scope_tick(c->scope);
            return;
        }
    }
    switch (c->state) {
    case FOC_STATE_CALIB:
        foc_cs_calib_add(&c->current_sense, &c->samples);
        break;
    case FOC_STATE_ALIGN:
    case FOC_STATE_OPENLOOP:
        /* the forced angle: turned by the slow step in ALIGN, advanced at
         * the forced speed here in OPENLOOP (one writer each) */
        if (c->state == FOC_STATE_OPENLOOP) {
            foc_startup_fast(&c->startup);
        } else {
            lprobe_count(c);
        }
        current_loop(c, FRAME_FORCED);
        break;
    case FOC_STATE_CATCH: {
        const uint8_t probe = (c->probe != 0u) ? catch_probe(c) : PROBE_LOOP;
        lprobe_count(c);
        if (probe != PROBE_BUSY) {
            uint8_t frame = FRAME_ESTIMATE;
            if (lprobe_running(c) != 0u) {
                /* the inductance probe's frame: the estimate at its start
                 * (one period on), turned at the speed CATCH found; the
                 * estimate's own wobble, times the back-EMF in the held
                 * voltage, would swamp the probe's step */
                if (c->lprobe == 1u) {
                    c->startup.theta32 = (uint32_t)c->est.theta << 16;
                }
                foc_startup_fast(&c->startup);
                frame = FRAME_PROBE;
            }
            current_loop(c, frame);
        }
        if (probe == PROBE_LOOP_ENABLE && c->state == FOC_STATE_CATCH) {
            /* once the probe's duties are set (not after the current
             * loop's over-current trip) */
            foc_port_pwm_enable();
        }
        break;
    }
    case FOC_STATE_COMMISSION:
        commission_fast(c);
        break;
    case FOC_STATE_RUN:
    case FOC_STATE_STOP:
    case FOC_STATE_BRAKE:
        /* (BRAKE: until the windings are shorted) */
        if (c->shorting == 0u) {
            current_loop(c, FRAME_ESTIMATE);
        }
        if (c->comm.step == (uint8_t)FOC_COMM_STEP_MECH) {
            foc_comm_mech_fast(&c->comm, c->i_dq.q);
        }
        break;
    default:
        break;
    }
    foc_scope_tick(c->scope);
}

/* ------------------------------------------------------------ start-up -- */

/* Starts (or restarts, for a reversal) in the direction of the speed
 * command: every start-up variable is reset here. */
static void begin_start(foc_ctrl_t *c)
{
    c->direction = (c->req.speed < 0) ? (int8_t)-1 : (int8_t)1;
    const uint8_t on_sensor =
        (uint8_t)(c->opt.sensored_start != 0u || c->est.kind == (uint8_t)FOC_EST_SENSORED);
    c->post_on_sensor = on_sensor;
    const uint8_t catching = (uint8_t)(on_sensor == 0u && c->opt.open_loop_only == 0u);
    post(c, (catching != 0u) ? FOC_POST_CATCH : FOC_POST_RESTART);
    foc_fw_reset(&c->fw);
    foc_speed_stats_reset(&c->speed_stats);
    foc_startup_begin(&c->startup, c->direction);
    reset_run_state(c);
    c->i_ref = zero_dq;
    c->forced_iq_max = FOC_CURRENT_LIMIT;
    if (on_sensor != 0u) {
        foc_sc_preset(&c->speed_ctrl, 0, 0);
        enter(c, FOC_STATE_RUN);
    } else {
        enter(c, (catching != 0u) ? FOC_STATE_CATCH : FOC_STATE_ALIGN);
    }
}

/* An alignment measure's ratio held within [0.5, 2) (Q14). */
static q15_t measured_ratio(int32_t ratio_q14)
{
    return (ratio_q14 < FOC_RATIO_MIN_Q14) ? FOC_RATIO_MIN_Q14 : (ratio_q14 > 32767) ? 32767 : (q15_t)ratio_q14;
}

/* The end of the alignment: the rotor held still on the d axis with
 * STARTUP_ALIGN_CURRENT_A, so vd = Rs id (no EMF, no di/dt; the dead time
 * compensated).  The estimators' Rs becomes that measure, as a ratio to
 * MOTOR_RS_OHM within [0.5, 2): a winding whose resistance differs from
 * the data sheet's (temperature, cables, tolerance) would otherwise show
 * its extra voltage drop as a back-EMF, and a stalled rotor as turning.
 * vd and id as align_average filtered them: one sample's vd carries the
 * current loop's answer to the ADC's noise (2 codes: 4 % RMS of Rs on the
 * Hurst075's realistic plant, 7 % once in 12 seeds). */
static void identify_rs(foc_ctrl_t *c)
{
    const q15_t id = foc_lpf_out(&c->rs_adapt.id);
    if (id < FOC_ALIGN_CURRENT / 2) {
        return; /* not held: no measure */
    }
    const int32_t drop = (int32_t)foc_mul_q15_shift(id, FOC_RS_MANT, FOC_RS_SHIFT); /* Rs id */
    const int32_t ratio = ((int32_t)foc_lpf_out(&c->rs_adapt.vd) * 16384) / ((drop > 0) ? drop : 1);
    foc_est_set_rs(&c->est, measured_ratio(ratio));
}

/* The inductance probe's dip against the one the parameter's Ld gives
 * (FOC_LPROBE_DI): Ld / MOTOR_LD_H, applied to both axes within [0.5, 2).
 * The winding's own decay over the probe, r = Rs T / L (Rs the
 * alignment's), shrinks the dip: ALIGN's by r / 2 (`aligned`: the ratio
 * less FOC_LPROBE_RT_Q14, which is r / 2 at the parameter's L); CATCH's,
 * less half the up half's end (l_probe_caught), by r^2 / 3 only, taken
 * off as (r at the parameter's L)^2 / (3 ratio) (the Hurst075 at 0.6 x
 * its inductance, r = 0.33: 3 % high without it).  A wrong inductance
 * fakes a speed from every torque step (dL / psi) diq/dt, which the speed
 * loop turns back into current (docs/safety.md); every sensorless
 * estimator takes the measure. */
static void identify_ls(foc_ctrl_t *c, int32_t dip, uint8_t aligned)
{
    if (foc_abs_q15(c->i_dq.d) < foc_abs_q15(c->i_ref.d) / 2 || dip <= 0) {
        return; /* not held: no measure */
    }
    /* r / 2 at the parameter's L, Q14 (<= 2^14 x 2 for rs_ratio < 2) */
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t half_r = (FOC_LPROBE_RT_Q14 * (int32_t)c->est.rs_ratio) >> 14;
    int32_t ratio = ((int32_t)FOC_LPROBE_DI * 16384) / dip;
    if (aligned != 0u) {
        ratio -= half_r;
    } else if (ratio > 0) {
        /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
        ratio -= (((4 * half_r * half_r) >> 14) * 16384) / (3 * ratio);
    } else {
        /* no measure: measured_ratio keeps it in range */
    }
    foc_est_set_ls(&c->est, measured_ratio(ratio));
}

/* On to RUN at the estimated speed, the speed PI's integrator at `iq`.  A
 * reversal commanded before (during the start-up, or before a flying
 * start) begins its ramp-down windows here: without that a caught rotor
 * braking to its reversal was judged against a window that began in
 * CATCH, and tripped SPEED_FEEDBACK (tools/flying_start.py: the fan
 * caught at -900 rpm for +750). */
static void enter_run(foc_ctrl_t *c, q15_t iq)
{
    foc_sc_preset(&c->speed_ctrl, c->est.est_speed, iq);
    c->start_ticks = 0;
    c->reversal_speed = foc_abs_q15(c->est.est_speed);
    foc_rs_adapt_reset(&c->rs_adapt, c->v_dq, c->i_dq, c->est.est_speed, c->est.rs_ratio);
    enter(c, FOC_STATE_RUN);
}

/* The rotor caught: RUN at its speed, the probe's d current let go. */
static void catch_run(foc_ctrl_t *c)
{
    c->lprobe_req = 0;
    c->i_ref.d = 0;
    enter_run(c, 0);
}

/* CATCH: zero current on the estimator's angle, so the bridge applies
 * the back-EMF of a rotor that turns and the estimator locks onto it.
 * From FOC_CATCH_TICKS on, a reliable estimate above the start-up minimum
 * is a rotor turning on its own: RUN at its speed, in its direction (the
 * speed loop then follows the command, through a reversal if need be),
 * after the inductance probe if it turns slowly enough for it
 * (FOC_LPROBE_SPEED_MAX): the estimate, locked at zero current, is right
 * whatever the inductance; the speed loop's current steps would not be.
 * The probe holds -FOC_LPROBE_DI on d (no torque, the field weakened a
 * little: a quarter of the alignment current, since -ALIGN would reverse
 * a weak magnet's flux on a drone-like winding and upset the estimate) and runs
 * once that current has settled, or is given up half a FOC_CATCH_TICKS
 * after FOC_CATCH_MAX_TICKS.
 * An estimate that says "turning" but is not steady yet is given until
 * FOC_CATCH_MAX_TICKS: aligning into a turning rotor is what CATCH is
 * there to avoid.  Otherwise the normal start: alignment. */
static void catch_tick(foc_ctrl_t *c)
{
    if (c->lprobe_req != 0u) {
        if (c->lprobe_req < FOC_LPROBE_GO) {
            const int32_t err = (int32_t)c->i_dq.d + FOC_LPROBE_DI;
            c->lprobe_req = (err < FOC_LPROBE_DI / 8 && err > -FOC_LPROBE_DI / 8 &&
                             foc_abs_q15(c->i_dq.q) < FOC_LPROBE_DI / 8)
                                ? (uint8_t)(c->lprobe_req + 1u) : 1u;
            c->startup.speed = c->est.speed; /* the probe's frame turns at it */
            if (c->state_ticks >= FOC_CATCH_MAX_TICKS + (uint16_t)FOC_CATCH_TICKS / 2u) {
                catch_run(c); /* never settled: no measure */
            }
        } else if (c->lprobe == FOC_LPROBE_DONE) {
            identify_ls(c, c->lprobe_peak, 0u);
            catch_run(c);
        } else {
            /* the probe runs */
        }
        return;
    }
    foc_speed_stats_push(&c->speed_stats, c->est.est_speed);
    if (c->state_ticks < (uint16_t)FOC_CATCH_TICKS) {
        return;
    }
    const q15_t mean = foc_speed_stats_mean(&c->speed_stats);
    const uint8_t turning = (uint8_t)(foc_abs_q15(mean) >= FOC_STARTUP_MIN_SPEED);
    if (turning != 0u &&
        /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
        foc_speed_stats_reliable(&c->speed_stats, FOC_STARTUP_VARIANCE_THRESHOLD) &&
        /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
        foc_est_emf_consistent(&c->est, FOC_STALL_EMF_RATIO)) {
        c->direction = (mean < 0) ? (int8_t)-1 : (int8_t)1;
        if ((int32_t)foc_abs_q15(c->est.speed) <= FOC_LPROBE_SPEED_MAX) {
            c->i_ref.d = (q15_t)-FOC_LPROBE_DI;
            c->lprobe_req = 1;
        } else {
            catch_run(c);
        }
        return;
    }
    if (turning != 0u && c->state_ticks < FOC_CATCH_MAX_TICKS) {
        return;
    }
    c->post_on_sensor = 0;
    post(c, FOC_POST_RESTART);
    foc_speed_stats_reset(&c->speed_stats);
    enter(c, FOC_STATE_ALIGN);
}

/* ST's convergence test on the estimated speed ([ST-FOC]) against the
 * speed the rotor is driven at (`driven`: the forced speed, or the sensor's
 * in a sensored start), plus the back-EMF check that rejects a held rotor
 * the estimator "sees" turning. */
static uint8_t estimator_converged(const foc_ctrl_t *c, q15_t driven)
{
    const int32_t mean = foc_speed_stats_mean(&c->speed_stats) * (int32_t)c->direction;
    const int32_t forced = (int32_t)foc_abs_q15(driven);
    return (uint8_t)(foc_speed_stats_reliable(&c->speed_stats, FOC_STARTUP_VARIANCE_THRESHOLD) &&
                     mean >= FOC_STARTUP_MIN_SPEED &&
                     /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
                     mean * 256 >= forced * FOC_STARTUP_WINDOW_MIN_Q8 &&
                     /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
                     mean * 256 <= forced * FOC_STARTUP_WINDOW_MAX_Q8 &&
                     /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
                     foc_est_emf_consistent(&c->est, FOC_STALL_EMF_RATIO));
}

/* Counts consecutive convergence tests; 1 when there have been enough. */
static uint8_t converged_long_enough(foc_ctrl_t *c, q15_t driven)
{
    c->converged_ticks = estimator_converged(c, driven) ? (uint8_t)(c->converged_ticks + 1u) : 0u;
    return (uint8_t)(c->converged_ticks >= (uint16_t)STARTUP_CONV_TESTS);
}

/* On to the estimator's angle: the current reference, held in the frame
 * at `theta_from` (forced angle or sensor), is rotated into the estimated
 * frame by d = theta_from - estimated angle (no step in current); the
 * speed PI starts from that q current and the ramp from the estimated
 * speed; the d part fades out over STARTUP_HANDOVER_TIME_S. */
static void hand_over(foc_ctrl_t *c, uint16_t theta_from)
{
    const foc_sincos_t sc = foc_sincos_q15((uint16_t)(theta_from - c->est.est_theta));
    const foc_ab_t rotated = foc_ipark_q15(c->i_ref, sc);
    const foc_ab_t v_rotated = foc_ipark_q15(c->v_dq, sc);
    c->post_v.d = v_rotated.alpha;
    c->post_v.q = v_rotated.beta;
    c->direction = (c->est.est_speed < 0) ? (int8_t)-1 : (int8_t)1;
    c->i_ref.d = rotated.alpha;
    c->i_ref.q = rotated.beta;
    post(c, FOC_POST_HANDOVER); /* after i_ref: the fast step starts from it */
    c->handover_id = c->i_ref.d;
    enter_run(c, c->i_ref.q);
}

/* ALIGN's slow tick: vd and id filtered over its last quarter for
 * identify_rs, once the rotor has settled on the start angle (16-bit
 * reads of what the fast step writes), in rs_adapt's filters: ALIGN and
 * RUN never overlap. */
static void align_average(foc_ctrl_t *c)
{
    if (c->startup.ticks < FOC_ALIGN_AVG_FROM) {
        return;
    }
    if (c->startup.ticks == FOC_ALIGN_AVG_FROM) {
        foc_lpf_init(&c->rs_adapt.vd, c->v_dq.d);
        foc_lpf_init(&c->rs_adapt.id, c->i_dq.d);
    } else {
        (void)foc_lpf_step(&c->rs_adapt.vd, c->v_dq.d, FOC_ALIGN_AVG_K);
        (void)foc_lpf_step(&c->rs_adapt.id, c->i_dq.d, FOC_ALIGN_AVG_K);
    }
}

static void startup_tick(foc_ctrl_t *c)
{
    if (c->start_ticks >= FOC_STARTUP_TIMEOUT_TICKS) {
        trip(c, (uint16_t)FOC_FAULT_STARTUP_FAILED);
        return;
    }
    if (c->state == FOC_STATE_ALIGN) {
        /* the rotor held at the alignment current while the fast step
         * probes the inductance FOC_LPROBE_REPEAT times, their dips
         * averaged (i_ref unchanged); each after the last has settled,
         * FOC_LPROBE_GO - 1 ticks */
        if (c->lprobe_req != 0u) {
            if (c->lprobe_req != FOC_LPROBE_GO) {
                c->lprobe_req++;
                return;
            }
            if (c->lprobe != FOC_LPROBE_DONE) {
                return;
            }
            c->lprobe_dips += c->lprobe_peak;
            c->lprobe_count++;
            if (c->lprobe_count < FOC_LPROBE_REPEAT) {
                c->lprobe_req = 1u; /* the fast step's count back to 0 */
                return;
            }
            identify_ls(c, c->lprobe_dips / (int32_t)FOC_LPROBE_REPEAT, 1u);
            c->lprobe_req = 0;
            enter(c, FOC_STATE_OPENLOOP);
        } else if (foc_startup_align_tick(&c->startup) != 0u) {
            identify_rs(c);
            c->lprobe_dips = 0;
            c->lprobe_count = 0;
            c->lprobe_req = FOC_LPROBE_GO;
            return;
        } else {
            align_average(c);
        }
    } else {
        const q15_t limit = (c->opt.open_loop_only != 0u) ? foc_abs_q15(c->req.speed)
                                                          : FOC_OL_FINAL_SPEED;
        foc_startup_ramp_tick(&c->startup, limit);
        foc_speed_stats_push(&c->speed_stats, c->est.est_speed);
        if (c->opt.open_loop_only == 0u) {
            if (converged_long_enough(c, c->startup.speed) != 0u) {
                hand_over(c, foc_startup_angle(&c->startup));
                return;
            }
        } else {
            c->start_ticks = 0; /* open loop on purpose: no timeout */
        }
    }
    c->i_ref.d = c->startup.current;
    c->i_ref.q = 0;
    c->forced_iq_max = foc_sc_iq_limit(c->i_ref.d);
}

/* ---------------------------------------------------------- speed loop -- */

/* The d current of a salient rotor: MTPA's for the q current `iq` or
 * field weakening's `id_fw`, the more negative (below base speed MTPA's,
 * above it the voltage asks for more).  `id_fw` where there is no MTPA. */
static q15_t salient_id(const foc_ctrl_t *c, q15_t id_fw, q15_t iq)
{
    if (!FOC_SALIENT || c->fw.mtpa == 0u) {
        return id_fw;
    }
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const q15_t id_mtpa = foc_mtpa_id_q15(iq, FOC_MTPA_K_Q12);
    return (id_mtpa < id_fw) ? id_mtpa : id_fw;
}

/* Sensorless with the dead-time compensation and field weakening on, a
 * light load's d current: what the load's q current lacks of the floor
 * (config.h FOC_DT_MIN_CURRENT: 0 up to 1.25 x the dead time's command
 * floor, rising to it over a quarter of that speed, at most 1/4 of the
 * EMF's ohmic current), else 0.  The load's current is the speed PI's
 * integrator and the speed its ramped reference: taken from the q current
 * and the estimate, the floor's d current followed their ripple, and the
 * estimators' inductance error turned that into speed ripple
 * (docs/estimators.md, "The dead-time current floor").  Not in
 * commissioning's MECH, which takes the friction from the q current: an
 * angle error would turn a share of the floor's d current into torque
 * (the Hurst075's viscous friction 25 % off, commission.hurst075.
 * mech_light).  Field weakening off: no negative d current at all. */
static q15_t dt_floor_id(const foc_ctrl_t *c)
{
    const q15_t w = foc_abs_q15(c->speed_ctrl.ramped);
    if (c->opt.deadtime_comp == 0u || c->est.use_sensor != 0u || c->fw.mode == (uint8_t)FW_MODE_OFF ||
        c->comm.step == (uint8_t)FOC_COMM_STEP_MECH || w <= FOC_DT_MIN_FROM) {
        return 0;
    }
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const q15_t ramp = foc_mul_q15_shift((q15_t)(w - FOC_DT_MIN_FROM), FOC_DT_MIN_RAMP_MANT, FOC_DT_MIN_RAMP_SHIFT);
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const q15_t by_emf = foc_mul_q15_shift(w, FOC_DT_MIN_PER_SPEED_MANT, FOC_DT_MIN_PER_SPEED_SHIFT);
    q15_t floor = (by_emf < FOC_DT_MIN_CURRENT) ? by_emf : FOC_DT_MIN_CURRENT;
    floor = (ramp < floor) ? ramp : floor;
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const q15_t load = foc_sat_q15(c->speed_ctrl.pi.integ >> 15);
    const q15_t short_of = foc_sub_q15(floor, foc_abs_q15(load));
    return (short_of > 0) ? (q15_t)-short_of : 0;
}

/* The d reference in RUN: field weakening's (or the dead-time floor's, or
 * MTPA's) plus the hand-over's fading share, held within the current limit
 * (the two together reached 1.15 x the limit:
 * tests/fuzz/findings/run_id_beyond_limit). */
static q15_t run_id(const foc_ctrl_t *c, q15_t id_fw, q15_t iq)
{
    const q15_t id = foc_add_q15(salient_id(c, id_fw, iq), c->handover_id);
    return (id < -FOC_CURRENT_LIMIT) ? (q15_t)-FOC_CURRENT_LIMIT
           : (id > FOC_CURRENT_LIMIT) ? FOC_CURRENT_LIMIT : id;
}

/* Field weakening first (Id takes its share of the current limit, plus the
 * hand-over current fading out), then the speed PI within what is left.
 * A salient rotor's MTPA d current follows the speed PI's q current: the
 * PI's limit takes last tick's share, and the q current is held within
 * the current limit's circle around the new d current (slow tick: a
 * square root only on salient rotors). */
static void speed_loop(foc_ctrl_t *c, q15_t target)
{
    /* TUNING: the reference creeps toward the command. */
    c->speed_ctrl.target = target;
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    c->speed_ctrl.step15 = (c->opt.tuning != 0u) ? FOC_TUNING_RAMP_STEP15
                           : (c->comm.step == (uint8_t)FOC_COMM_STEP_MECH) ? FOC_COMM_MECH_RAMP_STEP15
                                                                         /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
                                                                         : FOC_SPEED_RAMP_STEP15;
    const q15_t v_mag = foc_mag_q15(c->v_dq.d, c->v_dq.q);
    const q15_t id_fw = foc_fw_step(&c->fw, c->speed_ctrl.ramped, v_mag, c->bus.v_max);
    /* a round rotor's d current: field weakening's, or the dead-time
     * floor's if more negative (MTPA's, if more negative still, in run_id) */
    const q15_t id_floor = dt_floor_id(c);
    const q15_t id_round = (id_floor < id_fw) ? id_floor : id_fw;
    c->handover_id = foc_slew_q15(c->handover_id, 0, FOC_HANDOVER_ID_STEP);
    c->i_ref.d = run_id(c, id_round, c->i_ref.q);
    foc_est_set_fw(&c->est, c->fw.inv_kfi, c->fw.ls_scale);
    /* Out of voltage (within 1/64 of the limit) with field weakening
     * giving all it has (or off): no faster than now, and say so. */
    const uint8_t no_voltage =
        (uint8_t)((int32_t)v_mag * 64 >= (int32_t)c->bus.v_max * 63 &&
                  (c->fw.mode == (uint8_t)FW_MODE_OFF || id_fw <= (q15_t)(-FOC_FW_ID_MAX + FOC_FW_ID_MAX / 32)));
    c->speed_limited = (uint8_t)(no_voltage != 0u && foc_abs_q15(target) > foc_abs_q15(c->est.speed));
    if (c->speed_limited != 0u) {
        foc_sc_hold(&c->speed_ctrl, c->est.speed);
    }
    c->i_ref.q = foc_sc_step(&c->speed_ctrl, c->est.speed, c->i_ref.d);
    if (FOC_SALIENT && c->fw.mtpa != 0u) {
        c->i_ref.d = run_id(c, id_round, c->i_ref.q);
        const q15_t iq_max = foc_sc_iq_limit(c->i_ref.d);
        c->i_ref.q = (c->i_ref.q > iq_max) ? iq_max
                     : (c->i_ref.q < -iq_max) ? (q15_t)-iq_max : c->i_ref.q;
    }
}

/* Step-out / stall (sensorless): ST's reliability statistic, and the
 * back-EMF against the speed the estimator claims, which catches a locked
 * rotor the statistic misses (a rotor jittering on the spot).  The
 * statistic counts only while the reference is in the estimator's range:
 * below it a ramp alone makes the 64-sample variance exceed mean^2 x 1/16.
 * The back-EMF check pauses in a reversal's ramp down, which brakes the
 * rotor at the current limit through the estimator's low end (there the
 * back-EMF is within the resistance's and the dead time's voltage errors:
 * the fan at 150 rpm, seed 5201) and has its own windows. */
static void stall_check(foc_ctrl_t *c, uint8_t reversal)
{
    foc_speed_stats_push(&c->speed_stats, c->est.est_speed);
    if (c->est.use_sensor != 0u || c->speed_stats.count < FOC_SPEED_STATS_N) {
        return; /* nothing to check yet */
    }
    const uint8_t in_range = (uint8_t)(foc_abs_q15(c->speed_ctrl.ramped) >= FOC_STARTUP_MIN_SPEED);
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const uint8_t steady = foc_speed_stats_reliable(&c->speed_stats, FOC_STALL_VARIANCE_THRESHOLD);
    /* the estimate far below the estimator's range (a locked rotor's is
     * steady at standstill within 5 ms): the present one, not the
     * window's mean, which would wait for the window */
    const uint8_t too_slow =
        (uint8_t)((int32_t)c->est.est_speed * c->direction < FOC_STARTUP_MIN_SPEED / 2);
    const uint8_t motoring = (uint8_t)(((int32_t)c->i_ref.q * c->direction) > 0);
    const uint8_t emf_ok = foc_est_emf_consistent(
        &c->est, (motoring != 0u && c->est.kind == (uint8_t)FOC_EST_LUENBERGER)
                     /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
                     ? FOC_STALL_EMF_RATIO_MOTORING : FOC_STALL_EMF_RATIO);
    /* the variance's count leaks (2 up, 1 down): the estimate of a rotor
     * slipping poles looks steady for a moment each turn.  It trips at
     * STALL_TICKS, but with the estimate back within a quarter of the
     * reference only STALL_TICKS beyond the statistic's window: one
     * transient that passed (a load step's dip at low speed) keeps the
     * window unsteady for exactly its length, 32 ms on the boards */
    const int32_t off_abs = foc_abs_q15(foc_sub_q15(c->est.est_speed, c->speed_ctrl.ramped));
    const int32_t ref_abs = foc_abs_q15(c->speed_ctrl.ramped);
    /* (|off| saturates at Q15_MAX, where 4 x it exceeds any ref_abs too) */
    const uint8_t recovered = (uint8_t)(4 * off_abs < ref_abs);
    const uint16_t unsteady_max = (recovered != 0u)
                                      /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
                                      ? (uint16_t)(2u * ((uint16_t)STALL_TICKS + (uint16_t)FOC_SPEED_STATS_N))
                                      : (uint16_t)(2u * (uint16_t)STALL_TICKS);
    if (in_range == 0u) {
        c->unsteady_ticks = 0u;
        c->too_slow_ticks = 0u;
    } else {
        if (steady != 0u) {
            c->unsteady_ticks = (uint16_t)((c->unsteady_ticks != 0u) ? c->unsteady_ticks - 1u : 0u);
        } else {
            c->unsteady_ticks = (uint16_t)(c->unsteady_ticks + 2u);
        }
        c->too_slow_ticks = (too_slow != 0u) ? (uint16_t)(c->too_slow_ticks + 1u) : 0u;
    }
    /* the flux estimator's learned flux is itself slow and slewed (tens of
     * ms to reach its range's end): no second wait (regress/2b) */
    const uint16_t emf_low_max = (c->est.kind == (uint8_t)FOC_EST_FLUX) ? 1u : (uint16_t)STALL_TICKS;
    c->emf_low_ticks =
        (emf_ok != 0u || reversal != 0u) ? 0u : (uint16_t)(c->emf_low_ticks + 1u);
    if (c->unsteady_ticks >= unsteady_max ||
        c->too_slow_ticks >= (uint16_t)STALL_TICKS || c->emf_low_ticks >= emf_low_max) {
        trip(c, (uint16_t)FOC_FAULT_SPEED_FEEDBACK);
    }
}

/* A speed command of the other sign in a sensorless run: ramp down to the
 * estimator's low-speed end, then start again the other way (the
 * estimator cannot follow through standstill). */
static uint8_t reversing(const foc_ctrl_t *c, q15_t command)
{
    return (uint8_t)(c->est.use_sensor == 0u && command != 0 &&
                     (command < 0) != (c->direction < 0));
}

static void stop_or_brake(foc_ctrl_t *c)
{
    switch (c->opt.stop_mode) {
    case STOP_MODE_COAST:
        to_idle(c);
        break;
    case STOP_MODE_SHORT:
        enter(c, FOC_STATE_BRAKE);
        break;
    default:
        c->start_ticks = 0;
        enter(c, FOC_STATE_STOP);
        break;
    }
}

/* |speed| that a reversal's windows compare: the statistic's 64-tick mean
 * once it is full (one estimate of the fan's Luenberger observer swings
 * by 25 rpm against a 37 rpm progress: seed 5585), the estimate before. */
static q15_t reversal_speed_now(const foc_ctrl_t *c)
{
    return foc_abs_q15((c->speed_stats.count >= FOC_SPEED_STATS_N)
                           ? foc_speed_stats_mean(&c->speed_stats)
                           : c->est.speed);
}

static void run_tick(foc_ctrl_t *c)
{
    if (c->est.use_sensor != 0u && c->est.kind != (uint8_t)FOC_EST_SENSORED &&
        foc_abs_q15(c->est.speed) >= FOC_SENSORED_HANDOVER_SPEED) {
        /* Sensored start: on to the estimator once it has converged. */
        c->direction = (c->est.speed < 0) ? (int8_t)-1 : (int8_t)1;
        if (converged_long_enough(c, c->est.speed) != 0u) {
            hand_over(c, c->est.theta);
        }
    }
    /* the command: the user's, or commissioning's (MECH) */
    const uint8_t mech = (uint8_t)(c->comm.step == (uint8_t)FOC_COMM_STEP_MECH);
    const q15_t command = (mech != 0u) ? foc_comm_mech_tick(&c->comm, c->est.speed) : c->req.speed;
    if (mech != 0u && c->comm.step != (uint8_t)FOC_COMM_STEP_MECH) {
        if (c->comm.j_q12 == 0) {
            trip(c, (uint16_t)FOC_FAULT_COMMISSION_FAILED);
        } else {
            stop_or_brake(c);
        }
        return;
    }
    /* start_ticks, unused in RUN, times a reversal's ramp down */
    const uint8_t reversal = reversing(c, command);
    if (reversal != 0u) {
        speed_loop(c, 0);
        if (foc_abs_q15(c->est.speed) <= (q15_t)(FOC_STARTUP_MIN_SPEED / 2)) {
            begin_start(c);
            return;
        }
        if (c->start_ticks >= FOC_RAMP_DOWN_TICKS) {
            /* a window over: on while the rotor slows (a large inertia at
             * the current limit), else it does not slow down */
            const q15_t now = reversal_speed_now(c);
            if ((int32_t)c->reversal_speed - now < FOC_REVERSAL_PROGRESS) {
                trip(c, (uint16_t)FOC_FAULT_SPEED_FEEDBACK);
                return;
            }
            c->reversal_speed = now;
            c->start_ticks = 0;
        }
    } else {
        c->start_ticks = 0;
        c->reversal_speed = reversal_speed_now(c);
        speed_loop(c, command);
    }
    /* the follow check on the command, also through a reversal's ramp
     * down (its target 0): at the current limit there the speed must move
     * toward the new direction, or the estimate is stuck on a rotor that
     * has stopped (a winding resistance the estimator does not know shows
     * its drop as a back-EMF) */
    uint16_t faults = foc_sup_overspeed(&c->sup, c->est.speed);
    /* its windows begin once the hand-over's d current has faded: the fade
     * moves the estimate by a few rpm, which a heavy rotor gains in a
     * window (the fan at 10 x its inertia, seeds 1853, 3515) */
    if (c->handover_id == 0) {
        faults |= foc_sup_follow(&c->sup, command, c->est.speed, c->i_ref.q);
    }
    if (faults != 0u) {
        trip(c, faults);
        return;
    }
    stall_check(c, reversal);
    /* the winding warms: Rs follows (not through the hand-over's fade nor
     * a reversal's ramp down) */
    if (FOC_RS_ADAPT_BUILT && c->opt.rs_adapt != 0u && c->state == FOC_STATE_RUN && c->est.use_sensor == 0u &&
        reversal == 0u && c->handover_id == 0) {
        const q15_t rs = foc_rs_adapt_tick(&c->rs_adapt, c->v_dq, c->i_dq, c->est.speed,
                                           c->est.rs_ratio, c->est.ls_ratio);
        if (rs != c->est.rs_ratio) {
            foc_est_set_rs(&c->est, rs);
        }
    }
    /* the sensors' gain mismatch (from RUN's second tick: the voltage's
     * mean starts at the first) */
    if (c->state_ticks <= 1u) {
        foc_gb_follow(&c->gb, c->v_dq, c->i_dq);
    } else {
        foc_gb_tick(&c->gb, c->est.theta, c->v_dq, c->i_dq, c->est.speed);
    }
    if (c->state == FOC_STATE_RUN && c->pending.stop != 0u) {
        c->comm.step = (uint8_t)FOC_COMM_STEP_NONE; /* MECH abandoned */
        stop_or_brake(c);
    }
}

static void brake_tick(foc_ctrl_t *c)
{
    if (c->shorting != 0u) {
        if (c->state_ticks >= FOC_SHORT_HOLD_TICKS) {
            outputs_off(c);
            c->shorting = 0;
            enter(c, FOC_STATE_IDLE);
        }
        return;
    }
    speed_loop(c, 0);
    if (speed_squared(c->est.speed) <= FOC_SHORT_SAFE_SPEED2) {
        c->shorting = 1;
        c->state_ticks = 0;
        foc_port_low_sides_on();
    } else if (c->state_ticks >= FOC_RAMP_DOWN_TICKS) {
        /* it does not slow down: shorting now could exceed the current
         * limit, so let it coast */
        to_idle(c);
    } else {
        /* slowing down */
    }
}

static void fault_tick(foc_ctrl_t *c)
{
    /* A fault brake keeps the windings shorted until the rotor stands. */
    if (c->shorting != 0u && c->state_ticks >= FOC_SHORT_HOLD_TICKS) {
        c->shorting = 0;
    }
    if (c->shorting == 0u) {
        outputs_off(c);
    }
    if (c->pending.ack == 0u || c->state_ticks < FOC_ACK_MIN_TICKS) {
        return;
    }
    foc_port_overcurrent_clear();
    const uint8_t cooled = (uint8_t)((c->faults.active & (uint16_t)FOC_FAULT_MOTOR_OVERLOAD) == 0u ||
                                     foc_sup_cooled(&c->sup) != 0u);
    if (foc_port_overcurrent_latched() == 0u && cooled != 0u &&
        foc_protection_causes_gone(&c->protection, c->faults.active, c->samples.vdc,
                                   c->samples.temp) != 0u) {
        foc_faults_clear(&c->faults);
        enter(c, FOC_STATE_IDLE);
    }
}

/* FLUX done: the spin goes on in OPENLOOP with the estimator told the
 * measured Rs and Lq, until the start-up's convergence test hands it to
 * RUN, where MECH drives the speed loop (run_tick).  Without a closed
 * loop (open-loop only) there is nothing to measure MECH on. */
static void commission_run(foc_ctrl_t *c)
{
    if (c->opt.open_loop_only != 0u) {
        trip(c, (uint16_t)FOC_FAULT_COMMISSION_FAILED);
        return;
    }
    foc_est_set_rs(&c->est, measured_ratio(c->comm.rs_q14));
    foc_est_set_ls(&c->est, measured_ratio(c->comm.lq_q14));
    c->direction = 1;
    foc_speed_stats_reset(&c->speed_stats);
    c->converged_ticks = 0;
    c->start_ticks = 0;
    enter(c, FOC_STATE_OPENLOOP);
}

/* COMMISSION's slow tick: the sequence (commission.c) drives the forced
 * frame and its d current; the bridge goes on (its controllers from zero)
 * when the offsets are taken; the end is IDLE, a failed step a fault. */
static void commission_tick(foc_ctrl_t *c)
{
    const uint8_t was_off = (uint8_t)(c->comm.mode == (uint8_t)FOC_COMM_MODE_OFF);
    /* cppcheck-suppress misra-c2012-9.2 ; F analyser false positive */
    const foc_comm_in_t in = { c->current_sense.calibrated, c->current_sense.offset,
                               (c->opt.deadtime_comp != 0u) ? c->dt_voltage : (q15_t)0 };
    const foc_comm_status_t status = foc_comm_tick(&c->comm, &c->startup, &in);
    /* the measured dead time from RS on: FLUX's voltage and MECH's
     * estimator (then the drive's, until a reset) see the bridge's own */
    if (c->comm.dt_q14 != 0) {
        /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
        c->dt_voltage = (q15_t)(((int32_t)FOC_DT_VOLTAGE * c->comm.dt_q14) >> 14);
    }
    if (status == FOC_COMM_FAILED) {
        trip(c, (uint16_t)FOC_FAULT_COMMISSION_FAILED);
        return;
    }
    if (status == FOC_COMM_HANDOVER) {
        commission_run(c);
        return;
    }
    if (status == FOC_COMM_DONE) {
        to_idle(c);
        return;
    }
    if (was_off != 0u && c->comm.mode != (uint8_t)FOC_COMM_MODE_OFF) {
        c->post_on_sensor = 0;
        post(c, FOC_POST_RESTART);
    }
    c->i_ref.d = c->startup.current;
    c->i_ref.q = 0;
    c->forced_iq_max = foc_sc_iq_limit(c->i_ref.d);
}

static void state_machine(foc_ctrl_t *c)
{
    if (c->state == FOC_STATE_CATCH || c->state == FOC_STATE_ALIGN ||
        c->state == FOC_STATE_OPENLOOP || c->state == FOC_STATE_RUN ||
        c->state == FOC_STATE_STOP) {
        foc_est_track_flux(&c->est);
    }
    switch (c->state) {
    case FOC_STATE_IDLE:
        if (c->pending.commission != 0u) {
            foc_cs_calib_start(&c->current_sense, FOC_COMM_CALIB_PERIODS_LOG2);
            outputs_off(c);
            reset_run_state(c);
            foc_comm_begin(&c->comm);
            enter(c, FOC_STATE_COMMISSION);
        } else if (c->pending.start != 0u) {
            foc_cs_calib_start(&c->current_sense, FOC_CALIB_PERIODS_LOG2);
            outputs_off(c);
            c->start_ticks = 0;
            enter(c, FOC_STATE_CALIB);
        } else {
            /* no request */
        }
        break;
    case FOC_STATE_CALIB:
        if (c->pending.stop != 0u) {
            enter(c, FOC_STATE_IDLE);
        } else if (c->current_sense.calibrated != 0u && c->state_ticks >= FOC_CALIB_TICKS) { /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
            begin_start(c);
        } else {
            /* calibrating */
        }
        break;
    case FOC_STATE_CATCH:
    case FOC_STATE_ALIGN:
    case FOC_STATE_OPENLOOP:
        if (c->pending.stop != 0u) {
            to_idle(c);
        } else if (c->state == FOC_STATE_CATCH) {
            catch_tick(c);
        } else {
            startup_tick(c);
        }
        break;
    case FOC_STATE_RUN:
        run_tick(c);
        break;
    case FOC_STATE_STOP: {
        speed_loop(c, 0);
        /* down to the stop speed (the reference and the speed within it,
         * the speed with a quarter's lag), or (an estimate that never
         * settles) out of time: FOC_STOP_SETTLE_TICKS after the ramp
         * reached zero (start_ticks, unused in STOP, counts them) or the
         * ramp from the maximum speed and those: outputs off either way */
        const q15_t stop_speed = (c->est.use_sensor != 0u) ? FOC_STOP_SPEED : FOC_STOP_SPEED_ESTIMATED;
        if (c->speed_ctrl.ramped != 0) {
            c->start_ticks = 0;
        }
        if ((foc_abs_q15(c->speed_ctrl.ramped) <= stop_speed &&
             /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
             foc_abs_q15(c->est.speed) <= stop_speed + (stop_speed >> 2)) ||
            c->start_ticks >= FOC_STOP_SETTLE_TICKS || c->state_ticks >= FOC_RAMP_DOWN_TICKS) {
            to_idle(c);
        }
        break;
    }
    case FOC_STATE_BRAKE:
        brake_tick(c);
        break;
    case FOC_STATE_COMMISSION:
        if (c->pending.stop != 0u) {
            to_idle(c);
        } else {
            commission_tick(c);
        }
        break;
    default:
        fault_tick(c);
        break;
    }
}

/* Each count read once: a request is pending for one tick, then dropped
 * if the state had no use for it. */
static uint8_t take_request(uint8_t asked, uint8_t *seen)
{
    const uint8_t moved = (uint8_t)(asked != *seen);
    *seen = asked;
    return moved;
}

void foc_slow_step(foc_ctrl_t *c)
{
    c->pending.start = take_request(c->req.asked.start, &c->seen.start);
    c->pending.stop = take_request(c->req.asked.stop, &c->seen.stop);
    c->pending.ack = take_request(c->req.asked.ack, &c->seen.ack);
    c->pending.commission = take_request(c->req.asked.commission, &c->seen.commission);
    foc_bus_update(&c->bus, c->samples.vdc);
    if (c->state_ticks < UINT16_MAX) {
        c->state_ticks++;
    }
    if (c->start_ticks < UINT16_MAX) {
        c->start_ticks++;
    }
    /* the winding heats with the current of the loop, cools otherwise */
    const uint8_t loop_on = (uint8_t)(((c->state >= FOC_STATE_ALIGN && c->state <= FOC_STATE_BRAKE) ||
                                       c->state == FOC_STATE_CATCH || c->state == FOC_STATE_COMMISSION) &&
                                      c->shorting == 0u);
    const uint16_t faults =
        (uint16_t)(foc_protection_check(&c->protection, c->samples.vdc, c->samples.temp) |
                   foc_sup_thermal(&c->sup, loop_on ? c->i_dq : zero_dq));
    if (faults != 0u) {
        if (c->state != FOC_STATE_FAULT) {
            trip(c, faults);
        } else {
            /* a new cause during a fault joins the set, so the acknowledge
             * waits for it too (the fault's timer keeps running) */
            c->faults.active = (uint16_t)(c->faults.active | faults);
        }
    }
    state_machine(c);
    /* the inverse Park's advance for the fast step: SAMPLE_DELAY_PERIODS
     * of rotation at the speed of the frame it runs in */
    const uint8_t forced = (uint8_t)(c->state == FOC_STATE_ALIGN || c->state == FOC_STATE_OPENLOOP ||
                                     c->state == FOC_STATE_COMMISSION);
    const q15_t speed = (forced != 0u) ? c->startup.speed : c->est.speed;
    c->advance_sc = foc_sincos_q15((uint16_t)foc_mul_q15(speed, FOC_ADVANCE_GAIN));
}

void foc_cmd_start(foc_ctrl_t *c)
{
    c->req.asked.start = (uint8_t)(c->req.asked.start + 1u);
}

void foc_cmd_stop(foc_ctrl_t *c)
{
    c->req.asked.stop = (uint8_t)(c->req.asked.stop + 1u);
}

void foc_cmd_ack(foc_ctrl_t *c)
{
    c->req.asked.ack = (uint8_t)(c->req.asked.ack + 1u);
}

void foc_cmd_commission(foc_ctrl_t *c)
{
    c->req.asked.commission = (uint8_t)(c->req.asked.commission + 1u);
}

void foc_cmd_speed(foc_ctrl_t *c, q15_t speed)
{
    /* never beyond the motor's maximum speed, whatever is asked, and
     * without a sensor not below the lowest speed the estimate holds */
    const q15_t lowest = (c->est.kind == (uint8_t)FOC_EST_SENSORED) ? 0 : c->opt.min_speed;
    c->req.speed = (speed > FOC_MAX_SPEED)                  ? FOC_MAX_SPEED
                   : (speed < -FOC_MAX_SPEED)               ? (q15_t)-FOC_MAX_SPEED
                   : (speed > 0 && speed < lowest)          ? lowest
                   : (speed < 0 && speed > (q15_t)-lowest)  ? (q15_t)-lowest
                                                            : speed;
}

const char *foc_state_name(foc_state_t s)
{
    static const char *const names[] = {
        "IDLE", "CALIB", "ALIGN", "OPENLOOP", "RUN", "STOP", "BRAKE", "FAULT", "CATCH",
        "COMMISSION",
    };
    return ((unsigned)s < sizeof names / sizeof names[0]) ? names[s] : "?";
}
