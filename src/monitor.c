/* Monitor: the binary protocol's commands; see monitor.h and
 * docs/monitor.md.  All multi-byte fields are little-endian. */
#include <stddef.h>

#include "foc/monitor.h"
#include "foc/config.h"

#ifndef FOC_BOARD_NAME
#define FOC_BOARD_NAME "unnamed"
#endif
#ifndef FOC_MOTOR_NAME
#define FOC_MOTOR_NAME ""
#endif

/* Bases in micro-units (speed: milli-rpm), folded at compile time (the
 * inner cast keeps the rounding a double: no composite expression is
 * converted, MISRA C:2012 rule 10.8). */
#define MICRO(x) ((uint32_t)(double)((x) * 1e6 + 0.5))
#define NANO(x) ((int64_t)(double)((x) * 1e9 + 0.5))
FOC_STATIC_ASSERT(FOC_I_BASE_A < 4000.0 && FOC_V_BASE_V < 4000.0 && FOC_VDC_BASE_V < 4000.0 &&
                      SPEED_BASE_RPM < 4.0e6,
                  "monitor: a base does not fit its identify field (32 bits, micro-units)");
FOC_STATIC_ASSERT((uint32_t)FOC_VAR_COUNT < FOC_MON_PARAM_BASE, "monitor: the variables overlap the parameters");
FOC_STATIC_ASSERT((4u + (2u * FOC_MON_SCOPE_CHUNK) + 2u) <= FOC_LINK_TX_MAX,
                  "monitor: a scope chunk does not fit the reply buffer");

/* The parameters: RAM fields of the controller worth changing from the
 * PC.  The gains are the Q15 mantissas of foc_pi_tune_t (0 .. 32767 at
 * the build's exponents, which stay constants: their full scale is
 * 2^shift per unit). */
#define P_STOP_MODE 2u /* foc_stop_mode_t: an enum, set through stop_modes[] */

#define F_WRITABLE 1u   /* may be written */
#define F_RUNNING 2u    /* ... also while the motor is driven */
#define T_I16 1u        /* value types (var info) */
#define T_U16 2u
#define T_U8 3u

/* 20 bytes an entry: the name and unit in one string, the full scale in
 * two 32-bit halves (an int64_t would align the entry to 8: 24 bytes), the
 * field as its offset in foc_ctrl_t (a table, not a switch per entry). */
typedef struct {
    const char *name_unit;     /* "name\0" "unit" */
    uint32_t fs_lo, fs_hi;     /* physical value of 32768 counts, x 1e9 */
    uint16_t max;              /* the largest value */
    uint16_t field;            /* offsetof(foc_ctrl_t, the field): T_U8 a */
                               /* uint8_t, T_I16 and T_U16 16-bit integers */
    uint8_t type;
    uint8_t flags;
    uint16_t min;              /* the least value (in the padding) */
} param_t;

#define AT(field) (uint16_t)offsetof(foc_ctrl_t, field)

/* The full scale x (physical value of 32768 counts) in 1e-9 units, in two
 * halves. */
#define FS(x) (uint32_t)((uint64_t)NANO(x) & 0xFFFFFFFFu), (uint32_t)((uint64_t)NANO(x) >> 32u)
#define COUNTS FS(32768.0) /* value = counts */
/* A gain's full scale: 2^shift (its exponent) per unit. */
#define GAIN_FS(shift, unit) FS((double)(1UL << (shift)) * (unit))
/* A PI's gain may be written under way: its integrator holds the output's
 * integral part, so a new ki is bumpless and a new kp steps the output by
 * the change times the present error.  An observer's only stopped (the
 * estimator takes it at its next restart). */
#define PI_GAIN T_U16, F_WRITABLE | F_RUNNING, 0u
#define OBS_GAIN T_U16, F_WRITABLE, 0u

