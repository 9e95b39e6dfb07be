#include "foc/monitor.h"
#include "foc/config.h"

/* PWM period in picoseconds and PWM rate in mHz, folded at compile time. */
#define PWM_PERIOD_PS ((int64_t)(1.0e12 / PWM_FREQUENCY_HZ + 0.5))
#define PWM_RATE_MHZ ((int64_t)(PWM_FREQUENCY_HZ * 1000.0 + 0.5))

#define LINE_TOO_LONG 0x1u
#define LINE_BAD_CHAR 0x2u

#define MILLI_MAX 99999999L /* parsed values: |x| <= 99999.999 */

enum { DUMP_NONE = 0, DUMP_HEADER, DUMP_CHANNELS, DUMP_DATA, DUMP_END };

/* ------------------------------------------------------------ timing -- */

void foc_isr_timing_init(foc_isr_timing_t *t, uint32_t clock_hz)
{
    t->min_cycles = 0u;
    t->max_cycles = 0u;
    t->avg_x64 = 0u;
    t->count = 0u;
    t->clock_hz = clock_hz;
    t->reset = 0u;
}

void foc_isr_timing_add(foc_isr_timing_t *t, uint32_t cycles)
{
    if (cycles > (1UL << 25)) {
        cycles = 1UL << 25; /* keeps avg_x64 within 32 bits */
    }
    if (t->reset != 0u || t->count == 0u) {
        t->reset = 0u;
        t->min_cycles = cycles;
        t->max_cycles = cycles;
        t->avg_x64 = cycles << FOC_MON_TIMING_AVG_SHIFT;
        t->count = 1u;
        return;
    }
    if (cycles < t->min_cycles) {
        t->min_cycles = cycles;
    }
    if (cycles > t->max_cycles) {
        t->max_cycles = cycles;
    }
    t->avg_x64 = t->avg_x64 - (t->avg_x64 >> FOC_MON_TIMING_AVG_SHIFT) + cycles;
    if (t->count < UINT32_MAX) {
        t->count++;
    }
}

/* ------------------------------------------------------------ output -- */

/* A reply being built: characters go to a small buffer that is passed to
 * `write` whenever it fills and at the end of each line. */
typedef struct {
    foc_mon_write_t write;
    char buf[48];
    uint8_t len;
} out_t;

static void out_flush(out_t *o)
{
    if (o->len != 0u) {
        o->write(o->buf, o->len);
        o->len = 0u;
    }
}

static void out_char(out_t *o, char ch)
{
    if (o->len >= sizeof o->buf) {
        out_flush(o);
    }
    o->buf[o->len++] = ch;
}

static void out_str(out_t *o, const char *s)
{
    while (*s != '\0') {
        out_char(o, *s++);
    }
}

static void out_end(out_t *o)
{
    out_str(o, "\r\n");
    out_flush(o);
}

static void out_line(out_t *o, const char *s)
{
    out_str(o, s);
    out_end(o);
}

/* Decimal digits of v, at least `min_digits` of them (leading zeros). */
static void out_u64(out_t *o, uint64_t v, uint8_t min_digits)
{
    char digits[20];
    uint8_t n = 0;
    while (v > UINT32_MAX && n < sizeof digits) {
        digits[n++] = (char)('0' + (uint8_t)(v % 10u));
        v /= 10u;
    }
    uint32_t small = (uint32_t)v; /* 32-bit divisions for the rest */
    do {
        digits[n++] = (char)('0' + (uint8_t)(small % 10u));
        small /= 10u;
    } while (small != 0u && n < sizeof digits);
    while (n < min_digits && n < sizeof digits) {
        digits[n++] = '0';
    }
    while (n > 0u) {
        out_char(o, digits[--n]);
    }
}

static void out_i64(out_t *o, int64_t v)
{
    if (v < 0) {
        out_char(o, '-');
        out_u64(o, (uint64_t)(-(v + 1)) + 1u, 1u);
    } else {
        out_u64(o, (uint64_t)v, 1u);
    }
}

/* v / 10^decimals as a decimal number; trailing fraction zeros (and the
 * point) dropped if `trim`.  decimals <= 18. */
static void out_fixed(out_t *o, int64_t v, uint8_t decimals, uint8_t trim)
{
    uint64_t div = 1u;
    for (uint8_t i = 0; i < decimals; i++) {
        div *= 10u;
    }
    if (v < 0) {
        out_char(o, '-');
    }
    const uint64_t mag = (v < 0) ? (uint64_t)(-(v + 1)) + 1u : (uint64_t)v;
    out_u64(o, mag / div, 1u);
    uint64_t frac = mag % div;
    uint8_t places = decimals;
    if (trim != 0u) {
        while (places > 0u && frac % 10u == 0u) {
            frac /= 10u;
            places--;
        }
    }
    if (places > 0u) {
        out_char(o, '.');
        out_u64(o, frac, places);
    }
}

