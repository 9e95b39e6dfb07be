#include "foc/speed_ctrl.h"
#include "foc/config.h"
#include "foc/sqrt.h"

void foc_sc_init(foc_speed_ctrl_t *sc)
{
    sc->target = 0;
    sc->ramped = 0;
    sc->ramped16 = 0;
    sc->step16 = FOC_SPEED_RAMP_STEP16;
    foc_pi_init(&sc->pi, FOC_SPEED_KP_MANT, FOC_SPEED_KP_SHIFT, FOC_SPEED_KI_MANT, FOC_SPEED_KI_SHIFT,
                FOC_SPEED_KC, (q15_t)-FOC_CURRENT_LIMIT, FOC_CURRENT_LIMIT);
}

void foc_sc_preset(foc_speed_ctrl_t *sc, q15_t speed_meas, q15_t iq_now)
{
    sc->ramped = speed_meas;
    sc->ramped16 = (int32_t)speed_meas * 65536;
    foc_pi_preset(&sc->pi, iq_now);
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
    /* |ramped16| < 2^31 and the step < 2^30: no overflow. */
    const int32_t target16 = (int32_t)sc->target * 65536;
    const int32_t diff = target16 - sc->ramped16;
    sc->ramped16 = (diff > sc->step16)    ? sc->ramped16 + sc->step16
                   : (diff < -sc->step16) ? sc->ramped16 - sc->step16
                                          : target16;
    sc->ramped = (q15_t)(sc->ramped16 >> 16);
    foc_pi_set_limits(&sc->pi, (q15_t)-iq_max, iq_max);
    return foc_pi_step(&sc->pi, foc_sub_q15(sc->ramped, speed_meas));
}
