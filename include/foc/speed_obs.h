/*
 * Closed-loop speed observer on the mechanical model (docs/references.md [WLG]
 * section 2.2 and figure 1):
 *
 *   J dw/dt = Te - B w - Tl,   Te = 1.5 p flux iq    (eq. 14, B neglected)
 *
 * The observer simulates the model with the torque command as feed-forward
 * and corrects it with the error between a measured angle (the flux
 * estimator's) and its own angle, so the speed never comes from
 * differentiating the angle.  Per PWM period, with e = theta_meas - theta^:
 *
 *   theta^ += l1 e                      then   theta^ += w^ Ts
 *   w^     += l2 e                             w^ += (p / J) Kt (iq_ref - iq_load^) Ts
 *   iq_load^ -= l3 e
 *
 * (electrical speed; the load torque is held as the q current that would
 * balance it).  Error dynamics s^3 + l1 s^2 + l2 s + l3 with l1 = 3 wo,
 * l2 = 3 wo^2, l3 = wo^3: three poles at -wo (FLUX_SPEED_OBS_BW_RAD_S).
 * With the feed-forward the estimate follows accelerations without lag;
 * the third state takes up load torque, friction and inertia error.
 *
 * Units: angle uint32 (2^32 = 360 deg), speed int32 Q31 of SPEED_BASE_RPM
 * (Q15 output = speed >> 16), load int32 Q27 of the current base (l3 is
 * large: 4 fewer fraction bits keep it a 16-bit mantissa), held within
 * +-1.0.  Gains: l1 Q15; l2, l3 and the feed-forward as mantissa/shift
 * (FOC_NORM_*), so each product is a 16 x 16-bit multiply.
 */
#ifndef FOC_SPEED_OBS_H
#define FOC_SPEED_OBS_H

#include <stdint.h>
#include "foc/q15.h"

typedef struct {
    uint32_t theta32; /* observer angle, predicted for the next sample */
    q31_t speed;      /* electrical speed, Q31 of SPEED_BASE_RPM */
    int32_t load;     /* load torque as q current, Q27 of the current base */
    q15_t speed_out;  /* speed at the last sample, Q15 (output) */
} foc_speed_obs_t;

/* Starts at angle `theta` and speed `speed` (Q15), in balance: the load
 * equals the q current `iq_now` (Q15) flowing now. */
void foc_speed_obs_reset(foc_speed_obs_t *o, uint16_t theta, q15_t speed, q15_t iq_now);

/* One PWM period: `theta_meas` is the angle measured at this sample,
 * `iq_ref` the q-current command (Q15) applied from now on. */
void foc_speed_obs_step(foc_speed_obs_t *o, uint16_t theta_meas, q15_t iq_ref);

static inline q15_t foc_speed_obs_speed(const foc_speed_obs_t *o)
{
    return o->speed_out;
}

#endif /* FOC_SPEED_OBS_H */
