#include "foc/scope.h"
#include "foc/config.h"

/* Physical value of 32768 counts in 1e-9 units, folded at compile time. */
#define FS_NANO(x) ((int64_t)((x) * 1e9 + 0.5))

/* The monitor converts with 64-bit products of counts and these scales. */
FOC_STATIC_ASSERT(SPEED_BASE_RPM <= 1.0e5 && FOC_VDC_BASE_V <= 1.0e5 &&
                      FOC_I_BASE_A <= 1.0e5 && FOC_V_BASE_V <= 1.0e5,
                  "scope: a per-unit base above 1e5 overflows the monitor's conversions");

/* The kinds of variable: a unit and the physical value of 32768 counts
 * (1e-9 units), held once for all the variables of a kind. */
#define SCALE_CURRENT 0u
#define SCALE_VOLTAGE 1u
#define SCALE_ANGLE 2u
#define SCALE_SPEED 3u
#define SCALE_VDC 4u
#define SCALE_ADC 5u
#define SCALE_FRACTION 6u
#define SCALE_COUNTS 7u
static const foc_var_scale_t scales[8] = {
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    [SCALE_CURRENT] = { "A", FS_NANO(FOC_I_BASE_A) },
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    [SCALE_VOLTAGE] = { "V", FS_NANO(FOC_V_BASE_V) },
    /* cppcheck-suppress misra-c2012-10.8 ; D3 modular angle */
    [SCALE_ANGLE] = { "deg", FS_NANO(180.0) }, /* 65536 counts = 360 deg */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    [SCALE_SPEED] = { "rpm", FS_NANO(SPEED_BASE_RPM) },
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    [SCALE_VDC] = { "V", FS_NANO(FOC_VDC_BASE_V) },
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    [SCALE_ADC] = { "V", FS_NANO(BOARD_ADC_VREF_V) },
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    [SCALE_FRACTION] = { "", FS_NANO(1.0) },
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    [SCALE_COUNTS] = { "", FS_NANO(32768.0) }, /* value = counts */
};

static const foc_var_info_t var_table[FOC_VAR_COUNT] = {
    [FOC_VAR_IA] = { "ia", SCALE_CURRENT, 0 },
    [FOC_VAR_IB] = { "ib", SCALE_CURRENT, 0 },
    [FOC_VAR_IC] = { "ic", SCALE_CURRENT, 0 },
    [FOC_VAR_IALPHA] = { "ialpha", SCALE_CURRENT, 0 },
    [FOC_VAR_IBETA] = { "ibeta", SCALE_CURRENT, 0 },
    [FOC_VAR_ID] = { "id", SCALE_CURRENT, 0 },
    [FOC_VAR_IQ] = { "iq", SCALE_CURRENT, 0 },
    [FOC_VAR_ID_REF] = { "id_ref", SCALE_CURRENT, 0 },
    [FOC_VAR_IQ_REF] = { "iq_ref", SCALE_CURRENT, 0 },
    [FOC_VAR_VD] = { "vd", SCALE_VOLTAGE, 0 },
    [FOC_VAR_VQ] = { "vq", SCALE_VOLTAGE, 0 },
    [FOC_VAR_VALPHA] = { "valpha", SCALE_VOLTAGE, 0 },
    [FOC_VAR_VBETA] = { "vbeta", SCALE_VOLTAGE, 0 },
    [FOC_VAR_THETA] = { "theta", SCALE_ANGLE, 1 },
    [FOC_VAR_THETA_EST] = { "theta_est", SCALE_ANGLE, 1 },
    [FOC_VAR_THETA_SENSOR] = { "theta_sensor", SCALE_ANGLE, 1 },
    [FOC_VAR_SPEED] = { "speed", SCALE_SPEED, 0 },
    [FOC_VAR_SPEED_EST] = { "speed_est", SCALE_SPEED, 0 },
    [FOC_VAR_SPEED_REF] = { "speed_ref", SCALE_SPEED, 0 },
    [FOC_VAR_SPEED_CMD] = { "speed_cmd", SCALE_SPEED, 0 },
    [FOC_VAR_SPEED_FORCED] = { "speed_forced", SCALE_SPEED, 0 },
    [FOC_VAR_VDC] = { "vdc", SCALE_VDC, 0 },
    [FOC_VAR_TEMP] = { "temp", SCALE_ADC, 0 },
    [FOC_VAR_POT] = { "pot", SCALE_FRACTION, 0 },
    [FOC_VAR_DUTY_A] = { "duty_a", SCALE_FRACTION, 0 },
    [FOC_VAR_DUTY_B] = { "duty_b", SCALE_FRACTION, 0 },
    [FOC_VAR_DUTY_C] = { "duty_c", SCALE_FRACTION, 0 },
    [FOC_VAR_STATE] = { "state", SCALE_COUNTS, 0 },
    [FOC_VAR_FAULTS] = { "faults", SCALE_COUNTS, 1 },
};

