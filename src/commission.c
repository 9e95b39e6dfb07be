#include "foc/commission.h"
#include "foc/config.h"
#include "foc/sqrt.h"

/* A result is accepted within [0.25, 2) of the parameter (Q14). */
#define RATIO_MIN_Q14 4096
#define RATIO_MAX_Q14 32767

void foc_comm_init(foc_comm_t *m)
{
    foc_comm_begin(m);
    m->step = (uint8_t)FOC_COMM_STEP_NONE;
    m->fast_mode = (uint8_t)FOC_COMM_MODE_OFF;
    m->count = 0;
}

void foc_comm_begin(foc_comm_t *m)
{
    m->step = (uint8_t)FOC_COMM_STEP_OFFSETS;
    m->mode = (uint8_t)FOC_COMM_MODE_OFF;
    m->level = 0;
    m->failed_step = (uint8_t)FOC_COMM_STEP_NONE;
    m->valid = 0;
    m->ticks = 0;
    m->rs_q14 = 0;
    m->ld_q14 = 0;
    m->lq_q14 = 0;
    m->flux_q14 = 0;
    m->j_q12 = 0;
    m->dt_q14 = 0;
    m->u.friction_i.low = 0;
    m->u.friction_i.high = 0;
}

/* ------------------------------------------------------------ per period */

/* A new mode: its sums start from zero, a pulse train half a half-period
 * in (so the triangle it drives is centred on the held current). */
static void fast_sync(foc_comm_t *m)
{
    if (m->fast_mode != m->mode) {
        m->fast_mode = m->mode;
        m->sum[0] = 0;
        m->sum[1] = 0;
        m->sum[2] = 0;
        m->sum[3] = 0;
        m->count = 0;
        m->cycles = 0;
        m->phase = (uint8_t)(FOC_COMM_PULSE_N / 2u);
    }
}

FOC_COLD void foc_comm_sum(foc_comm_t *m, foc_dq_t v, foc_dq_t i)
{
    fast_sync(m);
    if (m->count < FOC_COMM_SUM_N) { /* each sum within 2^15 x 2^12 */
        m->sum[0] += v.d;
        m->sum[1] += v.q;
        m->sum[2] += i.d;
        m->sum[3] += i.q;
        m->count++;
    }
}

/* Window sample j of n (0 .. n-1) has the least-squares weight
 * u = 2 j - (n - 1) (sum u i: the slope times sum u^2 / 2).  Summed by
 * parts, sum u i = sum over the intervals of W (the current's step), with
 * W = (j + 1) (n - 1 - j) after sample j; the step is (dV - Rs x the
 * interval's mean deviation) Ts / L, so the deviations weighted by the
 * mean of the W on either side, V = (2 j (n - 1 - j) + n - 1) / 2, give
 * Rs's share.  Both summed with the sign of the half, the hold cancels. */
static void pulse_add(foc_comm_t *m, int32_t j, int32_t dev, int32_t sign)
{
    const int32_t n = FOC_COMM_WIN_N;
    const int32_t u = 2 * j - (n - 1);           /* |u| < 32 */
    const int32_t v2 = 2 * j * (n - 1 - j) + n - 1; /* 2V < 512 */
    /* |dev| < 2^16: |u dev| < 2^21, |2V dev| < 2^25, shifted 4: the
     * totals, a slope's and a second-order share, stay within 2^31 */
    m->sum[0] += sign * u * dev;
    m->sum[1] += sign * ((v2 * dev) / 16);
}

FOC_COLD q15_t foc_comm_pulse(foc_comm_t *m, q15_t i_axis, q15_t i_hold)
{
    fast_sync(m);
    const int32_t k = m->phase;
    const int32_t n = FOC_COMM_PULSE_N;
    if (m->cycles >= 2u && m->count < FOC_COMM_PULSE_CYCLES) {
        /* window: samples 3 .. N-1 of each half, + then - */
        const int32_t j = (k < n) ? k - 3 : k - n - 3;
        if (j >= 0) {
            pulse_add(m, j, (int32_t)i_axis - i_hold, (k < n) ? 1 : -1);
        }
    }
    if (k + 1 >= 2 * n) {
        m->phase = 0;
        if (m->cycles >= 2u) {
            if (m->count < FOC_COMM_PULSE_CYCLES) {
                m->count++;
            }
        } else {
            m->cycles++;
        }
    } else {
        /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
        m->phase = (uint8_t)(k + 1);
    }
    const q15_t dv = (m->mode == (uint8_t)FOC_COMM_MODE_PULSE_D) ? FOC_COMM_PULSE_DV_D : FOC_COMM_PULSE_DV_Q;
    return (k < n) ? dv : (q15_t)-dv;
}