static void out_hex16(out_t *o, uint16_t v)
{
    static const char hex[] = "0123456789abcdef";
    out_str(o, "0x");
    for (uint8_t digit = 0; digit < 4u; digit++) {
        const unsigned shift = 12u - 4u * (unsigned)digit;
        out_char(o, hex[((unsigned)v >> shift) & 0xFu]);
    }
}

/* " key=" */
static void out_key(out_t *o, const char *key)
{
    out_char(o, ' ');
    out_str(o, key);
    out_char(o, '=');
}

/* num / den rounded to nearest, halves away from zero; den > 0. */
static int64_t div_round(int64_t num, int64_t den)
{
    return (num >= 0) ? (num + den / 2) / den : -((-num + den / 2) / den);
}

/* Counts of `var` as physical units x 1000 (counts x full scale / 32768). */
static int64_t counts_to_milli(int32_t counts, foc_var_t var)
{
    const int64_t fs_micro = foc_var_info(var)->full_scale_nano / 1000;
    return div_round((int64_t)counts * fs_micro, INT64_C(32768000));
}

/* Physical units x 1000 (|milli| <= MILLI_MAX) to counts of `var`. */
static int32_t milli_to_counts(int32_t milli, foc_var_t var)
{
    const int64_t fs_nano = foc_var_info(var)->full_scale_nano;
    return (int32_t)div_round((int64_t)milli * INT64_C(32768000000), fs_nano);
}

/* " key=<value of var in its unit, `decimals` places>" */
static void out_phys(out_t *o, const char *key, int32_t counts, foc_var_t var,
                     uint8_t decimals)
{
    int64_t scaled = counts_to_milli(counts, var);
    uint8_t drop = (uint8_t)(3u - decimals);
    int64_t div = 1;
    while (drop-- > 0u) {
        div *= 10;
    }
    scaled = div_round(scaled, div);
    out_key(o, key);
    out_fixed(o, scaled, decimals, 0u);
}

/* ----------------------------------------------------------- parsing -- */

static uint8_t same(const char *a, const char *b)
{
    while (*a != '\0' && *a == *b) {
        a++;
        b++;
    }
    return (uint8_t)(*a == *b);
}

/* Whole number 0..max. */
static uint8_t parse_u32(const char *s, uint32_t max, uint32_t *out)
{
    uint32_t v = 0u;
    if (*s == '\0') {
        return 0u;
    }
    for (; *s != '\0'; s++) {
        if (*s < '0' || *s > '9') {
            return 0u;
        }
        const uint32_t d = (uint32_t)(*s - '0');
        if (d > max || v > (max - d) / 10u) {
            return 0u;
        }
        v = v * 10u + d;
    }
    *out = v;
    return 1u;
}

/* [-|+]digits[.digits]: at most 5 integer and 3 fraction digits, as the
 * value x 1000. */
static uint8_t parse_milli(const char *s, int32_t *out)
{
    const uint8_t negative = (uint8_t)(*s == '-');
    if (*s == '-' || *s == '+') {
        s++;
    }
    int32_t v = 0;
    uint8_t int_digits = 0;
    for (; *s >= '0' && *s <= '9'; s++) {
        if (++int_digits > 5u) {
            return 0u;
        }
        v = v * 10 + (int32_t)(*s - '0');
    }
    uint8_t frac_digits = 0;
    if (*s == '.') {
        for (s++; *s >= '0' && *s <= '9'; s++) {
            if (++frac_digits > 3u) {
                return 0u;
            }
            v = v * 10 + (int32_t)(*s - '0');
        }
    }
    if (*s != '\0' || int_digits + frac_digits == 0u) {
        return 0u;
    }
    for (; frac_digits < 3u; frac_digits++) {
        v *= 10;
    }
    *out = negative ? -v : v;
    return 1u;
}

/* --------------------------------------------------------- commands -- */

typedef struct {
    foc_monitor_t *m;
    out_t *o;
    char **arg;  /* the words after the command */
    uint8_t n;   /* how many */
} call_t;

static void reply_ok(out_t *o)
{
    out_line(o, "ok");
}

static void reply_err(out_t *o, const char *what, const char *word)
{
    out_str(o, "err ");
    out_str(o, what);
    if (word != NULL) {
        out_str(o, ": ");
        out_str(o, word);
    }
    out_end(o);
}

/* The variable named `word`, or -1 after an error reply. */
static int find_var(out_t *o, const char *word)
{
    const int v = foc_var_find(word);
    if (v < 0) {
        reply_err(o, "unknown variable", word);
    }
    return v;
}

static uint8_t need_scope(const call_t *k)
{
    if (k->m->scope == NULL) {
        reply_err(k->o, "no scope", NULL);
        return 0u;
    }
    return 1u;
}

