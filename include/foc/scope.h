/*
 * Scope: trigger-based capture of up to FOC_SCOPE_CHANNELS controller
 * variables into a RAM buffer the application provides, one frame (one
 * value per channel) every `decim` PWM periods, and the selection of what
 * the port's two "DAC" debug outputs carry.
 *
 * Variables: foc_var_t names every Q15/uint16 quantity of foc_ctrl_t worth
 * watching; foc_var_info() gives its name, unit and full scale (the
 * physical value of 32768 counts), so a host tool can convert counts to
 * units: value = counts x full_scale / 32768 (counts 0..65535 for the
 * unsigned variables: angles, fault bits).  Channels hold raw counts.
 *
 * Capture, in the fast step (foc_scope_tick, once per PWM period):
 *   IDLE / DONE  nothing (one test)
 *   ARMED        a frame every `decim` periods into the ring; the trigger
 *                is tested on each stored frame once `pre` frames precede
 *                it (an edge also needs the frame before it): the trigger
 *                variable crossing `level` (rising: prev < level <= now;
 *                falling: prev >= level > now; either) or at once
 *                (immediate).
 *   TRIGGERED    frames - pre - 1 more frames, then DONE.
 * A capture holds `frames` = buf_len / channels frames; frame `pre` of the
 * read-out (foc_scope_value, oldest first) is the trigger frame.
 *
 * Concurrency: the fast step (highest priority) samples; the application
 * or the monitor (lower priority) configures, arms, stops and reads.
 * Configuration changes are refused while a capture runs (ARMED,
 * TRIGGERED), the fast step writes nothing in IDLE and DONE, and `mode` is
 * written last when arming, so the two never touch the same data at once.
 * A configuration change discards a finished capture (DONE -> IDLE), so a
 * capture is always read out with the configuration that made it; the DAC
 * selection is separate and can change at any time.
 *
 * Costs (fast step): not running, a test and a return; running, a frame is
 * `channels` loads and stores plus the trigger test, every `decim` periods.
 */
#ifndef FOC_SCOPE_H
#define FOC_SCOPE_H

#include <stddef.h>
#include <stdint.h>
#include "foc/controller.h"
#include "foc/q15.h"

#define FOC_SCOPE_CHANNELS 4u

/* Return codes of the configuration calls. */
#define FOC_SCOPE_OK 0
#define FOC_SCOPE_EBUSY (-1)  /* a capture is running: stop it first */
#define FOC_SCOPE_EINVAL (-2) /* argument out of range */

typedef enum {
    FOC_VAR_IA = 0,     /* phase currents as read (offset not removed), A */
    FOC_VAR_IB,
    FOC_VAR_IC,
    FOC_VAR_IALPHA,     /* stator-frame current (offset removed), A */
    FOC_VAR_IBETA,
    FOC_VAR_ID,         /* rotor-frame current, A */
    FOC_VAR_IQ,
    FOC_VAR_ID_REF,     /* current references (slow step), A */
    FOC_VAR_IQ_REF,
    FOC_VAR_VD,         /* voltage command, V */
    FOC_VAR_VQ,
    FOC_VAR_VALPHA,     /* the same in the stator frame, V */
    FOC_VAR_VBETA,
    FOC_VAR_THETA,      /* angle the controller uses, deg (unsigned) */
    FOC_VAR_THETA_EST,  /* the estimator's own angle, deg (unsigned) */
    FOC_VAR_THETA_SENSOR, /* position sensor, deg (unsigned) */
    FOC_VAR_SPEED,      /* speed the controller uses, rpm mechanical */
    FOC_VAR_SPEED_EST,  /* the estimator's own speed, rpm */
    FOC_VAR_SPEED_REF,  /* speed ramp output (speed loop reference), rpm */
    FOC_VAR_SPEED_CMD,  /* speed command (request), rpm */
    FOC_VAR_SPEED_FORCED, /* start-up forced speed, rpm */
    FOC_VAR_VDC,        /* bus voltage sample, V */
    FOC_VAR_TEMP,       /* temperature sensor output, V */
    FOC_VAR_POT,        /* potentiometer, fraction */
    FOC_VAR_DUTY_A,     /* duties for the next period, fraction */
    FOC_VAR_DUTY_B,
    FOC_VAR_DUTY_C,
    FOC_VAR_STATE,      /* foc_state_t, counts */
    FOC_VAR_FAULTS,     /* active fault bits, counts (unsigned) */
    FOC_VAR_COUNT
} foc_var_t;

typedef struct {
    const char *unit;        /* "" when dimensionless */
    int64_t full_scale_nano; /* physical value of 32768 counts, x 1e9 */
} foc_var_scale_t;           /* one per kind of variable (A, V, rpm ...) */

typedef struct {
    const char *name;    /* lower case, as the monitor takes it */
    uint8_t scale;       /* its unit and full scale: foc_var_scale() */
    uint8_t is_unsigned; /* 1: counts 0..65535; 0: -32768..32767 */
} foc_var_info_t;        /* 8 bytes (a pointer to the scale: 12) */

typedef enum {
    FOC_SCOPE_IDLE = 0,
    FOC_SCOPE_DONE = 1,
    FOC_SCOPE_ARMED = 2,     /* running states last: one test in the tick */
    FOC_SCOPE_TRIGGERED = 3
} foc_scope_state_t;

typedef enum {
    FOC_TRIG_IMMEDIATE = 0,
    FOC_TRIG_RISING,
    FOC_TRIG_FALLING,
    FOC_TRIG_EITHER
} foc_trig_edge_t;

