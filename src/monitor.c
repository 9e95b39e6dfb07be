/* Monitor: the binary protocol's commands; see monitor.h and
 * docs/monitor.md.  All multi-byte fields are little-endian. */
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
 * PC.  (The PI, observer and PLL gains are build constants, config.h, so
 * that the fast step folds them: they are not in RAM to write.) */
#define P_SPEED_GAIN_SHIFT 0u /* speed PI gains / 2^n: the hunting guard's lever */
#define P_MIN_SPEED 1u        /* sensorless minimum speed, Q15 of the speed base */
#define P_STOP_MODE 2u        /* foc_stop_mode_t */
#define P_FAULT_BRAKE 3u
#define P_DEADTIME_COMP 4u
#define P_BRAKE_RESISTOR 5u
#define P_OPEN_LOOP_ONLY 6u
#define P_TUNING 7u

#define F_WRITABLE 1u   /* may be written */
#define F_RUNNING 2u    /* ... also while the motor is driven */
#define T_I16 1u        /* value types (var info) */
#define T_U16 2u
#define T_U8 3u

typedef struct {
    const char *name;
    const char *unit;
    int64_t full_scale_nano;   /* physical value of 32768 counts, x 1e9 */
    uint16_t max;              /* minimum 0 */
    uint8_t type;
    uint8_t flags;
} param_t;

#define COUNTS ((int64_t)32768 * 1000000000) /* value = counts */

static const param_t params[FOC_MON_PARAMS] = {
    { "speed_gain_shift", "", COUNTS, FOC_SPEED_HUNT_SHIFT_MAX, T_U8, F_WRITABLE | F_RUNNING },
    { "min_speed", "rpm", NANO(SPEED_BASE_RPM), 32767u, T_I16, F_WRITABLE },
    { "stop_mode", "", COUNTS, 2u, T_U8, F_WRITABLE },
    { "fault_brake", "", COUNTS, 1u, T_U8, F_WRITABLE },
    { "deadtime_comp", "", COUNTS, 1u, T_U8, F_WRITABLE },
    { "brake_resistor", "", COUNTS, 1u, T_U8, F_WRITABLE },
    { "open_loop_only", "", COUNTS, 1u, T_U8, F_WRITABLE },
    { "tuning", "", COUNTS, 1u, T_U8, F_WRITABLE },
};

static uint16_t param_get(const foc_ctrl_t *c, uint8_t p)
{
    uint16_t v;
    switch (p) {
    case P_SPEED_GAIN_SHIFT: v = c->speed_ctrl.gain_shift; break;
    case P_MIN_SPEED: v = (uint16_t)c->opt.min_speed; break;
    case P_STOP_MODE: v = (uint16_t)c->opt.stop_mode; break;
    case P_FAULT_BRAKE: v = c->opt.fault_brake; break;
    case P_DEADTIME_COMP: v = c->opt.deadtime_comp; break;
    case P_BRAKE_RESISTOR: v = c->protection.resistor_enabled; break;
    case P_OPEN_LOOP_ONLY: v = c->opt.open_loop_only; break;
    default: v = c->opt.tuning; break; /* P_TUNING */
    }
    return v;
}

static const foc_stop_mode_t stop_modes[3] = { STOP_MODE_RAMP, STOP_MODE_COAST, STOP_MODE_SHORT };

/* `v` is within the parameter's range. */
static void param_set(foc_ctrl_t *c, uint8_t p, uint16_t v)
{
    const uint8_t b = (uint8_t)v;
    switch (p) {
    case P_SPEED_GAIN_SHIFT: c->speed_ctrl.gain_shift = b; break;
    case P_MIN_SPEED: c->opt.min_speed = (q15_t)v; break;
    case P_STOP_MODE: c->opt.stop_mode = stop_modes[b]; break;
    case P_FAULT_BRAKE: c->opt.fault_brake = b; break;
    case P_DEADTIME_COMP: c->opt.deadtime_comp = b; break;
    case P_BRAKE_RESISTOR: c->protection.resistor_enabled = b; break;
    case P_OPEN_LOOP_ONLY: c->opt.open_loop_only = b; break;
    default: c->opt.tuning = b; break; /* P_TUNING */
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

/* A NUL-terminated string, cut where the reply is full. */
static void put64(out_t *o, int64_t v)
{
    const uint64_t u = (uint64_t)v;
    put32(o, (uint32_t)(u & 0xFFFFFFFFu));
    put32(o, (uint32_t)(u >> 32u));
}

static void put_str(out_t *o, const char *s)
{
    const char *q = s;
    while (*q != '\0') {
        put8(o, (uint8_t)*q);
        q++;
    }
    put8(o, 0u);
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
    put8(o, (uint8_t)FOC_MON_PARAMS);
    put32(o, MICRO(FOC_I_BASE_A));
    put32(o, MICRO(FOC_V_BASE_V));
    put32(o, MICRO(FOC_VDC_BASE_V));
    put32(o, (uint32_t)(double)(SPEED_BASE_RPM * 1000.0 + 0.5));
    put_str(o, FOC_BOARD_NAME);
    put_str(o, FOC_MOTOR_NAME);
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

static uint8_t var_info(const foc_mon_t *m, uint8_t i, out_t *o)
{
    uint8_t e = FOC_MON_OK;
    if (i < (uint8_t)FOC_VAR_COUNT) {
        const foc_var_info_t *v = foc_var_info((foc_var_t)i);
        put8(o, i);
        put8(o, (v->is_unsigned != 0u) ? T_U16 : T_I16);
        put8(o, 0u);
        put16(o, (v->is_unsigned != 0u) ? 65535u : 32767u);
        put64(o, v->full_scale_nano);
        put_str(o, v->name);
        put_str(o, v->unit);
    } else if (i >= FOC_MON_PARAM_BASE && i < (uint8_t)(FOC_MON_PARAM_BASE + FOC_MON_PARAMS)) {
        const param_t *p = &params[i - FOC_MON_PARAM_BASE];
        put8(o, i);
        put8(o, p->type);
        put8(o, p->flags);
        put16(o, p->max);
        put64(o, p->full_scale_nano);
        put_str(o, p->name);
        put_str(o, p->unit);
    } else {
        e = FOC_MON_E_RANGE;
    }
    (void)m;
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
    } else if (i >= FOC_MON_PARAM_BASE && i < (uint8_t)(FOC_MON_PARAM_BASE + FOC_MON_PARAMS)) {
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
    } else if (i >= FOC_MON_PARAM_BASE && i < (uint8_t)(FOC_MON_PARAM_BASE + FOC_MON_PARAMS)) {
        const uint8_t k = (uint8_t)(i - FOC_MON_PARAM_BASE);
        if (v > params[k].max) {
            e = FOC_MON_E_RANGE;
        } else if ((params[k].flags & F_RUNNING) == 0u && stopped(m->ctrl) == 0u) {
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
        case FOC_MON_VAR_INFO: e = var_info(m, a[0], o); break;
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