static void reply_scope_code(out_t *o, int rc)
{
    if (rc == FOC_SCOPE_OK) {
        reply_ok(o);
    } else if (rc == FOC_SCOPE_EBUSY) {
        reply_err(o, "scope busy (scope stop first)", NULL);
    } else {
        reply_err(o, "out of range", NULL);
    }
}

static void cmd_help(const call_t *k);

static void cmd_start(const call_t *k)
{
    foc_cmd_start(k->m->ctrl);
    reply_ok(k->o);
}

static void cmd_stop(const call_t *k)
{
    foc_cmd_stop(k->m->ctrl);
    reply_ok(k->o);
}

static void cmd_ack(const call_t *k)
{
    foc_cmd_ack(k->m->ctrl);
    reply_ok(k->o);
}

static void cmd_commission(const call_t *k)
{
    if (k->m->ctrl->state != FOC_STATE_IDLE) {
        reply_err(k->o, "not idle", foc_state_name(k->m->ctrl->state));
        return;
    }
    foc_cmd_commission(k->m->ctrl);
    reply_ok(k->o);
}

/* The lines of `ident`: a parameter of userparms.h x 10^decimals, and,
 * for a measured one, which result's Q14 ratio scales it. */
#define IDENT_NONE 0u
#define IDENT_RS 1u
#define IDENT_LD 2u
#define IDENT_LQ 3u
#define IDENT_FLUX 4u
#define IDENT_J 5u        /* MECH's: its Q12 ratio (x 4) */
#define IDENT_VISCOUS 6u  /* MECH's friction line (ident_friction) */
#define IDENT_COULOMB 7u
typedef struct {
    const char *key;
    int64_t value;     /* the parameter x 10^decimals */
    uint8_t decimals;
    uint8_t measured;  /* IDENT_* */
} ident_row_t;

#define IDENT_ROW(key, x, decimals, factor, measured) { (key), (int64_t)((x) * (factor) + 0.5), (decimals), (measured) }

static const ident_row_t ident_rows[] = {
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    IDENT_ROW("pole_pairs", MOTOR_POLE_PAIRS, 0u, 1.0, IDENT_NONE),
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    IDENT_ROW("rs_ohm", MOTOR_RS_OHM, 9u, 1e9, IDENT_RS),
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    IDENT_ROW("ld_h", MOTOR_LD_H, 9u, 1e9, IDENT_LD),
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    IDENT_ROW("lq_h", MOTOR_LQ_H, 9u, 1e9, IDENT_LQ),
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    IDENT_ROW("flux_linkage_wb", FOC_FLUX_WB, 9u, 1e9, IDENT_FLUX),
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    IDENT_ROW("nominal_speed_rpm", MOTOR_NOMINAL_SPEED_RPM, 3u, 1e3, IDENT_NONE),
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    IDENT_ROW("max_speed_rpm", MOTOR_MAX_SPEED_RPM, 3u, 1e3, IDENT_NONE),
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    IDENT_ROW("rated_current_a_peak", MOTOR_RATED_CURRENT_A, 3u, 1e3, IDENT_NONE),
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    IDENT_ROW("max_current_a_peak", CURRENT_LIMIT_A, 3u, 1e3, IDENT_NONE),
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    IDENT_ROW("inertia_kgm2", MOTOR_INERTIA_KGM2, 12u, 1e12, IDENT_J),
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    IDENT_ROW("viscous_nm_per_krpm", MOTOR_VISCOUS_NM_PER_KRPM, 12u, 1e12, IDENT_VISCOUS),
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    IDENT_ROW("coulomb_nm", MOTOR_COULOMB_NM, 9u, 1e9, IDENT_COULOMB),
};

/* MECH's friction from its q current sums at the two speeds (commission.h,
 * Q15 x FOC_COMM_MECH_SUM_N): the viscous part from their slope, the
 * Coulomb part the line at zero speed, both times the measured flux's Kt
 * (flux_q14 x the parameter's).  Each is flux_q14 x a sum x NUM / DEN:
 * NUM = 2^16 keeps the product within 2^15 x 2^31 x 2^16 = 2^62, DEN
 * rounds the constant to 1/1024 at worst (config.h holds it above 1024). */
#define IDENT_A_PER_SUM (FOC_I_BASE_A / (32768.0 * FOC_COMM_MECH_SUM_N))
#define IDENT_VISCOUS_PER_SUM \
    (FOC_KT_NM_PER_A * IDENT_A_PER_SUM / FOC_COMM_MECH_DW_RAD_S * (1000.0 * 2.0 * FOC_PI_D / 60.0) * 1e12 / 16384.0)
#define IDENT_COULOMB_PER_SUM (FOC_KT_NM_PER_A * IDENT_A_PER_SUM * 1e9 / 16384.0)
#define IDENT_DEN(per_sum) ((int64_t)(65536.0 / (per_sum) + 0.5))
FOC_STATIC_ASSERT(IDENT_VISCOUS_PER_SUM < 64.0 && IDENT_COULOMB_PER_SUM < 64.0,
                  "ident's friction constants: the rounding of their DEN");

