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
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    sc->step15 = FOC_SPEED_RAMP_STEP15;
    foc_pi_init(&sc->pi, (q15_t)-FOC_CURRENT_LIMIT, FOC_CURRENT_LIMIT);
    sc->gains = foc_pi_tune_of(&speed_gains);
    sc->gain_shift = 0;
    sc->hunt_side = 0;
    sc->hunt_count = 0;
}

void foc_sc_preset(foc_speed_ctrl_t *sc, q15_t speed_meas, q15_t iq_now)
{
    sc->ramped = speed_meas;
    sc->ramped15 = (int32_t)speed_meas * 32768;
    foc_pi_preset(&sc->pi, iq_now);
    sc->gain_shift = 0;
    sc->hunt_side = 0;
    sc->hunt_count = 0;
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
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    return (q15_t)foc_isqrt32((uint32_t)(lim2 - id2));
}

/* The PI with its gains divided by 2^gain_shift: Kp e (Q15) and Ki e
 * (Q30) shifted rather than e, so the integral still sees an error of one
 * count.  Kc, the ratio of the two, stays. */
static q15_t pi_step(foc_speed_ctrl_t *sc, q15_t e)
{
    const foc_pi_gains_t g = foc_pi_gains_with(&sc->gains, &speed_gains);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t u = (sc->pi.integ >> 15) + (foc_pi_kp_term(&g, e) >> sc->gain_shift);
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    return foc_pi_finish_ki(&sc->pi, &g, foc_pi_ki_term(&g, e) >> sc->gain_shift, u);
}

/* The loop hunting: the q reference from beyond half its limit one way to
 * beyond half the other (a swing), more often than once per
 * FOC_SPEED_HUNT_SWING_TICKS, four times or more (config.h).  Each time the
 * loop's gains are halved: a rotor r times lighter than MOTOR_INERTIA_KGM2
 * wants them r times lower; the campaign's lightest, 0.2 x, is left at
 * 1.25 x the design's crossover after two halvings. */
static void watch_hunting(foc_speed_ctrl_t *sc, q15_t iq, q15_t iq_max)
{
    const int32_t twice = 2 * (int32_t)iq; /* Q15, |2 iq| <= 2^16 */
    const int8_t side = (twice > iq_max) ? (int8_t)1 : (twice < -(int32_t)iq_max) ? (int8_t)-1 : (int8_t)0;
    if (sc->hunt_count != 0u) {
        sc->hunt_count--;
    }
    if (side != 0 && side == -sc->hunt_side) {
        sc->hunt_count = (uint8_t)(sc->hunt_count + FOC_SPEED_HUNT_SWING_TICKS);
        if (sc->hunt_count >= FOC_SPEED_HUNT_TRIP_TICKS) {
            sc->hunt_count = 0;
            if (sc->gain_shift < FOC_SPEED_HUNT_SHIFT_MAX) {
                sc->gain_shift++;
            }
        }
    }
    if (side != 0) {
        sc->hunt_side = side;
    }
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
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    sc->ramped = (q15_t)(sc->ramped15 >> 15);
    foc_pi_set_limits(&sc->pi, (q15_t)-iq_max, iq_max);
    const q15_t iq = pi_step(sc, foc_sub_q15(sc->ramped, speed_meas));
    watch_hunting(sc, iq, iq_max);
    return iq;
}