const foc_var_info_t *foc_var_info(foc_var_t var)
{
    return ((unsigned)var < (unsigned)FOC_VAR_COUNT) ? &var_table[var] : NULL;
}

const foc_var_scale_t *foc_var_scale(const foc_var_info_t *info)
{
    return &scales[info->scale];
}

static uint8_t same_name(const char *a, const char *b)
{
    while (*a != '\0' && *a == *b) {
        a++;
        b++;
    }
    return (uint8_t)(*a == *b);
}

int foc_var_find(const char *name)
{
    for (int i = 0; i < (int)FOC_VAR_COUNT; i++) {
        if (same_name(name, var_table[i].name) != 0u) {
            return i;
        }
    }
    return -1;
}

/* Where the fast step reads `var`.  The uint16_t fields are read through
 * int16_t (the corresponding signed type: a permitted alias); the state
 * enum through a 16-bit copy the tick refreshes. */
static const int16_t *var_source(foc_scope_t *s, foc_var_t var)
{
    const foc_ctrl_t *c = s->ctrl;
    switch (var) {
    case FOC_VAR_IA: return &c->samples.i_a;
    case FOC_VAR_IB: return &c->samples.i_b;
    case FOC_VAR_IC: return &c->samples.i_c;
    case FOC_VAR_IALPHA: return &c->i_ab.alpha;
    case FOC_VAR_IBETA: return &c->i_ab.beta;
    case FOC_VAR_ID: return &c->i_dq.d;
    case FOC_VAR_IQ: return &c->i_dq.q;
    case FOC_VAR_ID_REF: return &c->i_ref.d;
    case FOC_VAR_IQ_REF: return &c->i_ref.q;
    case FOC_VAR_VD: return &c->v_dq.d;
    case FOC_VAR_VQ: return &c->v_dq.q;
    case FOC_VAR_VALPHA: return &c->v_ab.alpha;
    case FOC_VAR_VBETA: return &c->v_ab.beta;
    case FOC_VAR_THETA: return (const int16_t *)&c->est.theta;
    case FOC_VAR_THETA_EST: return (const int16_t *)&c->est.est_theta;
    case FOC_VAR_THETA_SENSOR: return (const int16_t *)&c->samples.theta_sensor;
    case FOC_VAR_SPEED: return &c->est.speed;
    case FOC_VAR_SPEED_EST: return &c->est.est_speed;
    case FOC_VAR_SPEED_REF: return &c->speed_ctrl.ramped;
    case FOC_VAR_SPEED_CMD: return &c->req.speed;
    case FOC_VAR_SPEED_FORCED: return &c->startup.speed;
    case FOC_VAR_VDC: return &c->samples.vdc;
    case FOC_VAR_TEMP: return &c->samples.temp;
    case FOC_VAR_POT: return &c->samples.pot;
    case FOC_VAR_DUTY_A: return &c->duty.a;
    case FOC_VAR_DUTY_B: return &c->duty.b;
    case FOC_VAR_DUTY_C: return &c->duty.c;
    case FOC_VAR_FAULTS: return (const int16_t *)&c->faults.active;
    default: return &s->state_shadow; /* FOC_VAR_STATE */
    }
}

