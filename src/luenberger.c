#include "foc/luenberger.h"
#include "foc/config.h"
#include "foc/trig.h"

/* State limits: +-1.0 of the base (the Q15 part stays a valid q15_t). */
#define I_STATE_MAX ((int32_t)32767 * (int32_t)LUENBERGER_F1)
#define E_STATE_MAX ((int32_t)32767 * (int32_t)LUENBERGER_F2)
/* h (Q16 rad) x e (Q15) is Q31 of the EMF; the state is Q(15 + log2 F2). */
#define ROT_SHIFT ((uint8_t)(16u - FOC_LUEN_F2_LOG2))
#define QUARTER_TURN 16384u
/* 1/|e| is held in Q9 (up to 64): the phase detector is normalised for
 * EMF amplitudes above 1/64 of the EMF base; below, its gain falls with
 * the EMF as in ST's PLL.  The same 1/64 of the speed base is the
 * hysteresis of the direction of rotation and the floor of the PLL
 * integrator's range. */
#define INV_Q 9u
#define INV_ONE ((int32_t)1 << INV_Q)
#define AMP_MIN ((int32_t)512) /* 32768 / 64 */
#define DIR_HYST ((q15_t)AMP_MIN)

static int32_t clamp32(int32_t x, int32_t max)
{
    if (x > max) {
        return max;
    }
    if (x < -max) {
        return -max;
    }
    return x;
}

/* Q15 part of a state (arithmetic shift; |state| <= 32767 x F). */
static q15_t q15_part(int32_t state, uint8_t log2_f)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return (q15_t)(state >> log2_f);
}

/* The phase detector's divisor: |e| within -3 %..+0 % (max(M, 7/8 M +
 * m/2) of the larger and smaller component; no multiplication), at least
 * FOC_LUEN_PLL_FULL_AMP (the EMF at full speed, >= 512 by config.h): the
 * detector's output is sin(angle error) times g = min(1, |e| / that EMF),
 * the PLL's gain scaled with the speed below maximum; <= 45056. */
static int32_t detector_amplitude(foc_ab_t e)
{
    const int32_t a = foc_abs_q15(e.alpha);
    const int32_t b = foc_abs_q15(e.beta);
    const int32_t big = (a > b) ? a : b;
    const int32_t small = (a > b) ? b : a;
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t blend = big - (big >> 3) + (small >> 1);
    const int32_t amp = (blend > big) ? blend : big;
    return (amp > FOC_LUEN_PLL_FULL_AMP) ? amp : FOC_LUEN_PLL_FULL_AMP;
}

/* One Newton step of inv -> 1/amp (Q9): inv (2 - amp inv), the factor
 * clamped to 0.25..1.75 so any start converges (geometrically, then
 * quadratically); the amplitude moves little per period, so one step a
 * period tracks it.  amp <= 45056 and inv <= 32767: products < 2^31. */
static void track_inverse(foc_luenberger_t *l, int32_t amp)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t one = (int32_t)1 << (15u + INV_Q); /* amp x inv = 1.0 */
    int32_t factor = 2 * one - amp * l->inv_amp;     /* Q24 */
    if (factor < one / 4) {
        factor = one / 4;
    } else if (factor > 7 * (one / 4)) {
        factor = 7 * (one / 4);
    } else {
        /* within the limits */
    }
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    l->inv_amp = clamp32((l->inv_amp * (factor >> INV_Q)) >> 15, 32767);
    if (l->inv_amp < 1) {
        l->inv_amp = 1;
    }
}

void foc_luen_reset(foc_luenberger_t *l, uint16_t theta, q15_t speed, foc_ab_t i_now)
{
    /* The EMF that speed implies, on the q axis at the centre of the
     * coming period; its Q15 amplitude is the Q15 speed (EMF base). */
    const uint16_t theta_mid =
        (uint16_t)(theta + (uint16_t)foc_mul_q15(speed, FOC_HALF_PERIOD_ANGLE));
    const foc_dq_t e_dq = { 0, speed };
    const foc_ab_t e_ab = foc_ipark_q15(e_dq, foc_sincos_q15(theta_mid));

    l->i_est.alpha = (int32_t)i_now.alpha * (int32_t)LUENBERGER_F1;
    l->i_est.beta = (int32_t)i_now.beta * (int32_t)LUENBERGER_F1;
    l->e_est.alpha = (int32_t)e_ab.alpha * (int32_t)LUENBERGER_F2;
    l->e_est.beta = (int32_t)e_ab.beta * (int32_t)LUENBERGER_F2;
    l->integ = 0;
    l->emf_speed = speed;
    l->forward = (uint8_t)(speed >= 0);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    l->inv_amp = INV_ONE;
    const int32_t amp = detector_amplitude(e_ab);
    for (unsigned k = 0; k < 16u; k++) {
        track_inverse(l, amp);
    }
    /* theta32 is the angle at the next sample (as after every step). */
    /* cppcheck-suppress misra-c2012-10.8 ; D3 modular angle */
    l->theta32 = ((uint32_t)theta << 16) + (uint32_t)((int32_t)speed * FOC_THETA32_PER_SPEED);
    l->theta = theta;
    l->omega = speed;
    foc_lpf_init(&l->speed, speed);
    foc_luen_set_winding(l, FOC_RATIO_ONE_Q14, FOC_RATIO_ONE_Q14);
    l->pll_kp = FOC_LUEN_PLL_KP_MANT;
    l->pll_ki = FOC_LUEN_PLL_KI;
}

