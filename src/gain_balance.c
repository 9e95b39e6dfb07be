/* Current-sensor gain balance: see gain_balance.h. */
#include "foc/gain_balance.h"
#include "foc/config.h"
#include "foc/sqrt.h"
#include "foc/trig.h"

/* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
FOC_STATIC_ASSERT(FOC_GB_Z_SHIFT <= 13 && FOC_GB_MIN_SPEED < FOC_GB_MAX_SPEED,
                  "gain balance: an impedance beyond 8192 per-unit, or the slow tick too slow "
                  "for twice the electrical frequency (CONTROL_SLOW_DIVIDER)");

#define GB_LIMIT_BITS 25u /* Gh per component within [-1/8, 1/8) in Q27 */
#define GB_MEAN_K ((q15_t)256)          /* the means: 1/128 per tick */
#define GB_HOLD_TICKS 128u              /* after a transient: the means' */
                                        /* time constant */
/* |W|^2 (Q29) below which the tick holds (|W| < 1/32 of 2^FOC_GB_Z_SHIFT
 * per-unit): the noise would swamp the mismatch. */
#define GB_DEN_MIN ((int32_t)0x80000) /* 2^19 */
/* The step's share 2^-rate: 2^-8 for the first 128 learning ticks, 2^-9
 * for the next 128, 2^-10 for 256, then 2^-11 (a mean over ever more
 * ticks: quick to learn, then steady against the noise; the gains do not
 * change). */
#define GB_RATE_FIRST_LOG2 8u
#define GB_RATE_LAST_LOG2 11u

void foc_gb_init(foc_gain_balance_t *gb)
{
    const foc_dq_t zero = { 0, 0 };
    foc_gb_follow(gb, zero, zero);
    gb->g_re_q27 = 0;
    gb->g_im_q27 = 0;
    gb->g_re = 0;
    gb->g_im = 0;
    gb->learned = 0;
}

void foc_gb_follow(foc_gain_balance_t *gb, foc_dq_t v, foc_dq_t i)
{
    foc_lpf_init(&gb->vd, v.d);
    foc_lpf_init(&gb->vq, v.q);
    foc_lpf_init(&gb->id, i.d);
    foc_lpf_init(&gb->iq, i.q);
    gb->vn_power = 0;
    gb->hold = GB_HOLD_TICKS;
}

