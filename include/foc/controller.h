/*
 * The controller: the per-PWM-period current loop and the slow-tick speed
 * loop and state machine, composed from the blocks in this directory.
 *
 * Entry points (called by the port):
 *   foc_fast_step()  once per PWM period, after the ADC conversion:
 *                    samples -> Clarke/Park -> estimator -> current PI ->
 *                    voltage limit -> inverse Park -> bus compensation ->
 *                    SVM -> duties for the next period.  Also checks the
 *                    hardware over-current latch every period, and
 *                    the sampled current against its trip level
 *                    (config.h FOC_CURRENT_TRIP_SQ_Q30) wherever the
 *                    current loop runs.
 *   foc_slow_step()  every CONTROL_SLOW_DIVIDER periods, lower priority:
 *                    bus filter, protection, speed ramp and PI, field
 *                    weakening, start-up sequencing, stall detection, the
 *                    state machine.
 * Commands (from buttons, the monitor or focsim) only set requests, which
 * the slow step acts on: foc_cmd_start/stop/ack/speed.
 *
 * Concurrency: the fast step may preempt the slow step (never the other
 * way round).  Every field of foc_ctrl_t has one writer, marked below:
 * [fast] the fast step, [slow] the slow step, [cmd] the foc_cmd_*()
 * calls, [init] foc_init() and the application before the interrupts run.
 * A field another context reads is at most 16 bits (one store on both
 * targets) or read only where a torn value is harmless (documented).
 * What the slow step needs done to fast-owned state (resetting the
 * estimator and the current controllers for a start, presetting the
 * controllers at the hand-over) it posts: it writes the request's data,
 * then `post` (one byte store); the fast step does the work at the start
 * of its next period and clears `post`.  A slow tick is several periods,
 * so a request is always taken before the next is posted.  The slow step
 * changes the state last, after posting.
 *
 * States:
 *   IDLE --start--> CALIB (outputs off, current offsets)
 *     sensorless: --> CATCH (zero current, the estimator running: a rotor
 *                 already turning is caught and goes to RUN at its own
 *                 speed) --> ALIGN --> OPENLOOP (forced angle, estimator
 *                 running)
 *                 --estimator converged--> RUN (bumpless hand-over)
 *                 no convergence within STARTUP_TIMEOUT_S: STARTUP_FAILED
 *     sensored (or the host's sensored start): --> RUN
 *   RUN --stop--> STOP (ramp down) | BRAKE (ramp to the safe speed, then
 *                 windings shorted) | coast (outputs off) --> IDLE
 *   RUN, reference of the other sign (sensorless): ramp down to low speed,
 *                 then ALIGN and start again in the new direction.
 *   any state --fault--> FAULT (outputs off, or windings shorted with
 *                 FAULT_BRAKE) --ack after
 *                 FAULT_ACK_MIN_TIME_S with every cause gone--> IDLE
 *   IDLE --commission--> COMMISSION (commission.h: offsets, Rs, Ld, Lq,
 *                 flux) --> IDLE with the results | FAULT COMMISSION_FAILED
 * Protection (bus, temperature, over-current) is active in every state.
 */
#ifndef FOC_CONTROLLER_H
#define FOC_CONTROLLER_H

#include <stdint.h>
#include "foc/bus.h"
#include "foc/commission.h"
#include "foc/current_ctrl.h"
#include "foc/current_sense.h"
#include "foc/estimator.h"
#include "foc/faults.h"
#include "foc/field_weakening.h"
#include "foc/port.h"
#include "foc/protection.h"
#include "foc/rs_adapt.h"
#include "foc/speed_ctrl.h"
#include "foc/speed_stats.h"
#include "foc/startup.h"
#include "foc/supervision.h"

struct foc_scope; /* foc/scope.h: capture and debug-output selection */

typedef enum {
    FOC_STATE_IDLE = 0,
    FOC_STATE_CALIB,
    FOC_STATE_ALIGN,
    FOC_STATE_OPENLOOP,
    FOC_STATE_RUN,
    FOC_STATE_STOP,
    FOC_STATE_BRAKE,
    FOC_STATE_FAULT,
    FOC_STATE_CATCH, /* start: zero current while the estimator looks */
                     /* for a rotor already turning (then RUN, else ALIGN) */
    FOC_STATE_COMMISSION /* self-commissioning (commission.h), from IDLE */
} foc_state_t;
#define FOC_STATE_LAST FOC_STATE_COMMISSION

typedef enum {
    STOP_MODE_RAMP = 0,  /* ramp down, then outputs off */
    STOP_MODE_COAST = 1, /* outputs off at once */
    STOP_MODE_SHORT = 2  /* ramp to the safe speed, then low sides on */
} foc_stop_mode_t;