#define COMMON_PARAMS 14u
static const param_t params[COMMON_PARAMS] = {
    { "speed_gain_shift\0", COUNTS, FOC_SPEED_HUNT_SHIFT_MAX, AT(speed_ctrl.gain_shift), T_U8,
      F_WRITABLE | F_RUNNING, 0u },
    { "min_speed\0" "rpm", FS(SPEED_BASE_RPM), 32767u, AT(opt.min_speed), T_I16, F_WRITABLE, 0u },
    { "stop_mode\0", COUNTS, 2u, AT(opt.stop_mode), T_U8, F_WRITABLE, 0u }, /* P_STOP_MODE */
    { "fault_brake\0", COUNTS, 1u, AT(opt.fault_brake), T_U8, F_WRITABLE, 0u },
    { "deadtime_comp\0", COUNTS, 1u, AT(opt.deadtime_comp), T_U8, F_WRITABLE, 0u },
    { "brake_resistor\0", COUNTS, 1u, AT(protection.resistor_enabled), T_U8, F_WRITABLE, 0u },
    { "open_loop_only\0", COUNTS, 1u, AT(opt.open_loop_only), T_U8, F_WRITABLE, 0u },
    { "tuning\0", COUNTS, 1u, AT(opt.tuning), T_U8, F_WRITABLE, 0u },
    /* the speed PI: Q15 current per Q15 speed, and per slow tick */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    { "speed_kp\0" "A/rpm", GAIN_FS(FOC_SPEED_KP_SHIFT, FOC_I_BASE_A / SPEED_BASE_RPM), 65535u,
      AT(speed_ctrl.gains.kp), PI_GAIN },
    { "speed_ki\0" "A/(rpm s)",
      /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
      GAIN_FS(FOC_SPEED_KI_SHIFT, FOC_I_BASE_A / (SPEED_BASE_RPM * FOC_SLOW_TS_S)), 32767u,
      AT(speed_ctrl.gains.ki), PI_GAIN },
    /* the current PIs (both axes): Q15 voltage per Q15 current, per period */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    /* at least Kref: the reference path's gain Kp - Kref stays >= 0 */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    { "current_kp\0" "V/A", GAIN_FS(FOC_CURRENT_KP_SHIFT, FOC_V_BASE_V / FOC_I_BASE_A), 65535u,
      AT(current_ctrl.gains.kp), T_U16, F_WRITABLE | F_RUNNING, FOC_CURRENT_KP_MIN_MANT },
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    { "current_ki\0" "V/(A s)", GAIN_FS(0u, FOC_V_BASE_V / (FOC_I_BASE_A * FOC_TS_S)), 32767u,
      AT(current_ctrl.gains.ki), PI_GAIN },
    /* the field-weakening PI: Q15 current per Q15 voltage, per slow tick */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    { "fw_kp\0" "A/V", GAIN_FS(FOC_FW_KP_SHIFT, FOC_I_BASE_A / FOC_V_BASE_V), 65535u,
      AT(fw.gains.kp), PI_GAIN },
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    { "fw_ki\0" "A/(V s)", GAIN_FS(0u, FOC_I_BASE_A / (FOC_V_BASE_V * FOC_SLOW_TS_S)), 32767u,
      AT(fw.gains.ki), PI_GAIN },
};

/* The estimators' gains: a firmware built for one estimator carries its
 * own only (param_at; focsim all of them, in this order). */
