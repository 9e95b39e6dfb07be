#include "foc/flux_est.h"
#include "foc/config.h"
#include "foc/trig.h"

/* Range of the learned magnet flux, Q31. */
#define PSI_M_MAX ((q31_t)FOC_FLUX_PSI_M * (q31_t)98304) /* 1.5 psi_m */
#define PSI_M_MIN ((q31_t)FOC_FLUX_PSI_M * (q31_t)32768) /* 0.5 psi_m */

uint8_t foc_flux_consistent(const foc_flux_est_t *f)
{
    return (uint8_t)(f->psi_m > PSI_M_MIN && f->psi_m < PSI_M_MAX);
}

/* Largest radial error the radius learns from, Q15 (0.1 psi_m). */
#define RADIAL_ERR_MAX ((int32_t)FOC_FLUX_PSI_M / 10)

/* Largest correction gain per period, Q15 (0.5). */
#define G_MAX ((int32_t)16384)

/* Ls i, Q15 flux (Ls < 1.0: FOC_FLUX_LS < 0.5 times a ratio < 2). */
static q15_t ls_i(const foc_flux_est_t *f, q15_t i)
{
    return foc_mul_q15(i, f->ls);
}

/* Rotor flux psi_s - Ls i on one axis, Q15. */
static q15_t rotor_flux(q31_t psi_s, q15_t li)
{
    return foc_sub_q15(foc_q31_to_q15(psi_s), li);
}

void foc_flux_set_rs(foc_flux_est_t *f, q15_t ratio_q14)
{
    f->rs = foc_mul_q15(FOC_RS2_MANT, ratio_q14);
}

void foc_flux_set_ls(foc_flux_est_t *f, q15_t ratio_q14)
{
    f->ls = foc_mul_q15_shift(FOC_FLUX_LS, ratio_q14, 1);
}

void foc_flux_reset(foc_flux_est_t *f, uint16_t theta, q15_t speed, foc_ab_t i_now)
{
    foc_flux_set_ls(f, FOC_RATIO_ONE_Q14);
    const foc_sincos_t sc = foc_sincos_q15(theta);
    f->psi_r.alpha = foc_mul_q15(FOC_FLUX_PSI_M, sc.cos);
    f->psi_r.beta = foc_mul_q15(FOC_FLUX_PSI_M, sc.sin);
    f->psi_alpha = (q31_t)foc_add_q15(f->psi_r.alpha, ls_i(f, i_now.alpha)) * (q31_t)65536;
    f->psi_beta = (q31_t)foc_add_q15(f->psi_r.beta, ls_i(f, i_now.beta)) * (q31_t)65536;
    f->i_prev = i_now;
    f->psi_m = (q31_t)FOC_FLUX_PSI_M * (q31_t)65536;
    foc_flux_set_rs(f, FOC_RATIO_ONE_Q14);
    /* Angle history of a constant speed: steps in counts per period,
     * |speed x THETA32_PER_SPEED| < 2^30. */
    /* cppcheck-suppress [misra-c2012-10.1, misra-c2012-10.8] ; D1 Q-format shift, D2 compile-time constant */
    const int16_t step = (int16_t)(((int32_t)speed * FOC_THETA32_PER_SPEED) >> 16);
    f->dtheta1 = step;
    f->dtheta2 = step;
    f->theta = theta;
    foc_speed_obs_reset(&f->obs, theta, speed, foc_park_q15(i_now, sc).q);
    f->corr_min = FOC_FLUX_CORR_MIN;
    f->corr_speed = FOC_FLUX_CORR_SPEED;
}

/* Eq. 4 on one axis: psi += Ts (v - Rs i_mid), Q31.  v - Rs i reaches
 * 2 pu (full voltage against full current), so it enters at half scale;
 * the increment is below 2^28 (FOC_FLUX_KINT_X < 8192, config.h). */
static q31_t integrate(q31_t psi, q15_t v, q15_t i, q15_t i_prev, q15_t rs)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const q15_t i_mid = (q15_t)(((int32_t)i + (int32_t)i_prev) >> 1);
    const q15_t r_drop = foc_mul_q15_shift(i_mid, rs, FOC_RS2_SHIFT);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const q15_t e_half = foc_sat_q15(((int32_t)v - (int32_t)r_drop + 1) >> 1);
    return foc_add_q31(psi, foc_mul_norm32(e_half, FOC_FLUX_KINT_MANT, FOC_FLUX_KINT_RSHIFT));
}

/* Eq. 15/17 on one axis: psi += g (target - psi_r), Q31;
 * |g x err x 2| <= 2^30 since 0 <= g <= G_MAX. */
