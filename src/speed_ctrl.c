#include "foc/speed_ctrl.h"
#include "foc/config.h"
#include "foc/sqrt.h"

static const foc_pi_gains_t speed_gains = FOC_PI_GAINS(
    FOC_SPEED_KP_MANT, FOC_SPEED_KP_SHIFT, FOC_SPEED_KI_MANT, FOC_SPEED_KI_SHIFT, FOC_SPEED_KC);

void foc_sc_init(foc_speed_ctrl_t *sc)
{
    sc->target = 0;
    sc->ramped = 0;
    sc->ramped15 = 0;
    sc->step15 = FOC_SPEED_RAMP_STEP15;
    foc_pi_init(&sc->pi, (q15_t)-FOC_CURRENT_LIMIT, FOC_CURRENT_LIMIT);
}

void foc_sc_preset(foc_speed_ctrl_t *sc, q15_t speed_meas, q15_t iq_now)
{
    sc->ramped = speed_meas;
    sc->ramped15 = (int32_t)speed_meas * 32768;
    foc_pi_preset(&sc->pi, iq_now);
}

void foc_sc_hold(foc_speed_ctrl_t *sc, q15_t speed_meas)
{
    /* only a reference beyond the speed, in the speed's direction */
    const int32_t speed15 = (int32_t)speed_meas * 32768;
    if ((speed_meas >= 0 && sc->ramped15 > speed15) || (speed_meas < 0 && sc->ramped15 < speed15)) {
        sc->ramped15 = speed15;
        sc->ramped = speed_meas;
    }
}

q15_t foc_sc_iq_limit(q15_t id_ref)
{
    const int32_t lim2 = (int32_t)FOC_CURRENT_LIMIT * FOC_CURRENT_LIMIT; /* Q30 */
    const int32_t id2 = (int32_t)id_ref * id_ref;                       /* Q30 */
    if (id2 >= lim2) {
        return 0;
    }
    return (q15_t)foc_isqrt32((uint32_t)(lim2 - id2));
}

q15_t foc_sc_step(foc_speed_ctrl_t *sc, q15_t speed_meas, q15_t id_ref)
{
    const q15_t iq_max = foc_sc_iq_limit(id_ref);
    /* Q15.15: |target|, |ramped| <= 2^30, so the difference (< 2^31) and
     * a step toward the target cannot overflow, even for a reversal from
     * full scale to full scale. */
    const int32_t target15 = (int32_t)sc->target * 32768;
    const int32_t diff = target15 - sc->ramped15;
    sc->ramped15 = (diff > sc->step15)    ? sc->ramped15 + sc->step15
                   : (diff < -sc->step15) ? sc->ramped15 - sc->step15
                                          : target15;
    sc->ramped = (q15_t)(sc->ramped15 >> 15);
    foc_pi_set_limits(&sc->pi, (q15_t)-iq_max, iq_max);
    return foc_pi_step(&sc->pi, &speed_gains, foc_sub_q15(sc->ramped, speed_meas));
}
