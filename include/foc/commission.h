/*
 * Self-commissioning (issue 12, docs/commissioning.md): the motor's Rs,
 * Ld, Lq and flux linkage measured through the port, as ratios to the
 * userparms.h values the firmware was built with.
 *
 * The controller runs it in FOC_STATE_COMMISSION (foc_cmd_commission from
 * IDLE), MECH in OPENLOOP and RUN, and ends in IDLE (after a STOP) with
 * `valid` set (and j_q12 when MECH ran), or in FAULT COMMISSION_FAILED
 * with `failed_step` (`valid` still set if only MECH failed).  This block holds the sequence (foc_comm_tick, one
 * slow tick) and its arithmetic; the per-period work it asks for
 * (foc_comm_mode_t) is the controller's forced-frame current loop plus
 * foc_comm_sum, or the inductance pulses of foc_comm_pulse.
 *
 * Steps (each with a timeout, FOC_COMM_STEP_TIMEOUT_TICKS):
 *   OFFSETS  bridge off: the current sense's calibration; an offset beyond
 *            FOC_COMM_OFFSET_MAX fails.
 *   ALIGN    the start-up's alignment to angle 0, then the rotor settles.
 *   RS       d current FOC_COMM_I_HIGH then FOC_COMM_I_LOW, each held and
 *            summed over FOC_COMM_SUM_N periods: Rs = dVd / dId (the
 *            dead time's and the switches' drop, the same at both, cancel);
 *            the line's intercept is what the bridge model misses of
 *            them: the bridge's effective dead time.
 *   LD, LQ   held at FOC_COMM_I_LOW on d, a square wave of +-dV on one
 *            axis; the current's slope over each half by least squares,
 *            which is a weighted mean of di/dt = (dV - Rs (i - i_hold)) / L:
 *            the same weights on the current give Rs's share, so
 *            L = (dV - Rs <i - i_hold>) / slope at any Rs / L.
 *   FLUX     I/f spin at FOC_COMM_SPIN_SPEED (the start-up's ramp and
 *            current); in the forced frame E = V - Rs I - j w Lq I lies on
 *            the rotor's q axis, |E| = w (psi + (Ld - Lq) id_rotor).
 *   MECH     the controller hands the spin over to the estimator (the
 *            start-up's convergence test, the measured Rs and Lq given to
 *            the estimator) and runs the speed loop on the speeds of
 *            foc_comm_mech_tick: held at FOC_COMM_MECH_LOW, the q current
 *            summed (the friction there); a window up to _HIGH; the
 *            friction at _HIGH; a window down.  With the friction linear
 *            in speed, i_f = i_low + s (w - w_low), the windows' q current
 *            sums A and speed sums W give 2 J dw = Kt Ts I_base (A_up -
 *            A_down - s (W_up - W_down)): the Coulomb part cancels, the
 *            profile within the windows does not matter, only that each
 *            starts and ends settled.  Kt is the measured flux's.
 *            Only with the measured flux, Ld and Lq within 15 % of the
 *            parameters (FOC_COMM_MECH_MATCH_*): the estimators run on
 *            the parameters, and 50 % off (shinano_la052's flux) the
 *            PLL's angle was off enough to make J 18 % high; the drone
 *            with Ld 0.7 and Lq 1.3 x its parameters lost its estimate in
 *            the spin's d current.  Otherwise the sequence ends after
 *            FLUX: rebuilt with the measured values, a second
 *            commissioning measures J and the friction.
 * Results, Q14 ratios to the parameter (16384 = 1.0), accepted within
 * [0.25, 2): outside, the step fails (an open winding, a rotor that does
 * not follow, a sensor that reads nothing).
 *
 * Concurrency as in controller.h: [slow] fields written by foc_comm_tick,
 * [fast] by foc_comm_sum / foc_comm_pulse; the slow step reads the sums
 * only once `count` says the fast step is done with them.
 */
#ifndef FOC_COMMISSION_H
#define FOC_COMMISSION_H

#include <stdint.h>
#include "foc/config.h"
#include "foc/q15.h"
#include "foc/startup.h"
#include "foc/transforms.h"

typedef enum {
    FOC_COMM_STEP_NONE = 0,
    FOC_COMM_STEP_OFFSETS,
    FOC_COMM_STEP_ALIGN,
    FOC_COMM_STEP_RS,
    FOC_COMM_STEP_LD,
    FOC_COMM_STEP_LQ,
    FOC_COMM_STEP_FLUX,
    FOC_COMM_STEP_MECH
} foc_comm_step_t;

/* What the fast step runs (foc_comm_t.mode). */
typedef enum {
    FOC_COMM_MODE_OFF = 0, /* bridge off (offsets: the calibration sums) */
    FOC_COMM_MODE_HOLD,    /* forced-frame current loop on the startup's */
    FOC_COMM_MODE_SUM,     /* angle, SUM: and foc_comm_sum */
    FOC_COMM_MODE_PULSE_D, /* the held voltages plus foc_comm_pulse on d */
    FOC_COMM_MODE_PULSE_Q, /* ... on q */
    FOC_COMM_MODE_SPIN,    /* HOLD with the forced angle turning */
    FOC_COMM_MODE_SPIN_SUM /* SPIN and foc_comm_sum */
} foc_comm_mode_t;

typedef enum {
    FOC_COMM_BUSY = 0,
    FOC_COMM_DONE,     /* FLUX done, MECH not run (see MECH above) */
    FOC_COMM_HANDOVER, /* FLUX done: the spin on to RUN for MECH */
    FOC_COMM_FAILED
} foc_comm_status_t;