static q31_t correct(q31_t psi, q15_t target, q15_t psi_r, int32_t g)
{
    const q15_t err = foc_sub_q15(target, psi_r);
    return foc_add_q31(psi, g * (int32_t)err * 2);
}

/* The circle's radius: the mean of the rotor flux component along the
 * predicted direction (`radial`, about |psi_r|), low-passed at
 * FLUX_MAG_PER_SPEED |w| and held within [0.5, 1.5] psi_m.  A flux offset
 * makes that component swing at the rotor frequency, above the low-pass,
 * and is corrected; a steady radial error (Rs error, dead time, magnet
 * temperature) is learned instead of fought, which would turn it into an
 * angle error.  The error learned from is limited to 0.1 psi_m, so the
 * large swings of an unknown initial flux (whose mean is biased outward)
 * barely move the radius.  Returns the radius before this update, Q15. */
static q15_t learn_radius(foc_flux_est_t *f, q15_t radial, q15_t speed_abs)
{
    const q15_t mag = foc_q31_to_q15(f->psi_m);
    const q15_t g_mag = foc_mul_q15(speed_abs, FOC_FLUX_MAG_SPEED); /* < 0.5 */
    int32_t err = (int32_t)radial - (int32_t)mag;
    if (err > RADIAL_ERR_MAX) {
        err = RADIAL_ERR_MAX;
    } else if (err < -RADIAL_ERR_MAX) {
        err = -RADIAL_ERR_MAX;
    } else {
        /* within the limits */
    }
    f->psi_m = foc_add_q31(f->psi_m, (int32_t)g_mag * err * 2);
    if (f->psi_m > PSI_M_MAX) {
        f->psi_m = PSI_M_MAX;
    } else if (f->psi_m < PSI_M_MIN) {
        f->psi_m = PSI_M_MIN;
    } else {
        /* within the limits */
    }
    return mag;
}

/* Correction gain per period (k_min + c |w|) Ts, Q15, at most G_MAX. */
static int32_t correction_gain(const foc_flux_est_t *f, q15_t speed_abs)
{
    const int32_t g = (int32_t)f->corr_min + (int32_t)foc_mul_q15(speed_abs, f->corr_speed);
    return (g > G_MAX) ? G_MAX : g;
}

void foc_flux_step(foc_flux_est_t *f, foc_ab_t v_last, foc_ab_t i_now, q15_t iq_ref)
{
    f->psi_alpha = integrate(f->psi_alpha, v_last.alpha, i_now.alpha, f->i_prev.alpha, f->rs);
    f->psi_beta = integrate(f->psi_beta, v_last.beta, i_now.beta, f->i_prev.beta, f->rs);
    f->i_prev = i_now;
    const q15_t li_alpha = ls_i(f, i_now.alpha);
    const q15_t li_beta = ls_i(f, i_now.beta);

    /* Eq. 16: 3 th(k-1) - 3 th(k-2) + th(k-3)
     *       = th(k-1) + 2 (th(k-1) - th(k-2)) - (th(k-2) - th(k-3));
     * the conversion to uint16_t wraps modulo 360 deg. */
    /* cppcheck-suppress misra-c2012-10.8 ; D3 modular angle */
    const uint16_t theta_p = (uint16_t)((int32_t)f->theta + 2 * (int32_t)f->dtheta1 -
                                        (int32_t)f->dtheta2);
    const foc_sincos_t sc = foc_sincos_q15(theta_p);

    /* Eq. 15, 17: pull the rotor flux toward radius x e^(j theta_p). */
    const q15_t speed_abs = foc_abs_q15(foc_flux_speed(f));
    const q15_t ra = rotor_flux(f->psi_alpha, li_alpha);
    const q15_t rb = rotor_flux(f->psi_beta, li_beta);
    const q15_t radial = foc_add_q15(foc_mul_q15(ra, sc.cos), foc_mul_q15(rb, sc.sin));
    const q15_t radius = learn_radius(f, radial, speed_abs);
    const int32_t g = correction_gain(f, speed_abs);
    f->psi_alpha = correct(f->psi_alpha, foc_mul_q15(radius, sc.cos), ra, g);
    f->psi_beta = correct(f->psi_beta, foc_mul_q15(radius, sc.sin), rb, g);

    /* Eq. 9-13 solved exactly: the angle of the corrected rotor flux. */
    f->psi_r.alpha = rotor_flux(f->psi_alpha, li_alpha);
    f->psi_r.beta = rotor_flux(f->psi_beta, li_beta);
    const uint16_t theta = foc_atan2_q15(f->psi_r.beta, f->psi_r.alpha);
    f->dtheta2 = f->dtheta1;
    f->dtheta1 = foc_angle_diff(theta, f->theta);
    f->theta = theta;

    foc_speed_obs_step(&f->obs, theta, iq_ref);
}