/* ------------------------------------------------------------ arithmetic */

/* floor(num x 2^bits / den) for num >= 0 and den > 0, else 0, held to
 * `max` (<= 2^31 - 1): a restoring division in 32 bits (libgcc's 64-bit
 * division would cost 1 KB of flash).  rem < den < 2^31 before each
 * doubling, so it never wraps; q <= max before each doubling. */
FOC_COLD static int32_t div_frac(int32_t num, int32_t den, uint8_t bits, int32_t max)
{
    if (num <= 0 || den <= 0) {
        return 0;
    }
    uint32_t q = (uint32_t)num / (uint32_t)den;
    uint32_t rem = (uint32_t)num - q * (uint32_t)den;
    for (uint8_t k = 0; k < bits; k++) {
        if (q > (uint32_t)max) {
            return max;
        }
        q <<= 1;
        rem <<= 1;
        if (rem >= (uint32_t)den) {
            rem -= (uint32_t)den;
            q |= 1u;
        }
    }
    return (q > (uint32_t)max) ? max : (int32_t)q;
}

/* (a x b) / 2^shift, the product in 64 bits; the callers state that the
 * result fits 32 bits (an arithmetic shift: floor, as GCC and XC16 do). */
FOC_COLD static int32_t mul_shift(int32_t a, int32_t b, uint8_t shift)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return (int32_t)(((int64_t)a * b) >> shift);
}

/* Q14 ratio num / den, 0 .. RATIO_MAX_Q14 + 1 (beyond: implausible). */
static int32_t ratio_q14(int32_t num, int32_t den)
{
    return div_frac(num, den, 14, (int32_t)RATIO_MAX_Q14 + 1);
}

static uint8_t plausible(int32_t r)
{
    return (uint8_t)(r >= RATIO_MIN_Q14 && r <= RATIO_MAX_Q14);
}

/* Mean of a sum of FOC_COMM_SUM_N Q15 values, rounded (Q15). */
static int32_t mean_q15(int32_t sum)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    return (sum + (int32_t)(FOC_COMM_SUM_N / 2u)) / (int32_t)FOC_COMM_SUM_N;
}

/* L / L_param from the pulse sums: sum[0] = Ts / L x (dV x 2 cycles
 * x sum W - Rs x the weighted deviations, sum[1] x 16 / 2), against the
 * parameter's sum_param = Ts / L_param x dV x 2 cycles x sum W; Rs's
 * share with the measured Rs (ts_tau_q20: Ts Rs / L_param, Q20). */
FOC_COLD static int32_t inductance_q14(const foc_comm_t *m, int32_t sum_param, int32_t ts_tau_q20)
{
    /* Ts Rs / L_param (Q20, < 2^20) x the Rs ratio (Q14, < 2^15): Q20
     * below 2^21; times sum[1] x 8 (|sum[1]| < 2^31) in a 64-bit product,
     * < 2^55, back to the regression sum's scale by 2^20 */
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int64_t rs_share = ((int64_t)mul_shift(ts_tau_q20, m->rs_q14, 14) * m->sum[1] * 8) >> 20;
    const int64_t num = (int64_t)sum_param - rs_share; /* sum_param < 2^29 */
    return ratio_q14((num > INT32_MAX) ? INT32_MAX : (int32_t)num, m->sum[0]);
}

static int32_t sat_q15(int32_t x)
{
    return (x > 32767) ? 32767 : (x < -32767) ? -32767 : x;
}

/* The flux from the spin's means (forced frame, Q15) at the forced speed
 * `speed` (Q15, > 0): E = V - Rs I - j w Lq I (Rs, Lq the measured ones)
 * lies on the rotor's q axis; the rotor's d current is I's component
 * along E turned back 90 deg; psi = |E| / w - (Ld - Lq) id_rotor, against
 * the parameter's w_base psi / V_base (FOC_COMM_KE_Q15).  Per-unit
 * reactances in Q20 (each below 2^30: config.h). */