/* One axis of the observer: predicts the current from the last period's
 * voltage and EMF, compares it with the sample and corrects both states. */
static void observe_axis(const foc_luenberger_t *l, int32_t *i_st, int32_t *e_st, q15_t v_last,
                         q15_t i_now)
{
    const q15_t i_hat = q15_part(*i_st, FOC_LUEN_F1_LOG2);
    const q15_t e_hat = q15_part(*e_st, FOC_LUEN_F2_LOG2);
    /* |sum| < 2^31: config.h holds F1 + |C1| + |C2| + |C3| + |C5| < 2^16. */
    const int32_t i_pred = clamp32(*i_st - (int32_t)l->c1 * i_hat - (int32_t)l->c3 * e_hat +
                                       (int32_t)l->c5 * v_last,
                                   I_STATE_MAX);
    const q15_t err = foc_sub_q15(q15_part(i_pred, FOC_LUEN_F1_LOG2), i_now);
    *i_st = clamp32(i_pred + (int32_t)l->c2 * err, I_STATE_MAX);
    *e_st = clamp32(*e_st + (int32_t)l->c4 * err, E_STATE_MAX);
}

/* c x 16384 / ratio (Q14), within q15_t (the ratio's range keeps it so). */
static q15_t over_ratio(int32_t c, int32_t ratio_q14)
{
    return foc_sat_q15(c * 16384 / ratio_q14);
}

/* x held within [lo, hi]. */
static int32_t held(int32_t x, int32_t lo, int32_t hi)
{
    return (x < lo) ? lo : (x > hi) ? hi : x;
}

void foc_luen_set_winding(foc_luenberger_t *l, q15_t rs_ratio_q14, q15_t ls_ratio_q14)
{
    const int32_t r = held(ls_ratio_q14, FOC_LUEN_RATIO_MIN, FOC_LUEN_RATIO_MAX);
    /* Rs T/Ls as a ratio to the parameters' (Q14), within its formats */
    const int32_t x_held =
        /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
        held((int32_t)rs_ratio_q14 * 16384 / r, FOC_LUEN_X_RATIO_MIN, FOC_LUEN_X_RATIO_MAX);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    l->c1 = foc_sat_q15(((int32_t)FOC_LUEN_C1 * x_held) >> 14);
    l->c2 = foc_sat_q15((int32_t)FOC_LUEN_C2 - FOC_LUEN_C2X +
                        /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
                        (((int32_t)FOC_LUEN_C2X * x_held) >> 14));
    l->c3 = over_ratio(FOC_LUEN_C3, r);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    l->c4 = foc_sat_q15(((int32_t)FOC_LUEN_C4 * r) >> 14);
    l->c5 = over_ratio(FOC_LUEN_C5, r);
}

/* x g / 2^15 for |x| < 2^30 and g Q15 in 0..32767, within 1 of the exact
 * product: x split at bit 15 (hi in -2^15..2^15-1, lo in 0..32767), each
 * partial product < 2^30.  Keeps the PLL integrator's input at low speed,
 * where Ki x phase error is a few units of Q15 and g a few percent. */
static int32_t times_q15(int32_t x, q15_t g)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t hi = x >> 15;
    const int32_t lo = x - hi * 32768;
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return hi * (int32_t)g + ((lo * (int32_t)g) >> 15);
}

/* e += h J e: rotation by h = w T (Q16 rad), forward Euler as ST. */
static void rotate_emf(foc_luen_ab32_t *e, q15_t speed)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t h = ((int32_t)speed * (int32_t)FOC_LUEN_C6) >> 15; /* |h| < 2^15 */
    const q15_t ea = q15_part(e->alpha, FOC_LUEN_F2_LOG2);
    const q15_t eb = q15_part(e->beta, FOC_LUEN_F2_LOG2);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t round = (int32_t)1 << (ROT_SHIFT - 1u);
    /* |h e| <= 2^30; after the shift <= 2^15 F2 / 2 (config.h) */
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    e->alpha = clamp32(e->alpha - ((h * eb + round) >> ROT_SHIFT), E_STATE_MAX);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    e->beta = clamp32(e->beta + ((h * ea + round) >> ROT_SHIFT), E_STATE_MAX);
}