int16_t foc_scope_var_now(foc_scope_t *s, foc_var_t var)
{
    int16_t v = 0;
    if (var == FOC_VAR_STATE) {
        v = (int16_t)s->ctrl->state; /* the shadow is the fast step's */
    } else if ((unsigned)var < (unsigned)FOC_VAR_COUNT) {
        v = *var_source(s, var);
    } else {
        v = 0;
    }
    return v;
}

static uint8_t running(const foc_scope_t *s)
{
    return (uint8_t)(s->mode >= (uint8_t)FOC_SCOPE_ARMED);
}

/* A configuration change discards a finished capture: a DONE capture
 * always matches the configuration it is read out with. */
static void discard(foc_scope_t *s)
{
    s->mode = (uint8_t)FOC_SCOPE_IDLE;
}

static uint16_t pre_frames_of(uint16_t frames, uint8_t pct)
{
    if (frames == 0u) {
        return 0u;
    }
    const uint32_t pre = (uint32_t)frames * pct / 100u;
    return (pre >= frames) ? (uint16_t)(frames - 1u) : (uint16_t)pre;
}

void foc_scope_init(foc_scope_t *s, const foc_ctrl_t *c, int16_t *buf, uint16_t buf_len)
{
    static const foc_var_t defaults[2] = { FOC_VAR_ID, FOC_VAR_IQ };
    s->mode = (uint8_t)FOC_SCOPE_IDLE;
    s->ctrl = c;
    s->buf = buf;
    s->buf_len = (buf != NULL) ? buf_len : 0u;
    s->state_shadow = (int16_t)c->state;
    (void)foc_scope_set_channels(s, defaults, 2u);
    s->decim = 1u;
    (void)foc_scope_set_trigger(s, FOC_VAR_ID, FOC_TRIG_IMMEDIATE, 0);
    s->pre_pct = 0u;
    s->wr = 0u;
    s->decim_left = 1u;
    s->stored = 0u;
    s->post_left = 0u;
    s->prev = 0;
    (void)foc_scope_set_dac(s, 0u, FOC_VAR_ID);
    (void)foc_scope_set_dac(s, 1u, FOC_VAR_IQ);
    s->frames = foc_scope_frames(s);
    s->pre = foc_scope_pre_frames(s);
    s->end = (uint16_t)(s->frames * s->nch);
}

int foc_scope_set_channels(foc_scope_t *s, const foc_var_t *vars, uint8_t n)
{
    if (running(s) != 0u) {
        return FOC_SCOPE_EBUSY;
    }
    if (n == 0u || n > FOC_SCOPE_CHANNELS) {
        return FOC_SCOPE_EINVAL;
    }
    for (uint8_t i = 0; i < n; i++) {
        if ((unsigned)vars[i] >= (unsigned)FOC_VAR_COUNT) {
            return FOC_SCOPE_EINVAL;
        }
    }
    discard(s);
    for (uint8_t i = 0; i < n; i++) {
        s->var[i] = (uint8_t)vars[i];
        s->src[i] = var_source(s, vars[i]);
    }
    s->nch = n;
    return FOC_SCOPE_OK;
}

int foc_scope_set_decimation(foc_scope_t *s, uint16_t decim)
{
    if (running(s) != 0u) {
        return FOC_SCOPE_EBUSY;
    }
    if (decim == 0u) {
        return FOC_SCOPE_EINVAL;
    }
    discard(s);
    s->decim = decim;
    return FOC_SCOPE_OK;
}