FOC_COLD static int32_t flux_q14(const foc_comm_t *m, q15_t speed)
{
    const int32_t vx = mean_q15(m->sum[0]);
    const int32_t vy = mean_q15(m->sum[1]);
    const int32_t ix = mean_q15(m->sum[2]);
    const int32_t iy = mean_q15(m->sum[3]);
    /* the measured Rs and w Lq at this speed, Q20 per-unit, each below
     * 2^31: the parameters below 1000 per-unit (config.h), the ratios
     * below 2, the speed below 1 */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const int32_t rs_q20 = mul_shift(FOC_COMM_RS_Q20, m->rs_q14, 14);
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const int32_t xq_q20 = mul_shift(mul_shift(FOC_COMM_XQ_Q20, speed, 15), m->lq_q14, 14);
    /* each term below 2^31 x 2^15 / 2^20 = 2^26 */
    const int32_t ex = sat_q15(vx - mul_shift(rs_q20, ix, 20) + mul_shift(xq_q20, iy, 20));
    const int32_t ey = sat_q15(vy - mul_shift(rs_q20, iy, 20) - mul_shift(xq_q20, ix, 20));
    /* each square below 2^30: the sum fits 32 bits unsigned */
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    const int32_t e = (int32_t)foc_isqrt32((uint32_t)(ex * ex) + (uint32_t)(ey * ey));
    if (e <= 0 || speed <= 0) {
        return 0;
    }
    /* |ex|, |ey| <= 32767 and |ix|, |iy| <= 32768: the cross product is
     * below 2^31; id_rotor Q15, |id_rotor| <= |I| < 2^16 */
    const int32_t id_rotor = ((int32_t)ix * ey - (int32_t)iy * ex) / e;
    /* Xd Ld_ratio - Xq Lq_ratio, Q20: both terms in [0, 2^31), so is
     * the difference's magnitude; times id_rotor (< 2^16) / 2^20: < 2^27 */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const int32_t xdq_q20 = mul_shift(FOC_COMM_XD_Q20, m->ld_q14, 14) - mul_shift(FOC_COMM_XQ_Q20, m->lq_q14, 14);
    const int32_t reluctance_q15 = mul_shift(xdq_q20, id_rotor, 20);
    /* |E| / w, Q15 per-unit flux, held below 2^30: the difference fits */
    const int32_t psi_q15 = div_frac(e, speed, 15, 1073741823) - reluctance_q15;
    return ratio_q14(psi_q15, FOC_COMM_KE_Q15);
}

/* ------------------------------------------------------------- sequence */

static void next_step(foc_comm_t *m, foc_comm_step_t step, foc_comm_mode_t mode)
{
    m->step = (uint8_t)step;
    m->mode = (uint8_t)mode;
    m->level = 0;
    m->ticks = 0;
}

static foc_comm_status_t fail(foc_comm_t *m)
{
    m->failed_step = m->step;
    m->mode = (uint8_t)FOC_COMM_MODE_OFF;
    return FOC_COMM_FAILED;
}

static uint8_t offsets_ok(const foc_abc_t *o)
{
    return (uint8_t)(foc_abs_q15(o->a) <= FOC_COMM_OFFSET_MAX && foc_abs_q15(o->b) <= FOC_COMM_OFFSET_MAX &&
                     foc_abs_q15(o->c) <= FOC_COMM_OFFSET_MAX);
}

/* The waiting mode (HOLD, SPIN) for `settle` ticks of the step, then
 * `measure` until the fast step's sums are complete: 1 then. */
static uint8_t measured(foc_comm_t *m, uint16_t settle, foc_comm_mode_t measure)
{
    if (m->ticks < settle) {
        return 0;
    }
    m->mode = (uint8_t)measure;
    const uint16_t target = (measure == FOC_COMM_MODE_PULSE_D || measure == FOC_COMM_MODE_PULSE_Q)
                                ? FOC_COMM_PULSE_CYCLES
                                : FOC_COMM_SUM_N;
    return (uint8_t)(m->fast_mode == m->mode && m->count >= target);
}