void foc_luen_step(foc_luenberger_t *l, foc_ab_t v_last, foc_ab_t i_now)
{
    observe_axis(l, &l->i_est.alpha, &l->e_est.alpha, v_last.alpha, i_now.alpha);
    observe_axis(l, &l->i_est.beta, &l->e_est.beta, v_last.beta, i_now.beta);

    /* PLL.  e^ is the EMF of the last period: project it on the axes of
     * the angle half a period back.  e_q (signed) is the speed at nominal
     * flux: the feed-forward.  -e_d / |e|, sign-corrected for the
     * direction, is sin(angle error): the PI's input. */
    const foc_ab_t e = foc_luen_emf(l);
    track_inverse(l, detector_amplitude(e));
    l->theta = (uint16_t)(l->theta32 >> 16);
    const uint16_t theta_mid =
        (uint16_t)(l->theta - (uint16_t)foc_mul_q15(l->omega, FOC_HALF_PERIOD_ANGLE));
    const foc_sincos_t sc = foc_sincos_q15(theta_mid);
    const q15_t ed = foc_add_q15(foc_mul_q15(e.alpha, sc.cos), foc_mul_q15(e.beta, sc.sin));
    l->emf_speed = foc_sub_q15(foc_mul_q15(e.beta, sc.cos), foc_mul_q15(e.alpha, sc.sin));
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t ed_norm = ((int32_t)ed * l->inv_amp) >> INV_Q; /* < 2^31 */
    /* Weighted by how sure the direction is: 0 at standstill, 1 from the
     * hysteresis up (|filtered speed| / DIR_HYST in Q15).  Near zero speed
     * the feed-forward e_q, which changes sign with the rotation, carries
     * the PLL, not a push based on a direction that may be stale. */
    const int32_t w_abs = foc_abs_q15(foc_lpf_out(&l->speed));
    const q15_t sure = foc_sat_q15(((w_abs < DIR_HYST) ? w_abs : DIR_HYST) * (32768 / DIR_HYST));
    const q15_t phase_err =
        foc_mul_q15(foc_sat_q15((l->forward != 0u) ? -ed_norm : ed_norm), sure);
    /* PI: Ki e in Q30 added to the Q30 integrator, which holds the flux
     * error only: bounded to half the EMF speed plus the floor, so the PLL
     * cannot claim a speed its EMF does not show.  Ki acts on the phase
     * detector's output times g_w = min(1, |filtered speed| / the EMF at
     * full speed) (Q15, 0..32767): Kp g and Ki g g_w, g_w = g in a lock at
     * nominal flux, so the natural frequency is proportional to the speed
     * below maximum at constant damping; where the PLL's speed runs ahead
     * of its EMF (a held rotor's unmodelled resistance drop turning with
     * the current) its integrator speeds up with it, to the bound, which
     * the stall check's EMF test sees (luenberger.h). */
    const q15_t g_w = foc_mul_q15_shift((q15_t)w_abs, FOC_LUEN_PLL_INV_FULL_MANT,
                                        FOC_LUEN_PLL_INV_FULL_SHIFT);
    const int32_t i_max = ((int32_t)foc_abs_q15(l->emf_speed) / 2 + AMP_MIN) * 32768;
    l->integ = clamp32(l->integ + times_q15((int32_t)l->pll_ki * phase_err, g_w), i_max);
    const q15_t prop = foc_mul_q15_shift(phase_err, l->pll_kp, FOC_LUEN_PLL_KP_SHIFT);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    l->omega = foc_sat_q15((int32_t)l->emf_speed + prop + (l->integ >> 15));

    /* Angle for the next sample (the conversion to uint32_t wraps). */
    /* cppcheck-suppress misra-c2012-10.8 ; D3 modular angle */
    l->theta32 += (uint32_t)((int32_t)l->omega * FOC_THETA32_PER_SPEED);
    (void)foc_lpf_step(&l->speed, l->omega, FOC_LUEN_SPEED_FILTER_K);

    /* The filtered speed (equal to the rotor's in any lock) gives the
     * direction, with hysteresis so transients near standstill do not flip
     * it, and turns the EMF for the coming period (ST turns it with the
     * PLL's output: the filter keeps the PI's noise out of the model). */
    const q15_t w_out = foc_lpf_out(&l->speed);
    if (l->forward != 0u && w_out < -DIR_HYST) {
        l->forward = 0;
    } else if (l->forward == 0u && w_out > DIR_HYST) {
        l->forward = 1;
    } else {
        /* within the hysteresis: the direction stays */
    }
    rotate_emf(&l->e_est, w_out);
}

foc_ab_t foc_luen_emf(const foc_luenberger_t *l)
{
    const foc_ab_t e = { q15_part(l->e_est.alpha, FOC_LUEN_F2_LOG2),
                         q15_part(l->e_est.beta, FOC_LUEN_F2_LOG2) };
    return e;
}

uint16_t foc_luen_theta_atan(const foc_luenberger_t *l)
{
    /* The EMF leads the rotor's d axis by 90 degrees forwards and lags it
     * by 90 backwards; e^ is centred half a period after the sample. */
    const foc_ab_t e = foc_luen_emf(l);
    const uint16_t q_axis = foc_atan2_q15(e.beta, e.alpha);
    const uint16_t half = (uint16_t)foc_mul_q15(l->omega, FOC_HALF_PERIOD_ANGLE);
    const uint16_t to_d = (l->forward != 0u) ? (uint16_t)(0u - QUARTER_TURN) : QUARTER_TURN;
    return (uint16_t)(q_axis + to_d - half);
}