static const param_t luen_params[2] = {
    /* the Luenberger observer's PLL: Q15 speed per Q15 sin(angle error) */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    { "luen_pll_kp\0" "rpm/rad", GAIN_FS(FOC_LUEN_PLL_KP_SHIFT, SPEED_BASE_RPM), 32767u,
      AT(est.gains.luen_kp), OBS_GAIN },
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    { "luen_pll_ki\0" "rpm/(rad s)", GAIN_FS(0u, SPEED_BASE_RPM / FOC_TS_S), 32767u,
      AT(est.gains.luen_ki), OBS_GAIN },
};
static const param_t pll_params[1] = {
    /* the PLL estimator's flux tracking: Q14 per slow tick (< 2^14) */
    { "pll_track_gain\0" "1/s", FS(2.0 / FOC_SLOW_TS_S), 16383u, AT(est.gains.pll_track),
      OBS_GAIN },
};
static const param_t flux_params[2] = {
    /* the flux estimator's correction: (k_min + c |w_e|) Ts, Q15 */
    { "flux_corr_min\0" "rad/s", FS(1.0 / FOC_TS_S), 16384u, AT(est.gains.flux_corr_min),
      OBS_GAIN },
    { "flux_corr_speed\0", FS(1.0 / (FOC_WE_BASE_RAD_S * FOC_TS_S)), 32767u,
      AT(est.gains.flux_corr_speed), OBS_GAIN },
};

/* How many of each table the build has, and in all. */
/* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
#define LUEN_PARAMS (FOC_EST_BUILT(FOC_EST_LUENBERGER) ? 2u : 0u)
/* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
#define PLL_PARAMS (FOC_EST_BUILT(FOC_EST_PLL) ? 1u : 0u)
/* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
#define FLUX_PARAMS (FOC_EST_BUILT(FOC_EST_FLUX) ? 2u : 0u)
#define PARAMS_BUILT ((uint8_t)(COMMON_PARAMS + LUEN_PARAMS + PLL_PARAMS + FLUX_PARAMS))

/* Parameter k of the build's table (k < PARAMS_BUILT): the common ones,
 * then the built estimators' (a table not built is never referenced, so
 * the linker drops it). */
static const param_t *param_at(uint8_t k)
{
    const param_t *p;
    if (k < COMMON_PARAMS) {
        p = &params[k];
    } else if (k < (COMMON_PARAMS + LUEN_PARAMS)) {
        p = &luen_params[k - COMMON_PARAMS];
    } else if (k < (COMMON_PARAMS + LUEN_PARAMS + PLL_PARAMS)) {
        p = &pll_params[k - COMMON_PARAMS - LUEN_PARAMS];
    } else {
        p = &flux_params[k - COMMON_PARAMS - LUEN_PARAMS - PLL_PARAMS];
    }
    return p;
}

/* The parameter's field: its byte, or the first of its 16-bit integer's
 * two, which are copied through a union (its bytes are the integer's
 * object representation, whatever its signedness; no memcpy: the core is
 * freestanding). */
static uint8_t *field_of(foc_ctrl_t *c, const param_t *p)
{
    return &((uint8_t *)c)[p->field];
}

typedef union {
    uint16_t v;
    uint8_t b[2];
} word_t;

static uint16_t param_get(foc_ctrl_t *c, uint8_t k)
{
    const param_t *p = param_at(k);
    uint16_t v;
    if (k == P_STOP_MODE) {
        v = (uint16_t)c->opt.stop_mode;
    } else if (p->type == T_U8) {
        v = *field_of(c, p);
    } else {
        const uint8_t *f = field_of(c, p);
        word_t w;
        w.b[0] = f[0];
        w.b[1] = f[1];
        v = w.v;
    }
    return v;
}

static const foc_stop_mode_t stop_modes[3] = { STOP_MODE_RAMP, STOP_MODE_COAST, STOP_MODE_SHORT };

/* `v` is within the parameter's range. */
static void param_set(foc_ctrl_t *c, uint8_t k, uint16_t v)
{
    const param_t *p = param_at(k);
    if (k == P_STOP_MODE) {
        c->opt.stop_mode = stop_modes[v];
    } else if (p->type == T_U8) {
        *field_of(c, p) = (uint8_t)v;
    } else {
        uint8_t *f = field_of(c, p);
        word_t w;
        w.v = v;
        f[0] = w.b[0];
        f[1] = w.b[1];
    }
}

/* ------------------------------------------------------------- reply -- */