/* The bridge's effective dead time, Q14 of DEADTIME_EFFECTIVE_S, 1 ..
 * 32767 (0 in a build without dead time), from `miss`, what the bridge
 * model of dead-time voltage `dt_model` missed along d at standstill
 * (Q15): at angle 0 the phase currents are (I, -I/2, -I/2), beyond the
 * dead time's soft bands, and the bridge loses 4/3 of a phase's dead-time
 * voltage along d.  |4 dt_model + 3 miss| < 2^17. */
static q15_t deadtime_ratio(int32_t miss, q15_t dt_model)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    if (FOC_DT_VOLTAGE == 0) {
        return 0;
    }
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const int32_t r = ratio_q14((4 * (int32_t)dt_model) + (3 * miss), 4 * (int32_t)FOC_DT_VOLTAGE);
    return (q15_t)((r < 1) ? 1 : ((r > RATIO_MAX_Q14) ? RATIO_MAX_Q14 : r));
}

static foc_comm_status_t rs_tick(foc_comm_t *m, foc_startup_t *su, q15_t dt_model)
{
    su->current = (m->level == 0u) ? FOC_COMM_I_HIGH : FOC_COMM_I_LOW;
    if (measured(m, FOC_COMM_SETTLE_TICKS, FOC_COMM_MODE_SUM) == 0u) {
        return FOC_COMM_BUSY;
    }
    if (m->level == 0u) {
        /* no current where one was asked: an open phase, a dead sensor */
        if (mean_q15(m->sum[2]) < (FOC_COMM_I_HIGH / 4) * 3) {
            return fail(m);
        }
        m->u.rs.v_high = m->sum[0];
        m->u.rs.i_high = m->sum[2];
        m->level = 1;
        m->ticks = 0;
        m->mode = (uint8_t)FOC_COMM_MODE_HOLD;
        return FOC_COMM_BUSY;
    }
    const int32_t di = m->u.rs.i_high - m->sum[2];
    /* the two levels' currents at least a quarter of the high one apart */
    if (mean_q15(di) < FOC_COMM_I_HIGH / 4) {
        return fail(m);
    }
    /* Rs per-unit, Q20 (< 2^31 while within 2 x the parameter: config.h
     * holds FOC_RS_PU below 1000), then its ratio to the parameter */
    const int32_t rs_q20 = div_frac(m->u.rs.v_high - m->sum[0], di, 20, INT32_MAX);
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const int32_t r = ratio_q14(rs_q20, FOC_COMM_RS_Q20);
    if (plausible(r) == 0u) {
        return fail(m);
    }
    m->rs_q14 = (q15_t)r;
    /* the line's intercept at the high level: vd - Rs id, within 2^27
     * as the sums (Rs id is the sum's part) */
    m->dt_q14 = deadtime_ratio(mean_q15(m->u.rs.v_high - mul_shift(rs_q20, m->u.rs.i_high, 20)),
                               dt_model);
    next_step(m, FOC_COMM_STEP_LD, FOC_COMM_MODE_HOLD);
    return FOC_COMM_BUSY;
}

static foc_comm_status_t inductance_tick(foc_comm_t *m, foc_startup_t *su)
{
    const uint8_t d = (uint8_t)(m->step == (uint8_t)FOC_COMM_STEP_LD);
    su->current = FOC_COMM_I_LOW;
    if (measured(m, FOC_COMM_SETTLE_TICKS, d ? FOC_COMM_MODE_PULSE_D : FOC_COMM_MODE_PULSE_Q) == 0u) {
        return FOC_COMM_BUSY;
    }
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const int32_t r = d ? inductance_q14(m, FOC_COMM_PULSE_SUM_D, FOC_COMM_TS_TAU_D_Q20)
                        /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
                        : inductance_q14(m, FOC_COMM_PULSE_SUM_Q, FOC_COMM_TS_TAU_Q_Q20);
    if (plausible(r) == 0u) {
        return fail(m);
    }
    if (d != 0u) {
        m->ld_q14 = (q15_t)r;
        next_step(m, FOC_COMM_STEP_LQ, FOC_COMM_MODE_HOLD);
    } else {
        m->lq_q14 = (q15_t)r;
        /* the I/f spin from the aligned rotor, the start-up's ramp */
        su->direction = 1;
        su->speed16 = 0;
        su->speed = 0;
        su->ticks = 0;
        su->current = FOC_OL_CURRENT_FIRST;
        next_step(m, FOC_COMM_STEP_FLUX, FOC_COMM_MODE_SPIN);
    }
    return FOC_COMM_BUSY;
}