/* Work posted by the slow step for the fast step (foc_ctrl_t.post). */
typedef enum {
    FOC_POST_NONE = 0,
    FOC_POST_RESTART,  /* estimator from rest (post_on_sensor), current */
                       /* controllers and voltages zero, duties at 1/2, */
                       /* bridge on unless the state is IDLE or FAULT */
    FOC_POST_HANDOVER, /* current controllers preset to post_v, the */
                       /* estimator's own angle used from now on */
    FOC_POST_CATCH     /* RESTART for CATCH: the bridge off, its probe */
                       /* first (controller.c, catch_probe) */
} foc_post_t;

/* One-shot requests, counted: each foc_cmd_*() call adds one to its count
 * [cmd], and the slow step acts on a count that moved since its last tick.
 * The slow step never writes a count, so a request made while it runs (a
 * command from an interrupt that preempts it) is taken at the next tick
 * instead of being cleared unseen. */
typedef struct {
    uint8_t start;
    uint8_t stop;
    uint8_t ack;
    uint8_t commission; /* IDLE: measure the motor (commission.h) */
} foc_oneshots_t;

/* Requests from the application [cmd]. */
typedef struct {
    foc_oneshots_t asked; /* counts, modulo 256 */
    q15_t speed;          /* speed command, Q15 of SPEED_BASE_RPM, signed */
} foc_requests_t;

/* Operating options, from userparms.h at foc_init; changeable in IDLE. */
typedef struct {
    foc_stop_mode_t stop_mode;
    uint8_t open_loop_only; /* OPEN_LOOP_FUNCTIONING: never hand over */
    uint8_t tuning;         /* TUNING: slow speed-reference ramp */
    uint8_t sensored_start; /* run on the position sensor until the */
                            /* hand-over speed (boards with a sensor) */
    uint8_t deadtime_comp;  /* DEADTIME_COMPENSATION (deadtime.h) */
    uint8_t fault_brake;    /* FAULT_BRAKE: a fault shorts the windings */
                            /* (below the safe speed, not for over-current) */
    uint8_t rs_adapt;       /* RS_ADAPTATION: Rs follows the winding's */
                            /* warming in RUN (rs_adapt.h) */
    q15_t min_speed;        /* SENSORLESS_MIN_SPEED_RPM, Q15 of the speed */
                            /* base: sensorless commands raised to it */
} foc_options_t;