/* value x ratio / 2^14 rounded, value >= 0 below 2^50 (an inertia up to
 * 1000 kg m^2 x 10^12), ratio below 2^17: split so no product passes
 * 2^53. */
static int64_t ident_scaled(int64_t value, int32_t ratio_q14)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return (value >> 14) * ratio_q14 + (((value & 16383) * ratio_q14 + 8192) >> 14);
}

/* The friction row's value x 10^decimals (>= 0: friction takes energy). */
static int64_t ident_friction(const foc_comm_t *r, uint8_t which)
{
    const int64_t low = r->u.friction_i.low;
    const int64_t high = r->u.friction_i.high;
    const int64_t dw = FOC_COMM_MECH_HIGH - FOC_COMM_MECH_LOW;
    /* |sum| < 2^31: the slope's sum, or the line's at zero speed */
    const int64_t sum = (which == IDENT_VISCOUS) ? high - low
                                                 : div_round(low * dw - (high - low) * FOC_COMM_MECH_LOW, dw);
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const int64_t den = (which == IDENT_VISCOUS) ? IDENT_DEN(IDENT_VISCOUS_PER_SUM) : IDENT_DEN(IDENT_COULOMB_PER_SUM);
    const int64_t v = div_round(r->flux_q14 * sum * 65536, den);
    return (v > 0) ? v : 0;
}

/* Commissioning's results (commission.h) in SI units, as the motor
 * description tools/tune.py reads: data lines, then "ok"; the rest of the
 * description from userparms.h (commissioning does not measure it, nor
 * the inertia and friction when MECH did not run).  A result is its Q14
 * ratio times the parameter (ident_scaled), or the friction's line
 * (ident_friction). */
static void cmd_ident(const call_t *k)
{
    const foc_comm_t *r = &k->m->ctrl->comm;
    out_t *o = k->o;
    if (r->valid == 0u) {
        reply_err(o, (r->failed_step != 0u) ? "failed step" : "no results",
                  (r->failed_step != 0u) ? foc_comm_step_name(r->failed_step) : NULL);
        return;
    }
    out_line(o, "[motor]\r\nname = commissioned motor\r\nconnection = star\r\nrl_measured = phase");
    const uint8_t mech = (uint8_t)(r->j_q12 != 0);
    /* Q14; the mechanical rows the build's without MECH */
    const int32_t ratio[] = { 16384, r->rs_q14, r->ld_q14, r->lq_q14, r->flux_q14, mech ? 4 * (int32_t)r->j_q12 : 16384 };
    for (unsigned i = 0; i < sizeof ident_rows / sizeof ident_rows[0]; i++) {
        const ident_row_t *row = &ident_rows[i];
        out_str(o, row->key);
        out_str(o, " = ");
        const int64_t v = (row->measured >= IDENT_VISCOUS) ? (mech ? ident_friction(r, row->measured) : row->value)
                                                           : ident_scaled(row->value, ratio[row->measured]);
        out_fixed(o, v, row->decimals, 1u);
        out_end(o);
    }
    reply_ok(o);
}

static void cmd_speed(const call_t *k)
{
    int32_t milli = 0;
    if (parse_milli(k->arg[0], &milli) == 0u) {
        reply_err(k->o, "bad number", k->arg[0]);
        return;
    }
    const int32_t counts = milli_to_counts(milli, FOC_VAR_SPEED_CMD);
    if (counts < -32768L || counts > 32767L) {
        reply_err(k->o, "out of range", k->arg[0]);
        return;
    }
    foc_cmd_speed(k->m->ctrl, (q15_t)counts);
    reply_ok(k->o);
}

static void cmd_status(const call_t *k)
{
    const foc_ctrl_t *c = k->m->ctrl;
    out_t *o = k->o;
    const uint8_t forced = (uint8_t)(c->state == FOC_STATE_ALIGN || c->state == FOC_STATE_OPENLOOP ||
                                     c->state == FOC_STATE_COMMISSION);
    out_str(o, "ok");
    out_key(o, "state");
    out_str(o, foc_state_name(c->state));
    out_key(o, "fault");
    out_str(o, foc_fault_name(c->faults.first));
    out_key(o, "faults");
    out_hex16(o, c->faults.active);
    out_key(o, "est");
    out_str(o, foc_est_name(c->est.kind));
    out_phys(o, "speed_cmd_rpm", c->req.speed, FOC_VAR_SPEED_CMD, 1u);
    out_phys(o, "speed_ref_rpm", forced ? c->startup.speed : c->speed_ctrl.ramped,
             FOC_VAR_SPEED_REF, 1u);
    out_phys(o, "speed_rpm", c->est.speed, FOC_VAR_SPEED, 1u);
    out_phys(o, "speed_est_rpm", c->est.est_speed, FOC_VAR_SPEED_EST, 1u);
    out_phys(o, "id_a", c->i_dq.d, FOC_VAR_ID, 3u);
    out_phys(o, "iq_a", c->i_dq.q, FOC_VAR_IQ, 3u);
    out_phys(o, "vdc_v", c->samples.vdc, FOC_VAR_VDC, 2u);
    out_end(o);
}