/* A measured ratio within FOC_COMM_MECH_MATCH of the parameter (Q14). */
static uint8_t near_parameter(int32_t r)
{
    return (uint8_t)(r >= FOC_COMM_MECH_MATCH_MIN_Q14 && r <= FOC_COMM_MECH_MATCH_MAX_Q14);
}

/* FLUX: level 0 the ramp, 1 the swing settling, then the sums. */
static foc_comm_status_t flux_tick(foc_comm_t *m, foc_startup_t *su)
{
    foc_startup_ramp_tick(su, FOC_COMM_SPIN_SPEED);
    if (m->level == 0u) {
        if (su->speed >= FOC_COMM_SPIN_SPEED) {
            m->level = 1;
            m->ticks = 0;
        }
        return FOC_COMM_BUSY;
    }
    if (measured(m, FOC_COMM_SPIN_SETTLE_TICKS, FOC_COMM_MODE_SPIN_SUM) == 0u) {
        return FOC_COMM_BUSY;
    }
    /* a rotor that does not follow shows (almost) no back-EMF */
    const int32_t r = flux_q14(m, su->speed);
    if (plausible(r) == 0u) {
        return fail(m);
    }
    m->flux_q14 = (q15_t)r;
    m->valid = 1;
    if (near_parameter(r) == 0u || near_parameter(m->ld_q14) == 0u || near_parameter(m->lq_q14) == 0u) {
        m->mode = (uint8_t)FOC_COMM_MODE_OFF;
        return FOC_COMM_DONE;
    }
    /* MECH's sums from zero (mode OFF: the fast step leaves them), the
     * fast step's block full: MECH's first tick takes it (unused) */
    next_step(m, FOC_COMM_STEP_MECH, FOC_COMM_MODE_OFF);
    m->sum[0] = 0;
    m->sum[1] = 0;
    m->sum[2] = 0;
    m->sum[3] = 0;
    m->u.friction_i.low = 0;
    m->u.friction_i.high = 0;
    m->iq_block = 0;
    m->count = (uint16_t)CONTROL_SLOW_DIVIDER;
    return FOC_COMM_HANDOVER;
}

FOC_COLD foc_comm_status_t foc_comm_tick(foc_comm_t *m, foc_startup_t *su, const foc_comm_in_t *in)
{
    if (m->ticks < UINT16_MAX) {
        m->ticks++;
    }
    if (m->ticks > FOC_COMM_STEP_TIMEOUT_TICKS) {
        return fail(m);
    }
    switch (m->step) {
    case FOC_COMM_STEP_OFFSETS:
        /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
        if (in->calibrated == 0u || m->ticks < FOC_CALIB_TICKS) {
            return FOC_COMM_BUSY;
        }
        if (offsets_ok(&in->offset) == 0u) {
            return fail(m);
        }
        foc_startup_begin(su, 1);
        next_step(m, FOC_COMM_STEP_ALIGN, FOC_COMM_MODE_HOLD);
        return FOC_COMM_BUSY;
    case FOC_COMM_STEP_ALIGN:
        /* the start-up's alignment to angle 0, then the rotor settles at
         * the high current */
        if (m->level == 0u) {
            if (foc_startup_align_tick(su) != 0u) {
                m->level = 1;
                m->ticks = 0;
            }
        } else if (m->ticks >= FOC_COMM_ROTOR_SETTLE_TICKS) {
            next_step(m, FOC_COMM_STEP_RS, FOC_COMM_MODE_HOLD);
        } else {
            /* the rotor settles */
        }
        if (m->level != 0u) {
            su->current = FOC_COMM_I_HIGH;
        }
        return FOC_COMM_BUSY;
    case FOC_COMM_STEP_RS:
        return rs_tick(m, su, in->dt_model);
    case FOC_COMM_STEP_LD:
    case FOC_COMM_STEP_LQ:
        return inductance_tick(m, su);
    case FOC_COMM_STEP_FLUX:
        return flux_tick(m, su);
    default:
        return fail(m);
    }
}

/* MECH's levels: each ends after its ticks (the windows' sums start at
 * the speed step, the friction's once settled). */