typedef struct {
    uint8_t *p; /* the link's tx buffer */
    uint8_t n;  /* bytes so far */
} out_t;

static void put8(out_t *o, uint8_t v)
{
    if (o->n < (uint8_t)(FOC_LINK_TX_MAX - 2u)) {
        o->p[o->n] = v;
        o->n++;
    }
}

static void put16(out_t *o, uint16_t v)
{
    put8(o, (uint8_t)(v & 0xFFu));
    put8(o, (uint8_t)(v >> 8u));
}

static void put32(out_t *o, uint32_t v)
{
    put16(o, (uint16_t)(v & 0xFFFFu));
    put16(o, (uint16_t)(v >> 16u));
}

/* A NUL-terminated string, cut where the reply is full; returns what
 * follows its NUL. */
static const char *put_str(out_t *o, const char *s)
{
    const char *q = s;
    while (*q != '\0') {
        put8(o, (uint8_t)*q);
        q++;
    }
    put8(o, 0u);
    return &q[1];
}

static uint16_t get16(const uint8_t *p)
{
    return (uint16_t)((uint16_t)p[0] | (uint16_t)((uint16_t)p[1] << 8u));
}

static uint8_t stopped(const foc_ctrl_t *c)
{
    return (uint8_t)((c->state == FOC_STATE_IDLE || c->state == FOC_STATE_FAULT) ? 1u : 0u);
}

static uint8_t scope_err(int rc)
{
    uint8_t e;
    if (rc == FOC_SCOPE_OK) {
        e = FOC_MON_OK;
    } else if (rc == FOC_SCOPE_EBUSY) {
        e = FOC_MON_E_BUSY;
    } else {
        e = FOC_MON_E_RANGE;
    }
    return e;
}

/* ---------------------------------------------------------- commands -- */

static void identify(out_t *o)
{
    put8(o, FOC_MON_PROTOCOL);
    put16(o, FOC_MON_FW_VERSION);
    put8(o, (uint8_t)FOC_ESTIMATOR);
    put32(o, (uint32_t)PWM_FREQUENCY_HZ);
    put8(o, (uint8_t)CONTROL_SLOW_DIVIDER);
    put8(o, (uint8_t)MOTOR_POLE_PAIRS);
    put8(o, (uint8_t)FOC_VAR_COUNT);
    put8(o, PARAMS_BUILT);
    put32(o, MICRO(FOC_I_BASE_A));
    put32(o, MICRO(FOC_V_BASE_V));
    put32(o, MICRO(FOC_VDC_BASE_V));
    put32(o, (uint32_t)(double)(SPEED_BASE_RPM * 1000.0 + 0.5));
    (void)put_str(o, FOC_BOARD_NAME);
    (void)put_str(o, FOC_MOTOR_NAME);
}

static void status(const foc_mon_t *m, out_t *o)
{
    const foc_ctrl_t *c = m->ctrl;
    put8(o, (uint8_t)c->state);
    put16(o, c->faults.active);
    put16(o, c->faults.first);
    put16(o, (uint16_t)c->req.speed);
    put16(o, (uint16_t)c->speed_ctrl.ramped);
    put16(o, (uint16_t)c->est.speed);
    put16(o, (uint16_t)c->est.est_speed);
    put16(o, (uint16_t)c->i_dq.d);
    put16(o, (uint16_t)c->i_dq.q);
    put16(o, (uint16_t)c->samples.vdc);
    put16(o, (uint16_t)c->samples.temp);
    put16(o, m->cpu_load_q15);
    put16(o, m->overruns);
    put16(o, m->link.dropped);
    put8(o, (m->scope != NULL) ? (uint8_t)foc_scope_state(m->scope) : 0u);
}