static void cmd_timing(const call_t *k)
{
    foc_isr_timing_t *t = k->m->timing;
    out_t *o = k->o;
    if (t == NULL) {
        reply_err(o, "no timing", NULL);
        return;
    }
    if (k->n == 1u) {
        if (same(k->arg[0], "reset") == 0u) {
            reply_err(o, "usage", "timing [reset]");
            return;
        }
        t->reset = 1u;
        reply_ok(o);
        return;
    }
    const uint32_t avg = t->avg_x64 >> FOC_MON_TIMING_AVG_SHIFT;
    out_str(o, "ok");
    out_key(o, "min_cycles");
    out_u64(o, t->min_cycles, 1u);
    out_key(o, "avg_cycles");
    out_u64(o, avg, 1u);
    out_key(o, "max_cycles");
    out_u64(o, t->max_cycles, 1u);
    out_key(o, "count");
    out_u64(o, t->count, 1u);
    out_key(o, "clock_hz");
    out_u64(o, t->clock_hz, 1u);
    if (t->clock_hz != 0u) {
        /* share of the PWM period, avg / (clock / f_pwm), in 0.1 %:
         * avg x f_pwm x 1000 / clock, f_pwm x 1000 being PWM_RATE_MHZ */
        /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
        const int64_t load = div_round((int64_t)avg * PWM_RATE_MHZ, (int64_t)t->clock_hz);
        out_key(o, "load_pct");
        out_fixed(o, load, 1u, 0u);
    }
    out_end(o);
}

static void cmd_dac(const call_t *k)
{
    if (need_scope(k) == 0u) {
        return;
    }
    foc_scope_t *s = k->m->scope;
    if (k->n == 1u) {
        reply_err(k->o, "usage", "dac [<var1> <var2>]");
        return;
    }
    if (k->n == 2u) {
        const int v1 = find_var(k->o, k->arg[0]);
        if (v1 < 0) {
            return;
        }
        const int v2 = find_var(k->o, k->arg[1]);
        if (v2 < 0) {
            return;
        }
        (void)foc_scope_set_dac(s, 0u, (foc_var_t)v1);
        (void)foc_scope_set_dac(s, 1u, (foc_var_t)v2);
    }
    out_str(k->o, "ok");
    out_key(k->o, "dac1");
    out_str(k->o, foc_var_info((foc_var_t)s->dac_var[0])->name);
    out_key(k->o, "dac2");
    out_str(k->o, foc_var_info((foc_var_t)s->dac_var[1])->name);
    out_end(k->o);
}

/* "<name> <unit or -> <full scale> <s|u>" */
static void out_var(out_t *o, foc_var_t var)
{
    const foc_var_info_t *info = foc_var_info(var);
    out_str(o, info->name);
    out_char(o, ' ');
    out_str(o, info->unit[0] != '\0' ? info->unit : "-");
    out_char(o, ' ');
    out_fixed(o, info->full_scale_nano, 9u, 1u);
    out_str(o, info->is_unsigned != 0u ? " u" : " s");
}

static void cmd_vars(const call_t *k)
{
    for (uint8_t v = 0; v < (uint8_t)FOC_VAR_COUNT; v++) {
        out_str(k->o, "var ");
        out_var(k->o, (foc_var_t)v);
        out_end(k->o);
    }
    out_str(k->o, "ok");
    out_key(k->o, "vars");
    out_u64(k->o, (uint64_t)FOC_VAR_COUNT, 1u);
    out_end(k->o);
}

/* ------------------------------------------------------------- scope -- */

static const char *const edge_names[] = { "immediate", "rising", "falling", "either" };

/* The configuration, as " key=value" pairs (status and dump header). */
static void out_scope_config(out_t *o, const foc_scope_t *s)
{
    out_key(o, "state");
    out_str(o, foc_scope_state_name(foc_scope_state(s)));
    out_key(o, "channels");
    out_u64(o, s->nch, 1u);
    out_key(o, "frames");
    out_u64(o, foc_scope_frames(s), 1u);
    out_key(o, "pre");
    out_u64(o, foc_scope_pre_frames(s), 1u);
    out_key(o, "decim");
    out_u64(o, s->decim, 1u);
    out_key(o, "dt_s");
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    out_fixed(o, PWM_PERIOD_PS * (int64_t)s->decim, 12u, 1u);
    out_key(o, "trigger");
    if (s->edge == (uint8_t)FOC_TRIG_IMMEDIATE) {
        out_str(o, edge_names[0]);
        return;
    }
    out_str(o, foc_var_info((foc_var_t)s->trig_var)->name);
    out_key(o, "edge");
    out_str(o, edge_names[s->edge]);
    out_key(o, "level");
    out_i64(o, s->level);
}