typedef struct {
    foc_state_t state;      /* [slow]; the fast step sets FAULT on an */
                            /* over-current, latched or sampled (then the */
                            /* slow step only acknowledges) */
    foc_faults_t faults;    /* [slow], [fast] on an over-current: */
                            /* raised in the same period, the slow step */
                            /* merges and clears only in FAULT */
    foc_requests_t req;     /* [cmd] */
    foc_oneshots_t seen;    /* [slow] req.asked at the last tick */
    foc_oneshots_t pending; /* [slow] 1: asked since the tick before */
    foc_options_t opt;      /* [init] (changeable in IDLE) */
    uint8_t post;           /* foc_post_t: [slow] sets, [fast] clears */
    uint8_t post_on_sensor; /* [slow] RESTART: run on the sensor */
    foc_dq_t post_v;        /* [slow] HANDOVER: the controllers' voltage */

    /* last period's measurements and commands (Q15 per-unit) */
    foc_samples_t samples;  /* [fast]; the slow step reads vdc, temp */
    foc_ab_t i_ab;          /* [fast] */
    foc_dq_t i_dq;          /* [fast]; I2t reads it (a torn pair is one */
                            /* period's mix) */
    foc_dq_t i_ref;         /* [slow] current references */
    foc_sincos_t advance_sc; /* [slow] sin/cos of the inverse Park's */
                             /* advance (SAMPLE_DELAY_PERIODS of rotation) */
    foc_dq_t i_ref_slewed;  /* [fast] i_ref approached by a step of */
                            /* FOC_IREF_STEP_BITS */
                            /* per period (equal to it in the forced */
                            /* frame; held during the inductance */
                            /* probe) */
    foc_dq_t v_dq;          /* [fast] voltage command, Q15 of the voltage */
                            /* base; field weakening reads its magnitude */
    foc_ab_t v_ab;          /* [fast] the same in the stator frame: */
                            /* applied during the next period */
    foc_ab_t v_ab_prev;     /* [fast] computed one step earlier: being */
                            /* applied now */
    foc_duty_t duty;        /* [fast] */
    uint8_t probe;          /* [fast] CATCH's probe: periods since the */
                            /* restart, 0 once done */
    uint8_t lprobe_req;     /* [slow] the inductance probe (ALIGN, CATCH) */
                            /* is wanted: FOC_LPROBE_GO (held until its */
                            /* result is read), below while its hold */
                            /* current settles, 0 not */
    uint8_t lprobe;         /* [fast] its period (1..FOC_LPROBE_PERIODS), */
                            /* FOC_LPROBE_DONE once over, 0 when not asked; */
                            /* the voltage it steps from: the d PI's */
                            /* integrator, left as it was */
    uint8_t lprobe_count;   /* [slow] ALIGN's probes so far */
    int32_t lprobe_dips;    /* [slow] the sum of their dips, Q15 */
    foc_protection_t protection; /* [slow] */

    foc_current_sense_t current_sense; /* [slow] starts a calibration in */
                                       /* IDLE, [fast] sums in CALIB */
    foc_gain_balance_t gb;             /* [slow]; [fast] reads its Q15 Gh */
    foc_current_ctrl_t current_ctrl;   /* [fast] (gains [init]) */
    foc_speed_ctrl_t speed_ctrl;       /* [slow] */
    foc_fw_t fw;                       /* [slow] */
    foc_bus_t bus;                     /* [slow], and [fast] on a step */
                                       /* (bus.h); 16-bit fields */
    foc_estimator_t est;               /* [fast]; [slow] sets the field- */
                                       /* weakening constants (16-bit) */
                                       /* and owns the PLL's flux tracking */
                                       /* (flux_corr, 16-bit, read fast) */
    foc_startup_t startup;             /* [slow]; [fast] advances theta32 */
                                       /* in OPENLOOP and in CATCH's */
                                       /* inductance probe only (the slow */
                                       /* step turns it in ALIGN only, */
                                       /* sets the speed CATCH's probe */
                                       /* turns at before it runs) */
    foc_speed_stats_t speed_stats;     /* [slow] */
    foc_rs_adapt_t rs_adapt;           /* [slow] online Rs (rs_adapt.h); */
                                       /* its vd, id also ALIGN's Rs measure */
    foc_supervision_t sup;             /* [slow] */
    foc_comm_t comm;                   /* commissioning: [slow] its */
                                       /* sequence, [fast] its sums */
                                       /* (commission.h); the results */
                                       /* stay until the next one */

    int8_t direction;       /* [slow] +1 / -1: direction of the present run */
    uint8_t converged_ticks; /* [slow] consecutive start-up convergence tests */
    uint8_t shorting;       /* [slow] BRAKE: windings shorted */
    uint8_t speed_limited;  /* [slow] status: the command is beyond what the */
                            /* voltage reaches; the speed is held there */
    q15_t handover_id;      /* [slow] forced d current fading out after */
                            /* the hand-over */
    q15_t forced_iq_max;    /* [slow] start-up: the q current the forced d */
                            /* current leaves inside the limit */
    q15_t reversal_speed;   /* [slow] |speed| where a reversal's window */
                            /* began (it must slow down in each) */
    q15_t dt_voltage;       /* [slow] the phase voltage a dead time loses, */
                            /* Q15 of the voltage base (deadtime.h): */
                            /* FOC_DT_VOLTAGE, commissioning's measure */
                            /* from its RS step on (read fast) */
    uint16_t start_ticks;   /* [slow] slow ticks since `start` (start-up */
                            /* timeout; in RUN, a reversal's ramp down) */
    uint16_t unsteady_ticks; /* [slow] stall detection: the speed statistic */
                             /* unsteady (leaky, 2 up 1 down), */
    uint16_t too_slow_ticks; /* [slow] its mean far below the range, */
    uint16_t emf_low_ticks;  /* [slow] the back-EMF below its speed's */
    uint16_t state_ticks;   /* [slow] slow ticks spent in the present state */
    q15_t lprobe_peak;      /* [fast] the largest deviation of the current */
                            /* from its reference during the inductance */
                            /* probe (here: no padding) */
    foc_dq_t lprobe_dip;    /* [fast] CATCH: that deviation's vector, and */
    uint8_t lprobe_dip_k;   /* its period (0: taken) */
    struct foc_scope *scope; /* [init] NULL: none (debug outputs id, iq); */
                             /* the application attaches one after foc_init */
} foc_ctrl_t;

/* Everything to rest: IDLE, no fault, outputs off, options from
 * userparms.h. */
void foc_init(foc_ctrl_t *c);

void foc_fast_step(foc_ctrl_t *c);
void foc_slow_step(foc_ctrl_t *c);

void foc_cmd_start(foc_ctrl_t *c);
void foc_cmd_stop(foc_ctrl_t *c);
void foc_cmd_ack(foc_ctrl_t *c);
/* From IDLE: self-commissioning (commission.h), back to IDLE with
 * c->comm.valid, or FAULT COMMISSION_FAILED naming c->comm.failed_step.
 * The rotor turns (the flux's I/f spin) and coasts at the end. */
void foc_cmd_commission(foc_ctrl_t *c);
/* Speed command, Q15 of SPEED_BASE_RPM (mechanical), signed. */
void foc_cmd_speed(foc_ctrl_t *c, q15_t speed);

/* "IDLE", "CALIB", "ALIGN", "OPENLOOP", "RUN", "STOP", "BRAKE", "FAULT", "CATCH",
 * "COMMISSION". */
const char *foc_state_name(foc_state_t s);

#endif /* FOC_CONTROLLER_H */