/* A variable's entry is put as a parameter's: read-only, its unit apart. */
static uint8_t var_info(uint8_t i, out_t *o)
{
    uint8_t e = FOC_MON_OK;
    param_t q = { NULL, 0u, 0u, 0u, 0u, 0u, 0u, 0u };
    const char *unit = NULL; /* NULL: after the name, in name_unit */
    if (i < (uint8_t)FOC_VAR_COUNT) {
        const foc_var_info_t *v = foc_var_info((foc_var_t)i);
        const foc_var_scale_t *sc = foc_var_scale(v);
        const uint64_t fs = (uint64_t)sc->full_scale_nano;
        q.name_unit = v->name;
        unit = sc->unit;
        q.fs_lo = (uint32_t)(fs & 0xFFFFFFFFu);
        q.fs_hi = (uint32_t)(fs >> 32u);
        q.max = (v->is_unsigned != 0u) ? 65535u : 32767u;
        q.type = (v->is_unsigned != 0u) ? T_U16 : T_I16;
    } else if (i >= FOC_MON_PARAM_BASE && i < (uint8_t)(FOC_MON_PARAM_BASE + PARAMS_BUILT)) {
        q = *param_at((uint8_t)(i - FOC_MON_PARAM_BASE));
    } else {
        e = FOC_MON_E_RANGE;
    }
    if (e == FOC_MON_OK) {
        put8(o, i);
        put8(o, q.type);
        put8(o, q.flags);
        put16(o, q.max);
        put32(o, q.fs_lo);
        put32(o, q.fs_hi);
        const char *next = put_str(o, q.name_unit);
        (void)put_str(o, (unit != NULL) ? unit : next);
    }
    return e;
}

static uint8_t var_read(foc_mon_t *m, uint8_t i, out_t *o)
{
    uint8_t e = FOC_MON_OK;
    if (i < (uint8_t)FOC_VAR_COUNT) {
        if (m->scope == NULL) {
            e = FOC_MON_E_NOSCOPE;
        } else {
            put8(o, i);
            put16(o, (uint16_t)foc_scope_var_now(m->scope, (foc_var_t)i));
        }
    } else if (i >= FOC_MON_PARAM_BASE && i < (uint8_t)(FOC_MON_PARAM_BASE + PARAMS_BUILT)) {
        put8(o, i);
        put16(o, param_get(m->ctrl, (uint8_t)(i - FOC_MON_PARAM_BASE)));
    } else {
        e = FOC_MON_E_RANGE;
    }
    return e;
}

static uint8_t var_write(foc_mon_t *m, uint8_t i, uint16_t v)
{
    uint8_t e = FOC_MON_OK;
    if (i < (uint8_t)FOC_VAR_COUNT) {
        e = FOC_MON_E_READONLY;
    } else if (i >= FOC_MON_PARAM_BASE && i < (uint8_t)(FOC_MON_PARAM_BASE + PARAMS_BUILT)) {
        const uint8_t k = (uint8_t)(i - FOC_MON_PARAM_BASE);
        const param_t *p = param_at(k);
        if (v > p->max || v < p->min) {
            e = FOC_MON_E_RANGE;
        } else if ((p->flags & F_RUNNING) == 0u && stopped(m->ctrl) == 0u) {
            e = FOC_MON_E_RUNNING;
        } else {
            param_set(m->ctrl, k, v);
        }
    } else {
        e = FOC_MON_E_RANGE;
    }
    return e;
}

/* args: nch, nch variables, decim (2), trigger variable, edge, level (4,
 * signed), pre-trigger percent. */