static void scope_status(const call_t *k)
{
    const foc_scope_t *s = k->m->scope;
    out_str(k->o, "ok");
    out_scope_config(k->o, s);
    out_key(k->o, "vars");
    for (uint8_t ch = 0; ch < s->nch; ch++) {
        if (ch != 0u) {
            out_char(k->o, ',');
        }
        out_str(k->o, foc_var_info((foc_var_t)s->var[ch])->name);
    }
    out_end(k->o);
}

static void scope_channels(const call_t *k)
{
    foc_var_t vars[FOC_SCOPE_CHANNELS];
    const uint8_t n = (uint8_t)(k->n - 1u);
    if (n == 0u || n > FOC_SCOPE_CHANNELS) {
        reply_err(k->o, "usage", "scope ch <var> [<var> [<var> [<var>]]]");
        return;
    }
    for (uint8_t i = 0; i < n; i++) {
        const int v = find_var(k->o, k->arg[i + 1u]);
        if (v < 0) {
            return;
        }
        vars[i] = (foc_var_t)v;
    }
    reply_scope_code(k->o, foc_scope_set_channels(k->m->scope, vars, n));
}

static void scope_decim(const call_t *k)
{
    uint32_t d = 0;
    if (k->n != 2u) {
        reply_err(k->o, "usage", "scope decim <1..65535>");
        return;
    }
    if (parse_u32(k->arg[1], 65535u, &d) == 0u || d == 0u) {
        reply_err(k->o, "bad number", k->arg[1]);
        return;
    }
    reply_scope_code(k->o, foc_scope_set_decimation(k->m->scope, (uint16_t)d));
}

static void scope_pre(const call_t *k)
{
    uint32_t pct = 0;
    if (k->n != 2u) {
        reply_err(k->o, "usage", "scope pre <0..100>");
        return;
    }
    if (parse_u32(k->arg[1], 100u, &pct) == 0u) {
        reply_err(k->o, "bad number", k->arg[1]);
        return;
    }
    reply_scope_code(k->o, foc_scope_set_pretrigger(k->m->scope, (uint8_t)pct));
}

/* scope trig immediate | scope trig <var> <edge> <level in units> */
static void scope_trig(const call_t *k)
{
    foc_scope_t *s = k->m->scope;
    if (k->n == 2u && same(k->arg[1], "immediate") != 0u) {
        reply_scope_code(k->o, foc_scope_set_trigger(s, FOC_VAR_ID, FOC_TRIG_IMMEDIATE, 0));
        return;
    }
    if (k->n != 4u) {
        reply_err(k->o, "usage", "scope trig immediate | scope trig <var> rising|falling|either <level>");
        return;
    }
    const int v = find_var(k->o, k->arg[1]);
    if (v < 0) {
        return;
    }
    uint8_t edge = 1u;
    while (edge < 4u && same(k->arg[2], edge_names[edge]) == 0u) {
        edge++;
    }
    if (edge == 4u) {
        reply_err(k->o, "unknown edge", k->arg[2]);
        return;
    }
    int32_t milli = 0;
    if (parse_milli(k->arg[3], &milli) == 0u) {
        reply_err(k->o, "bad number", k->arg[3]);
        return;
    }
    const int32_t counts = milli_to_counts(milli, (foc_var_t)v);
    const int rc = foc_scope_set_trigger(s, (foc_var_t)v, (foc_trig_edge_t)edge, counts);
    if (rc == FOC_SCOPE_EINVAL) {
        reply_err(k->o, "out of range", k->arg[3]);
    } else if (rc == FOC_SCOPE_OK) {
        out_str(k->o, "ok");
        out_key(k->o, "level");
        out_i64(k->o, counts);
        out_end(k->o);
    } else {
        reply_scope_code(k->o, rc);
    }
}

static void scope_arm(const call_t *k)
{
    reply_scope_code(k->o, foc_scope_arm(k->m->scope));
}

static void scope_stop(const call_t *k)
{
    foc_scope_stop(k->m->scope);
    reply_ok(k->o);
}

static void scope_dump(const call_t *k)
{
    const foc_scope_t *s = k->m->scope;
    if (foc_scope_state(s) != FOC_SCOPE_DONE) {
        reply_err(k->o, "scope not done", foc_scope_state_name(foc_scope_state(s)));
        return;
    }
    k->m->dump = DUMP_HEADER; /* written by foc_mon_poll */
    k->m->dump_index = 0u;
    k->m->dump_sum = 0u;
}