#define MECH_SETTLE 0u      /* to the low speed: a window's time */
#define MECH_LOW 1u         /* the friction at the low speed */
#define MECH_UP 2u          /* the window up */
#define MECH_HIGH 3u        /* the friction at the high speed */
#define MECH_DOWN 4u        /* the window down */

/* J / MOTOR_INERTIA_KGM2 (Q12) from the sums: X = A_up - A_down - s
 * (W_up - W_down) with the friction's slope s = (i_high - i_low) / dw in
 * Q24 (|i| < 2^15, dw > 2^8: s < 2^31), times the measured flux's share
 * of Kt, against FOC_COMM_MECH_J_SUM.  In 64 bits: a q current near its
 * limit in both windows would not fit 32 (the result is then refused). */
FOC_COLD static int32_t inertia_q12(const foc_comm_t *m)
{
    const int32_t slope_q24 = mul_shift(m->u.friction_i.high - m->u.friction_i.low, FOC_COMM_MECH_INV_DW_Q24,
                                        FOC_COMM_MECH_SUM_LOG2);
    const int64_t x = (int64_t)m->sum[0] - m->sum[2] -
                      /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
                      (((int64_t)slope_q24 * ((int64_t)m->sum[1] - m->sum[3])) >> 24);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int64_t kt_x = (x * m->flux_q14) >> 14;
    const int32_t num = (kt_x > INT32_MAX) ? INT32_MAX : (kt_x < 0) ? 0 : (int32_t)kt_x;
    return div_frac(num, FOC_COMM_MECH_J_SUM, 12, 32768);
}

FOC_COLD q15_t foc_comm_mech_tick(foc_comm_t *m, q15_t speed)
{
    const uint8_t level = m->level;
    if (m->count < (uint16_t)CONTROL_SLOW_DIVIDER) {
        /* the fast step's block is not complete: a tick that counts not */
        return (level == MECH_UP || level == MECH_HIGH) ? FOC_COMM_MECH_HIGH : FOC_COMM_MECH_LOW;
    }
    /* the block's mean, rounded (the noise dithers the rounding) */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    const int32_t half = (m->iq_block < 0) ? -(int32_t)(CONTROL_SLOW_DIVIDER / 2) : (int32_t)(CONTROL_SLOW_DIVIDER / 2);
    const q15_t iq = (q15_t)((m->iq_block + half) / (int32_t)CONTROL_SLOW_DIVIDER);
    m->iq_block = 0;
    m->count = 0; /* last: the fast step sums again */
    const uint16_t length = (level == MECH_LOW || level == MECH_HIGH) ? FOC_COMM_MECH_SUM_N
                                                                      : (uint16_t)FOC_COMM_MECH_WINDOW_TICKS;
    /* the sums (zeroed when MECH began): |iq|, |speed| < 2^15 over at
     * most 2^15 ticks */
    if (level == MECH_LOW || level == MECH_HIGH) {
        *((level == MECH_LOW) ? &m->u.friction_i.low : &m->u.friction_i.high) += iq;
    } else if (level != MECH_SETTLE) {
        int32_t *const window = &m->sum[(level == MECH_DOWN) ? 2 : 0];
        window[0] += iq;
        window[1] += speed;
    } else {
        /* MECH_SETTLE: nothing summed */
    }
    m->ticks++;
    if (m->ticks >= length) {
        m->ticks = 0;
        m->level = (uint8_t)(level + 1u);
        if (level == MECH_DOWN) {
            const int32_t j = inertia_q12(m);
            m->step = (uint8_t)FOC_COMM_STEP_NONE;
            if (j >= 256 && j <= 32767) {
                m->j_q12 = (q15_t)j;
            } else {
                m->failed_step = (uint8_t)FOC_COMM_STEP_MECH;
            }
        }
    }
    return (m->level == MECH_UP || m->level == MECH_HIGH) ? FOC_COMM_MECH_HIGH : FOC_COMM_MECH_LOW;
}

const char *foc_comm_step_name(uint8_t step)
{
    static const char *const names[] = { "NONE", "OFFSETS", "ALIGN", "RS", "LD", "LQ", "FLUX", "MECH" };
    return (step < sizeof names / sizeof names[0]) ? names[step] : "?";
}