void foc_gb_tick(foc_gain_balance_t *gb, uint16_t theta, foc_dq_t v, foc_dq_t i, q15_t speed)
{
    const q15_t vn_d = foc_sub_q15(v.d, foc_lpf_out(&gb->vd));
    const q15_t vn_q = foc_sub_q15(v.q, foc_lpf_out(&gb->vq));
    const foc_dq_t i_mean = { foc_lpf_out(&gb->id), foc_lpf_out(&gb->iq) };
    const int32_t in_d = foc_sub_q15(i.d, i_mean.d);
    const int32_t in_q = foc_sub_q15(i.q, i_mean.q);
    (void)foc_lpf_step(&gb->vd, v.d, GB_MEAN_K);
    (void)foc_lpf_step(&gb->vq, v.q, GB_MEAN_K);
    (void)foc_lpf_step(&gb->id, i.d, GB_MEAN_K);
    (void)foc_lpf_step(&gb->iq, i.q, GB_MEAN_K);
    /* the voltage's deviation, |vn|^2 in W's scale (Q29), over 16 ticks */
    const q15_t vz_d = foc_mul_q15(vn_d, FOC_GB_V_TO_Z);
    const q15_t vz_q = foc_mul_q15(vn_q, FOC_GB_V_TO_Z);
    const int32_t vn2 = foc_mul_q29(vz_d, vz_d) + foc_mul_q29(vz_q, vz_q);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    gb->vn_power += (vn2 - gb->vn_power) >> 4;
    const q15_t w = foc_abs_q15(speed);
    if (w < FOC_GB_MIN_SPEED || w > FOC_GB_MAX_SPEED) {
        return;
    }
    /* Zn = r - j x, Q15 of 2^FOC_GB_Z_SHIFT per-unit */
    const q15_t r = FOC_GB_RS_Z;
    const q15_t x = foc_mul_q15(speed, FOC_GB_XL_Z);
    /* W = Zn conj(I) = (r Id - x Iq) - j (r Iq + x Id) */
    const q15_t w_re = foc_q29_to_q15(foc_mul_q29(r, i_mean.d) - foc_mul_q29(x, i_mean.q));
    const q15_t w_im = foc_sat_q15(-(int32_t)foc_q29_to_q15(foc_mul_q29(r, i_mean.q) + foc_mul_q29(x, i_mean.d)));
    const int32_t den = foc_mul_q29(w_re, w_re) + foc_mul_q29(w_im, w_im); /* |W|^2, Q29 */
    if (den < GB_DEN_MIN) {
        return;
    }
    /* Noise or a transient: the voltage's deviation (noise through the
     * current PI's gain, a mean that lags) beyond W / 2.8 in RMS (the
     * largest mismatch's share is 0.18 W) would move Gh by more than it
     * learns (a fan at 0.13 A, flying start: 2.6 % in 7 ticks, then its
     * iq swung 0.9 A); it holds the learning until 128 ticks after. */
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    if (gb->vn_power > (den >> 3)) {
        gb->hold = GB_HOLD_TICKS;
        return;
    }
    if (gb->hold != 0u) {
        gb->hold--;
        return;
    }
    /* Zn In - Vn before the turn, Q28 of 2^FOC_GB_Z_SHIFT, each term
     * below 2^28 */
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t v_scale = (int32_t)1 << (13 - FOC_GB_Z_SHIFT);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t e_re = (((int32_t)r * in_d) >> 2) + (((int32_t)x * in_q) >> 2) - vn_d * v_scale;
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t e_im = (((int32_t)r * in_q) >> 2) - (((int32_t)x * in_d) >> 2) - vn_q * v_scale;
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const q15_t e_re15 = foc_sat_q15((e_re + 0x1000) >> 13);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const q15_t e_im15 = foc_sat_q15((e_im + 0x1000) >> 13);
    /* D = that e^{j 2 theta} */
    const foc_sincos_t sc2 = foc_sincos_q15((uint16_t)(theta * 2u));
    const q15_t d_re = foc_q29_to_q15(foc_mul_q29(e_re15, sc2.cos) - foc_mul_q29(e_im15, sc2.sin));
    const q15_t d_im = foc_q29_to_q15(foc_mul_q29(e_re15, sc2.sin) + foc_mul_q29(e_im15, sc2.cos));
    /* the step D conj(W) / |W|^2 / 2^rate, Q27; |W|^2 >= 2^s */
    const int32_t num_re = foc_mul_q29(d_re, w_re) + foc_mul_q29(d_im, w_im);
    const int32_t num_im = foc_mul_q29(d_im, w_re) - foc_mul_q29(d_re, w_im);
    /* floor(log2(learned / 128 + 1)) = bit length - 1 */
    uint8_t rate = (uint8_t)(GB_RATE_FIRST_LOG2 - 1u + foc_bit_length((uint32_t)(gb->learned >> 7) + 1u));
    if (rate > GB_RATE_LAST_LOG2) {
        rate = GB_RATE_LAST_LOG2;
    }
    if (gb->learned < UINT16_MAX) {
        gb->learned++;
    }
    /* floor(log2 den) + rate - 27: den >= 2^19, at least 0 */
    const uint8_t shift = (uint8_t)(foc_bit_length((uint32_t)den) + rate - 28u);
    /* learned, saturated (|Gh| <= 2^24 and the step < 2^30: no overflow) */
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    gb->g_re_q27 = FOC_SAT_BITS(gb->g_re_q27 + (num_re >> shift), GB_LIMIT_BITS);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    gb->g_im_q27 = FOC_SAT_BITS(gb->g_im_q27 + (num_im >> shift), GB_LIMIT_BITS);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    gb->g_re = (q15_t)((gb->g_re_q27 + 0x800) >> 12);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    gb->g_im = (q15_t)((gb->g_im_q27 + 0x800) >> 12);
}