typedef struct {
    uint8_t step;        /* [slow] foc_comm_step_t */
    uint8_t mode;        /* [slow] foc_comm_mode_t */
    uint8_t level;       /* [slow] RS: 0 the high current, 1 the low; */
                         /* ALIGN, FLUX: 0 the start-up's part, 1 the */
                         /* rotor settling; MECH: foc_comm_mech_tick's */
    uint8_t failed_step; /* [slow] foc_comm_step_t that failed, 0 none */
    uint8_t valid;       /* [slow] 1: the results below are measured */
    uint8_t fast_mode;   /* [fast] the mode its sums belong to */
    uint8_t phase;       /* [fast] pulse: period in the cycle, 0 .. 2N-1 */
    uint16_t cycles;     /* [fast] pulse: cycles done (2 settle first) */
    uint16_t count;      /* [fast] periods (SUM, MECH) or cycles (PULSE) */
                         /* summed; its target reached: the sums are the */
                         /* slow's (MECH: it takes iq_block, then clears) */
    uint16_t ticks;      /* [slow] slow ticks in the step */
    int32_t sum[4];      /* [fast] SUM: vd, vq, id, iq (Q15 x 2^12); */
                         /* PULSE: sum[0] the regression sum u x di, */
                         /* sum[1] the weighted deviation (2V x di) / 16 */
                         /* (commission.c, foc_comm_pulse); */
                         /* [slow] MECH (RUN: the fast step leaves them): */
                         /* the windows' q current and speed sums (Q15 x */
                         /* ticks), up: sum[0], sum[1]; down: sum[2], sum[3] */
    int32_t iq_block;    /* [fast] MECH: the q current (Q15) summed over */
                         /* CONTROL_SLOW_DIVIDER periods (the mean of a */
                         /* whole slow tick: a sample once a tick would */
                         /* see the speed loop's steps at one phase) */
    union {
        struct {         /* [slow] RS: the high level's vd and id sums */
            int32_t v_high;
            int32_t i_high;
        } rs;
        struct {         /* [slow] MECH's results: the q current held at */
            int32_t low; /* FOC_COMM_MECH_LOW and _HIGH, summed over */
            int32_t high;/* FOC_COMM_MECH_SUM_N ticks (Q15 x 2^12): the */
        } friction_i;    /* friction's (no load on the shaft) */
    } u;
    /* results, Q14 ratios to MOTOR_RS_OHM, MOTOR_LD_H, MOTOR_LQ_H and
     * the flux of MOTOR_KE_VPK_PER_KRPM, in [4096, 32767] when valid */
    q15_t rs_q14;
    q15_t ld_q14;
    q15_t lq_q14;
    q15_t flux_q14;
    q15_t j_q12;         /* J / MOTOR_INERTIA_KGM2, Q12, [256, 32767] */
                         /* when MECH measured it, else 0 */
    q15_t dt_q14;        /* the bridge's effective dead time (config.h) */
                         /* / DEADTIME_EFFECTIVE_S, Q14, [1, 32767] */
                         /* from RS on; 0 before, or in a build */
                         /* without dead time */
} foc_comm_t;

/* Inputs of a slow tick from the controller. */
typedef struct {
    uint8_t calibrated;  /* the current sense's offsets are taken */
    foc_abc_t offset;    /* and these they are (Q15) */
    q15_t dt_model;      /* the dead-time voltage (deadtime.h) whose */
                         /* error the voltage summed holds (0: the bare */
                         /* command, the compensation off) */
} foc_comm_in_t;

/* At rest: no commissioning has run, no results (foc_init). */
void foc_comm_init(foc_comm_t *m);

/* Starts the sequence (OFFSETS, bridge off); the results are forgotten. */
void foc_comm_begin(foc_comm_t *m);

/* One slow tick: the sequence.  Drives the forced frame and its current
 * (su->theta32, su->speed, su->current: the controller's d reference). */
foc_comm_status_t foc_comm_tick(foc_comm_t *m, foc_startup_t *su, const foc_comm_in_t *in);

/* SUM / SPIN_SUM, once per period after the current loop: the forced
 * frame's voltage command and current (Q15). */
void foc_comm_sum(foc_comm_t *m, foc_dq_t v, foc_dq_t i);

/* PULSE_D / PULSE_Q, once per period: `i_axis`, the pulsed axis's current
 * sampled this period, less `i_hold`, the current held on it (Q15), joins
 * the regression; returns the voltage to add to that axis's held voltage
 * this period (Q15, +-dV). */
q15_t foc_comm_pulse(foc_comm_t *m, q15_t i_axis, q15_t i_hold);

/* MECH, once per period of RUN: the q current measured (Q15) joins the
 * block the slow step takes (|sum| < 255 x 2^15). */
static inline void foc_comm_mech_fast(foc_comm_t *m, q15_t iq)
{
    if (m->count < (uint16_t)CONTROL_SLOW_DIVIDER) {
        m->iq_block += iq;
        m->count++;
    }
}

/* MECH, one slow tick of RUN: the estimated speed (Q15); returns the
 * speed command.  At the end j_q12 is set and the step is NONE (the
 * controller then stops the motor); a result out of range fails the
 * step (failed_step MECH, the step NONE). */
q15_t foc_comm_mech_tick(foc_comm_t *m, q15_t speed);

/* "NONE", "OFFSETS", "ALIGN", "RS", "LD", "LQ", "FLUX", "MECH". */
const char *foc_comm_step_name(uint8_t step);

#endif /* FOC_COMMISSION_H */
