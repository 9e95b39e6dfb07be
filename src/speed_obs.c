#include "foc/speed_obs.h"
#include "foc/config.h"
#include "foc/trig.h"

/* Load estimate limit: the current base, Q27. */
#define LOAD_MAX ((int32_t)0x08000000) /* 2^27 */

/* Q27 load -> Q15, rounded (|load| <= 2^27). */
static q15_t load_q15(int32_t load)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return foc_sat_q15(((load >> 11) + 1) >> 1);
}

void foc_speed_obs_reset(foc_speed_obs_t *o, uint16_t theta, q15_t speed, q15_t iq_now)
{
    /* The angle is held predicted one period ahead. */
    /* cppcheck-suppress misra-c2012-10.8 ; D3 modular angle */
    o->theta32 = ((uint32_t)theta << 16) + (uint32_t)((int32_t)speed * FOC_THETA32_PER_SPEED);
    o->speed = (q31_t)speed * (q31_t)65536;
    o->load = (int32_t)iq_now * (int32_t)4096; /* Q15 -> Q27 */
    o->speed_out = speed;
}

void foc_speed_obs_step(foc_speed_obs_t *o, uint16_t theta_meas, q15_t iq_ref)
{
    /* Correction from the angle error, counts (|err| <= 2^15). */
    const q15_t err = foc_angle_diff(theta_meas, (uint16_t)(o->theta32 >> 16));
    /* l1 err in 2^-16 counts: |err x L1 x 2| < 2^31 (L1 < 0.5, checked). */
    /* cppcheck-suppress misra-c2012-10.8 ; D3 modular angle */
    o->theta32 += (uint32_t)((int32_t)err * (int32_t)FOC_SOBS_L1 * 2);
    o->speed = foc_add_q31(o->speed, foc_mul_norm32(err, FOC_SOBS_L2_MANT, FOC_SOBS_L2_RSHIFT));
    /* |load| <= 2^27 and |l3 err| < 2^30: the sum fits int32_t. */
    o->load -= foc_mul_norm32(err, FOC_SOBS_L3_MANT, FOC_SOBS_L3_RSHIFT);
    if (o->load > LOAD_MAX) {
        o->load = LOAD_MAX;
    } else if (o->load < -LOAD_MAX) {
        o->load = -LOAD_MAX;
    } else {
        /* within the limits */
    }
    o->speed_out = foc_q31_to_q15(o->speed);

    /* Prediction to the next sample: torque command minus load, through
     * p / J (feed-forward); the angle advances at the corrected speed. */
    const q15_t i_accel = foc_sub_q15(iq_ref, load_q15(o->load));
    o->speed = foc_add_q31(o->speed, foc_mul_norm32(i_accel, FOC_SOBS_FF_MANT, FOC_SOBS_FF_RSHIFT));
    /* |speed_out x THETA32_PER_SPEED| < 2^30 (90 deg per period checked);
     * the conversion to uint32_t wraps. */
    /* cppcheck-suppress misra-c2012-10.8 ; D3 modular angle */
    o->theta32 += (uint32_t)((int32_t)o->speed_out * FOC_THETA32_PER_SPEED);
}