typedef struct {
    const char *name;
    void (*run)(const call_t *k);
    uint8_t takes_args; /* 0: the handler gets none (checked here) */
} subcmd_t;

static const subcmd_t scope_cmds[] = {
    { "state", scope_status, 0 }, { "ch", scope_channels, 1 },
    { "decim", scope_decim, 1 },  { "trig", scope_trig, 1 },
    { "pre", scope_pre, 1 },      { "arm", scope_arm, 0 },
    { "stop", scope_stop, 0 },    { "dump", scope_dump, 0 },
};

static void cmd_scope(const call_t *k)
{
    if (need_scope(k) == 0u) {
        return;
    }
    if (k->n == 0u) {
        scope_status(k);
        return;
    }
    for (unsigned i = 0; i < sizeof scope_cmds / sizeof scope_cmds[0]; i++) {
        if (same(k->arg[0], scope_cmds[i].name) != 0u) {
            if (scope_cmds[i].takes_args == 0u && k->n != 1u) {
                reply_err(k->o, "too many arguments", NULL);
                return;
            }
            scope_cmds[i].run(k);
            return;
        }
    }
    reply_err(k->o, "unknown scope command", k->arg[0]);
}

/* ---------------------------------------------------- command table -- */

typedef struct {
    const char *name;
    uint8_t min_args, max_args;
    void (*run)(const call_t *k);
    const char *syntax;
    const char *what;
} cmd_t;

static const cmd_t commands[] = {
    { "help", 0, 0, cmd_help, "help", "this list" },
    { "start", 0, 0, cmd_start, "start", "start the motor" },
    { "stop", 0, 0, cmd_stop, "stop", "stop the motor" },
    { "ack", 0, 0, cmd_ack, "ack", "acknowledge a fault" },
    { "speed", 1, 1, cmd_speed, "speed <rpm>", "speed command, mechanical, signed" },
    { "status", 0, 0, cmd_status, "status", "state, faults, speeds, currents, bus" },
    { "timing", 0, 1, cmd_timing, "timing [reset]", "fast-step interrupt cycles" },
    { "dac", 0, 2, cmd_dac, "dac [<var1> <var2>]", "debug outputs' variables" },
    { "vars", 0, 0, cmd_vars, "vars", "variables: name unit full-scale s|u" },
    { "scope", 0, 5, cmd_scope, "scope [state]", "capture configuration and state" },
    { "commission", 0, 0, cmd_commission, "commission", "measure the motor (from IDLE)" },
    { "ident", 0, 0, cmd_ident, "ident", "commissioning's results, as a motor file" },
};

#define N_COMMANDS (sizeof commands / sizeof commands[0])

static const char *const scope_help[] = {
    "scope ch <var> [..4]  channels",
    "scope decim <n>       a frame every n PWM periods",
    "scope trig immediate | scope trig <var> rising|falling|either <level>",
    "scope pre <0..100>    pre-trigger part, %",
    "scope arm|stop|dump   start, abandon, read out a capture",
};

static void cmd_help(const call_t *k)
{
    for (unsigned i = 0; i < N_COMMANDS; i++) {
        uint8_t col = 0;
        for (const char *p = commands[i].syntax; *p != '\0'; p++, col++) {
            out_char(k->o, *p);
        }
        do {
            out_char(k->o, ' ');
        } while (++col < 22u);
        out_line(k->o, commands[i].what);
    }
    for (unsigned i = 0; i < sizeof scope_help / sizeof scope_help[0]; i++) {
        out_line(k->o, scope_help[i]);
    }
    reply_ok(k->o);
}

/* Splits the line into words (in place); 0 if there are too many. */
static uint8_t split(char *line, char **words, uint8_t *n)
{
    *n = 0;
    char *p = line;
    for (;;) {
        while (*p == ' ') {
            p++;
        }
        if (*p == '\0') {
            return 1u;
        }
        if (*n == FOC_MON_MAX_ARGS) {
            return 0u;
        }
        words[(*n)++] = p;
        while (*p != ' ' && *p != '\0') {
            p++;
        }
        if (*p == ' ') {
            *p++ = '\0';
        }
    }
}

static void execute(foc_monitor_t *m, out_t *o)
{
    char *words[FOC_MON_MAX_ARGS];
    uint8_t n = 0;
    m->line[m->len] = '\0';
    if (split(m->line, words, &n) == 0u) {
        reply_err(o, "too many arguments", NULL);
        return;
    }
    if (n == 0u) {
        return; /* blank line: no reply */
    }
    for (unsigned i = 0; i < N_COMMANDS; i++) {
        const cmd_t *cmd = &commands[i];
        if (same(words[0], cmd->name) == 0u) {
            continue;
        }
        const uint8_t args = (uint8_t)(n - 1u);
        if (args < cmd->min_args) {
            reply_err(o, "missing argument", cmd->syntax);
        } else if (args > cmd->max_args) {
            reply_err(o, "too many arguments", NULL);
        } else {
            const call_t k = { m, o, &words[1], args };
            cmd->run(&k);
        }
        return;
    }
    reply_err(o, "unknown command", words[0]);
}