static uint8_t scope_set(foc_scope_t *s, const uint8_t *a, uint8_t n)
{
    uint8_t e = FOC_MON_E_LENGTH;
    const uint8_t nch = (n > 0u) ? a[0] : 0u;
    if (nch >= 1u && nch <= FOC_SCOPE_CHANNELS && n == (uint8_t)(nch + 10u)) {
        foc_var_t vars[FOC_SCOPE_CHANNELS];
        uint8_t bad = 0u;
        for (uint8_t k = 0u; k < nch; k++) {
            if (a[1u + k] >= (uint8_t)FOC_VAR_COUNT) {
                bad = 1u;
            }
            vars[k] = (foc_var_t)a[1u + k];
        }
        const uint8_t *t = &a[1u + nch];
        const uint32_t level_bits = (uint32_t)get16(&t[4]) | ((uint32_t)get16(&t[6]) << 16u);
        const int32_t level = (int32_t)level_bits;
        if (bad != 0u || t[2] >= (uint8_t)FOC_VAR_COUNT || t[3] > (uint8_t)FOC_TRIG_EITHER) {
            e = FOC_MON_E_RANGE;
        } else {
            e = scope_err(foc_scope_set_channels(s, vars, nch));
            if (e == FOC_MON_OK) {
                e = scope_err(foc_scope_set_decimation(s, get16(&t[0])));
            }
            if (e == FOC_MON_OK) {
                e = scope_err(foc_scope_set_trigger(s, (foc_var_t)t[2], (foc_trig_edge_t)t[3], level));
            }
            if (e == FOC_MON_OK) {
                e = scope_err(foc_scope_set_pretrigger(s, t[8]));
            }
        }
    }
    return e;
}

static void scope_state(const foc_scope_t *s, out_t *o)
{
    put8(o, (uint8_t)foc_scope_state(s));
    put8(o, s->nch);
    for (uint8_t k = 0u; k < FOC_SCOPE_CHANNELS; k++) {
        put8(o, s->var[k]);
    }
    put16(o, s->decim);
    put8(o, s->trig_var);
    put8(o, s->edge);
    put32(o, (uint32_t)s->level);
    put8(o, s->pre_pct);
    put16(o, foc_scope_frames(s));
    put16(o, foc_scope_pre_frames(s));
    put16(o, s->buf_len);
}

/* args: first sample (2: frame x channels + channel, oldest frame first),
 * count (1..FOC_MON_SCOPE_CHUNK). */
static uint8_t scope_read(const foc_scope_t *s, const uint8_t *a, out_t *o)
{
    uint8_t e = FOC_MON_OK;
    const uint16_t first = get16(a);
    const uint8_t count = a[2];
    const uint32_t total = (uint32_t)foc_scope_frames(s) * s->nch;
    if (foc_scope_state(s) != FOC_SCOPE_DONE) {
        e = FOC_MON_E_NODATA;
    } else if (count == 0u || count > FOC_MON_SCOPE_CHUNK || ((uint32_t)first + count) > total) {
        e = FOC_MON_E_RANGE;
    } else {
        put16(o, first);
        put8(o, count);
        for (uint16_t k = first; k < (uint16_t)(first + count); k++) {
            const uint16_t frame = (uint16_t)(k / s->nch);
            const uint8_t ch = (uint8_t)(k - (uint16_t)(frame * s->nch));
            put16(o, (uint16_t)foc_scope_value(s, frame, ch));
        }
    }
    return e;
}

static void comm_result(const foc_ctrl_t *c, out_t *o)
{
    const foc_comm_t *r = &c->comm;
    put8(o, r->valid);
    put8(o, r->failed_step);
    put16(o, (uint16_t)r->rs_q14);
    put16(o, (uint16_t)r->ld_q14);
    put16(o, (uint16_t)r->lq_q14);
    put16(o, (uint16_t)r->flux_q14);
    put16(o, (uint16_t)r->j_q12);
    put32(o, (uint32_t)r->u.friction_i.low);
    put32(o, (uint32_t)r->u.friction_i.high);
    put16(o, (uint16_t)r->dt_q14);
}