int foc_scope_set_trigger(foc_scope_t *s, foc_var_t var, foc_trig_edge_t edge,
                          int32_t level_counts)
{
    if (running(s) != 0u) {
        return FOC_SCOPE_EBUSY;
    }
    if ((unsigned)edge > (unsigned)FOC_TRIG_EITHER) {
        return FOC_SCOPE_EINVAL;
    }
    if (edge == FOC_TRIG_IMMEDIATE) {
        var = FOC_VAR_ID;
        level_counts = 0;
    }
    const foc_var_info_t *info = foc_var_info(var);
    if (info == NULL) {
        return FOC_SCOPE_EINVAL;
    }
    const int32_t lo = (info->is_unsigned != 0u) ? 0 : -32768L;
    const int32_t hi = (info->is_unsigned != 0u) ? 65535L : 32767L;
    if (level_counts < lo || level_counts > hi) {
        return FOC_SCOPE_EINVAL;
    }
    discard(s);
    s->trig_var = (uint8_t)var;
    s->trig_unsigned = info->is_unsigned;
    s->edge = (uint8_t)edge;
    s->level = level_counts;
    s->trig_src = var_source(s, var);
    return FOC_SCOPE_OK;
}

int foc_scope_set_pretrigger(foc_scope_t *s, uint8_t percent)
{
    if (running(s) != 0u) {
        return FOC_SCOPE_EBUSY;
    }
    if (percent > 100u) {
        return FOC_SCOPE_EINVAL;
    }
    discard(s);
    s->pre_pct = percent;
    return FOC_SCOPE_OK;
}

uint16_t foc_scope_frames(const foc_scope_t *s)
{
    return (uint16_t)(s->buf_len / s->nch);
}

uint16_t foc_scope_pre_frames(const foc_scope_t *s)
{
    return pre_frames_of(foc_scope_frames(s), s->pre_pct);
}

int foc_scope_arm(foc_scope_t *s)
{
    if (running(s) != 0u) {
        return FOC_SCOPE_EBUSY;
    }
    const uint16_t frames = foc_scope_frames(s);
    if (frames == 0u) {
        return FOC_SCOPE_EINVAL;
    }
    /* Through a volatile lvalue, so the compiler keeps these stores before
     * the store of `mode` that hands the scope to the fast step. */
    volatile foc_scope_t *v = s;
    v->pre = pre_frames_of(frames, s->pre_pct);
    v->frames = frames;
    v->end = (uint16_t)(frames * s->nch);
    v->wr = 0u;
    v->decim_left = 1u; /* the first frame is the next period's */
    v->stored = 0u;
    v->post_left = 0u;
    v->prev = 0;
    v->mode = (uint8_t)FOC_SCOPE_ARMED;
    return FOC_SCOPE_OK;
}

void foc_scope_stop(foc_scope_t *s)
{
    if (running(s) != 0u) {
        s->mode = (uint8_t)FOC_SCOPE_IDLE;
    }
}

foc_scope_state_t foc_scope_state(const foc_scope_t *s)
{
    return (foc_scope_state_t)s->mode;
}

const char *foc_scope_state_name(foc_scope_state_t st)
{
    static const char *const names[] = { "IDLE", "DONE", "ARMED", "TRIGGERED" };
    return ((unsigned)st < 4u) ? names[st] : "?";
}

int16_t foc_scope_value(const foc_scope_t *s, uint16_t frame, uint8_t ch)
{
    if (s->mode != (uint8_t)FOC_SCOPE_DONE || frame >= s->frames || ch >= s->nch) {
        return 0;
    }
    /* The oldest frame is where the next one would have gone. */
    const uint32_t pos = ((uint32_t)s->wr + (uint32_t)frame * s->nch) % s->end;
    return s->buf[pos + ch];
}

int foc_scope_set_dac(foc_scope_t *s, uint8_t out, foc_var_t var)
{
    if (out > 1u || (unsigned)var >= (unsigned)FOC_VAR_COUNT) {
        return FOC_SCOPE_EINVAL;
    }
    s->dac_var[out] = (uint8_t)var;
    s->dac_src[out] = var_source(s, var); /* one pointer store: atomic */
    return FOC_SCOPE_OK;
}

void foc_scope_dac(foc_scope_t *s, q15_t *ch1, q15_t *ch2)
{
    s->state_shadow = (int16_t)s->ctrl->state;
    *ch1 = *s->dac_src[0];
    *ch2 = *s->dac_src[1];
}