typedef struct foc_scope {
    volatile uint8_t mode;          /* foc_scope_state_t */

    /* configuration: written only while not running */
    const foc_ctrl_t *ctrl;
    int16_t *buf;
    uint16_t buf_len;               /* samples */
    uint8_t nch;                    /* channels, 1..FOC_SCOPE_CHANNELS */
    uint8_t var[FOC_SCOPE_CHANNELS];
    const int16_t *src[FOC_SCOPE_CHANNELS];
    uint16_t decim;                 /* a frame every `decim` periods, >= 1 */
    uint8_t trig_var;
    uint8_t trig_unsigned;          /* its counts are 0..65535 */
    uint8_t edge;                   /* foc_trig_edge_t */
    int32_t level;                  /* counts, in the variable's range */
    uint8_t pre_pct;                /* pre-trigger part of the capture, % */
    const int16_t *trig_src;

    /* set when arming */
    uint16_t frames;                /* frames per capture */
    uint16_t end;                   /* frames x nch: ring length, samples */
    uint16_t pre;                   /* frames before the trigger frame */

    /* fast step */
    uint16_t wr;                    /* ring index of the next frame */
    uint16_t decim_left;            /* periods until the next frame */
    uint16_t stored;                /* frames stored since arming (sat.) */
    uint16_t post_left;             /* frames still to store after trigger */
    int32_t prev;                   /* trigger variable at the last frame */
    int16_t state_shadow;           /* ctrl->state as 16 bits */

    /* debug ("DAC") outputs */
    uint8_t dac_var[2];
    const int16_t *dac_src[2];
} foc_scope_t;

/* Binds the scope to a controller and a sample buffer of `buf_len` int16
 * (0 is allowed: then only the DAC selection works).  Defaults: channels
 * id and iq, decimation 1, immediate trigger, no pre-trigger, DAC id and
 * iq; IDLE.  Call before the fast step can see the scope. */
void foc_scope_init(foc_scope_t *s, const foc_ctrl_t *c, int16_t *buf, uint16_t buf_len);

/* Channel variables, 1..FOC_SCOPE_CHANNELS of them. */
int foc_scope_set_channels(foc_scope_t *s, const foc_var_t *vars, uint8_t n);

/* A frame every `decim` PWM periods (>= 1). */
int foc_scope_set_decimation(foc_scope_t *s, uint16_t decim);

/* Trigger on `var` crossing `level_counts` (in the variable's count range:
 * -32768..32767, or 0..65535 if unsigned) with `edge`; `var` and the
 * level are ignored with FOC_TRIG_IMMEDIATE. */
int foc_scope_set_trigger(foc_scope_t *s, foc_var_t var, foc_trig_edge_t edge,
                          int32_t level_counts);

/* Part of the capture before the trigger frame, 0..100 % (at most all
 * frames but the trigger frame). */
int foc_scope_set_pretrigger(foc_scope_t *s, uint8_t percent);

/* Starts a capture (from IDLE or DONE; the previous capture is lost).
 * FOC_SCOPE_EINVAL if the buffer holds no frame. */
int foc_scope_arm(foc_scope_t *s);

/* Abandons a running capture (-> IDLE); a finished one stays readable. */
void foc_scope_stop(foc_scope_t *s);

foc_scope_state_t foc_scope_state(const foc_scope_t *s);

/* "IDLE", "DONE", "ARMED", "TRIGGERED". */
const char *foc_scope_state_name(foc_scope_state_t st);

/* Frames of a capture (buf_len / channels) and frames before the trigger
 * frame, for the present configuration. */
uint16_t foc_scope_frames(const foc_scope_t *s);
uint16_t foc_scope_pre_frames(const foc_scope_t *s);

/* Counts of channel `ch` in frame `frame` (0 = oldest) of a DONE capture;
 * 0 if out of range. */
int16_t foc_scope_value(const foc_scope_t *s, uint16_t frame, uint8_t ch);

/* Selects what debug output `out` (0 or 1) carries. */
int foc_scope_set_dac(foc_scope_t *s, uint8_t out, foc_var_t var);

/* The two debug output values now (Q15 counts of the selected variables). */
void foc_scope_dac(foc_scope_t *s, q15_t *ch1, q15_t *ch2);

/* The present counts of `var` (the monitor's read; 0 if out of range). */
int16_t foc_scope_var_now(foc_scope_t *s, foc_var_t var);

/* Variable table: NULL if out of range; the index of `name`, or -1. */
const foc_var_info_t *foc_var_info(foc_var_t var);
/* A variable's unit and full scale. */
const foc_var_scale_t *foc_var_scale(const foc_var_info_t *info);
int foc_var_find(const char *name);

/* The running part of the tick; use foc_scope_tick. */
void foc_scope_sample(foc_scope_t *s);

/* Once per PWM period at the end of the fast step; `s` may be NULL. */
static inline void foc_scope_tick(foc_scope_t *s)
{
    if (s != NULL && s->mode >= (uint8_t)FOC_SCOPE_ARMED) {
        foc_scope_sample(s);
    }
}

/* The fast step's debug outputs: the scope's DAC selection, or id and iq
 * without a scope. */
static inline void foc_scope_debug_out(foc_scope_t *s, const foc_ctrl_t *c)
{
    if (s == NULL) {
        foc_port_debug_out(c->i_dq.d, c->i_dq.q);
        return;
    }
    s->state_shadow = (int16_t)c->state;
    foc_port_debug_out(*s->dac_src[0], *s->dac_src[1]);
}

#endif /* FOC_SCOPE_H */