/* ------------------------------------------------------------- input -- */

void foc_mon_init(foc_monitor_t *m, foc_ctrl_t *ctrl, foc_scope_t *scope,
                  foc_isr_timing_t *timing, foc_mon_write_t write)
{
    m->ctrl = ctrl;
    m->scope = scope;
    m->timing = timing;
    m->write = write;
    m->len = 0u;
    m->line_error = 0u;
    m->last_cr = 0u;
    m->dump = DUMP_NONE;
    m->dump_index = 0u;
    m->dump_sum = 0u;
}

static void end_of_line(foc_monitor_t *m)
{
    out_t o;
    o.write = m->write;
    o.len = 0u;
    if ((m->line_error & LINE_TOO_LONG) != 0u) {
        out_str(&o, "err line too long (max ");
        out_u64(&o, FOC_MON_LINE_MAX, 1u);
        out_str(&o, " characters)");
        out_end(&o);
    } else if ((m->line_error & LINE_BAD_CHAR) != 0u) {
        reply_err(&o, "bad character", NULL);
    } else {
        execute(m, &o);
    }
    m->len = 0u;
    m->line_error = 0u;
}

void foc_mon_feed(foc_monitor_t *m, uint8_t byte)
{
    if (byte == (uint8_t)'\r' || byte == (uint8_t)'\n') {
        const uint8_t second_of_pair = (uint8_t)(byte == (uint8_t)'\n' && m->last_cr != 0u);
        m->last_cr = (uint8_t)(byte == (uint8_t)'\r');
        if (second_of_pair == 0u) {
            end_of_line(m);
        }
        return;
    }
    m->last_cr = 0u;
    if (m->dump != DUMP_NONE) {
        out_t o;
        o.write = m->write;
        o.len = 0u;
        m->dump = DUMP_NONE;
        reply_err(&o, "dump aborted", NULL);
    }
    if (byte == 0x08u || byte == 0x7Fu) { /* backspace, delete */
        if (m->len > 0u && m->line_error == 0u) {
            m->len--;
        }
        return;
    }
    if (byte == (uint8_t)'\t') {
        byte = (uint8_t)' ';
    }
    if (byte < 0x20u || byte > 0x7Eu) {
        m->line_error |= LINE_BAD_CHAR;
        return;
    }
    if (m->len >= FOC_MON_LINE_MAX) {
        m->line_error |= LINE_TOO_LONG;
        return;
    }
    if (byte >= (uint8_t)'A' && byte <= (uint8_t)'Z') {
        byte = (uint8_t)(byte + ('a' - 'A'));
    }
    m->line[m->len++] = (char)byte;
}

/* -------------------------------------------------------------- dump -- */

uint8_t foc_mon_poll(foc_monitor_t *m)
{
    const foc_scope_t *s = m->scope;
    out_t o;
    o.write = m->write;
    o.len = 0u;
    switch (m->dump) {
    case DUMP_HEADER:
        out_str(&o, "scope");
        out_scope_config(&o, s);
        out_end(&o);
        m->dump = DUMP_CHANNELS;
        return 1u;
    case DUMP_CHANNELS:
        out_str(&o, "chan ");
        out_u64(&o, m->dump_index, 1u);
        out_char(&o, ' ');
        out_var(&o, (foc_var_t)s->var[m->dump_index]);
        out_end(&o);
        if (++m->dump_index >= s->nch) {
            m->dump = DUMP_DATA;
            m->dump_index = 0u;
        }
        return 1u;
    case DUMP_DATA: {
        const uint16_t frame = m->dump_index;
        out_i64(&o, (int64_t)frame - (int64_t)foc_scope_pre_frames(s));
        for (uint8_t ch = 0; ch < s->nch; ch++) {
            const int16_t v = foc_scope_value(s, frame, ch);
            m->dump_sum = (uint16_t)(m->dump_sum + (uint16_t)v);
            out_char(&o, ' ');
            out_i64(&o, (foc_var_info((foc_var_t)s->var[ch])->is_unsigned != 0u)
                            ? (int64_t)(uint16_t)v
                            : (int64_t)v);
        }
        out_end(&o);
        if (++m->dump_index >= foc_scope_frames(s)) {
            m->dump = DUMP_END;
        }
        return 1u;
    }
    case DUMP_END:
        out_str(&o, "ok dump");
        out_key(&o, "frames");
        out_u64(&o, foc_scope_frames(s), 1u);
        out_key(&o, "sum");
        out_u64(&o, m->dump_sum, 1u);
        out_end(&o);
        m->dump = DUMP_NONE;
        return 0u;
    default:
        return 0u;
    }
}