/* The argument length each command takes (0xFF: any, checked by it). */
static uint8_t args_of(uint8_t cmd)
{
    uint8_t n;
    switch (cmd) {
    case FOC_MON_SPEED: n = 2u; break;
    case FOC_MON_VAR_INFO: n = 1u; break;
    case FOC_MON_VAR_READ: n = 1u; break;
    case FOC_MON_VAR_WRITE: n = 3u; break;
    case FOC_MON_SCOPE_SET: n = 0xFFu; break;
    case FOC_MON_SCOPE_READ: n = 3u; break;
    default: n = 0u; break;
    }
    return n;
}

static uint8_t needs_scope(uint8_t cmd)
{
    return (uint8_t)((cmd >= FOC_MON_SCOPE_SET && cmd <= FOC_MON_SCOPE_READ) ? 1u : 0u);
}

/* Executes rx[0 .. n-1] into the reply `o` (its status byte at o->p[1]). */
static void execute(foc_mon_t *m, uint8_t n, out_t *o)
{
    const uint8_t *rq = m->link.rx;
    const uint8_t cmd = rq[0];
    const uint8_t *a = &rq[1];
    const uint8_t na = (uint8_t)(n - 1u);
    foc_ctrl_t *c = m->ctrl;
    uint8_t e = FOC_MON_OK;
    if (args_of(cmd) != 0xFFu && na != args_of(cmd)) {
        e = FOC_MON_E_LENGTH;
    } else if (needs_scope(cmd) != 0u && m->scope == NULL) {
        e = FOC_MON_E_NOSCOPE;
    } else {
        switch (cmd) {
        case FOC_MON_IDENTIFY: identify(o); break;
        case FOC_MON_START: foc_cmd_start(c); break;
        case FOC_MON_STOP: foc_cmd_stop(c); break;
        case FOC_MON_ACK: foc_cmd_ack(c); break;
        case FOC_MON_SPEED: foc_cmd_speed(c, (q15_t)get16(a)); break;
        case FOC_MON_STATUS: status(m, o); break;
        case FOC_MON_VAR_INFO: e = var_info(a[0], o); break;
        case FOC_MON_VAR_READ: e = var_read(m, a[0], o); break;
        case FOC_MON_VAR_WRITE: e = var_write(m, a[0], get16(&a[1])); break;
        case FOC_MON_SCOPE_SET: e = scope_set(m->scope, a, na); break;
        case FOC_MON_SCOPE_ARM: e = scope_err(foc_scope_arm(m->scope)); break;
        case FOC_MON_SCOPE_STOP: foc_scope_stop(m->scope); break;
        case FOC_MON_SCOPE_STATE: scope_state(m->scope, o); break;
        case FOC_MON_SCOPE_READ: e = scope_read(m->scope, a, o); break;
        case FOC_MON_COMMISSION:
            if (c->state == FOC_STATE_IDLE) {
                foc_cmd_commission(c);
            } else {
                e = FOC_MON_E_RUNNING;
            }
            break;
        case FOC_MON_COMM_RESULT: comm_result(c, o); break;
        default: e = FOC_MON_E_COMMAND; break;
        }
    }
    if (e != FOC_MON_OK) {
        o->n = 2u; /* an error carries no data */
    }
    o->p[1] = e;
}

void foc_mon_init(foc_mon_t *m, foc_ctrl_t *ctrl, foc_scope_t *scope)
{
    foc_link_init(&m->link);
    m->ctrl = ctrl;
    m->scope = scope;
    m->cpu_load_q15 = FOC_MON_LOAD_UNKNOWN;
    m->overruns = 0u;
}

void foc_mon_rx(foc_mon_t *m, uint8_t byte)
{
    const uint8_t n = foc_link_rx(&m->link, byte);
    if (n != 0u) {
        out_t o = { m->link.tx, 2u };
        o.p[0] = (uint8_t)(m->link.rx[0] | 0x80u);
        execute(m, n, &o);
        foc_link_send(&m->link, o.n);
    }
}

uint8_t foc_mon_tx(foc_mon_t *m, uint8_t *byte)
{
    return foc_link_tx(&m->link, byte);
}
