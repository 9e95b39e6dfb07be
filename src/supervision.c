#include "foc/supervision.h"
#include "foc/config.h"
#include "foc/faults.h"

void foc_sup_init(foc_supervision_t *s)
{
    s->heat = 0;
    foc_sup_run_reset(s);
}

/* No window of the follow check under way, none before it. */
static void follow_restart(foc_supervision_t *s)
{
    s->follow_ticks = 0;
    s->follow_sum = 0;
    s->follow_last = FOC_SUP_FOLLOW_NONE;
}

void foc_sup_run_reset(foc_supervision_t *s)
{
    follow_restart(s);
    s->overspeed_ticks = 0;
}

uint16_t foc_sup_thermal(foc_supervision_t *s, foc_dq_t i_dq)
{
    /* id^2 + iq^2 (Q30, <= 2^31) as Q15 of I_base^2, at most 1.0 (the ADC
     * measures no more), then (I / I_rated)^2 in Q20 (<= 2^29). */
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    const uint32_t sq = (uint32_t)((int32_t)i_dq.d * i_dq.d) + (uint32_t)((int32_t)i_dq.q * i_dq.q);
    const q15_t x15 = (sq >= (uint32_t)32767 << 15) ? Q15_MAX : (q15_t)(sq >> 15);
    const int32_t target = foc_mul_norm32(x15, FOC_I2T_MANT, FOC_I2T_RSHIFT);
    /* heat += (target - heat) Ts / tau: |difference| < 2^30 times a Q30
     * constant needs 64 bits (once per slow tick). */
    /* cppcheck-suppress [misra-c2012-10.1, misra-c2012-10.8] ; D1 Q-format shift, D2 compile-time constant */
    s->heat += (int32_t)(((int64_t)(target - s->heat) * FOC_I2T_K_Q30) >> 30);
    return (s->heat >= FOC_I2T_TRIP) ? (uint16_t)FOC_FAULT_MOTOR_OVERLOAD : 0u;
}

uint8_t foc_sup_cooled(const foc_supervision_t *s)
{
    return (uint8_t)(s->heat < FOC_I2T_CLEAR);
}

uint16_t foc_sup_overspeed(foc_supervision_t *s, q15_t speed)
{
    if (foc_abs_q15(speed) > FOC_OVERSPEED) {
        if (s->overspeed_ticks < UINT8_MAX) {
            s->overspeed_ticks++;
        }
    } else {
        s->overspeed_ticks = 0;
    }
    return (s->overspeed_ticks >= FOC_OVERSPEED_TICKS) ? (uint16_t)FOC_FAULT_OVERSPEED : 0u;
}

uint16_t foc_sup_follow(foc_supervision_t *s, q15_t command, q15_t speed, q15_t iq_ref)
{
    const q15_t cmd = foc_abs_q15(command);
    /* at the limit, pushing toward the command: within 1/8 of the whole
     * current limit, not of what field weakening leaves (a rotor held by
     * the voltage settles at the speed it can reach); in a reversal's
     * ramp down the loop may still push the old way */
    const uint8_t limited =
        (uint8_t)((int32_t)foc_abs_q15(iq_ref) * 8 >= (int32_t)FOC_CURRENT_LIMIT * 7 &&
                  (iq_ref < 0) == (command < 0));
    /* behind: below 7/8 of the command, or turning the other way */
    const uint8_t behind =
        (uint8_t)(cmd != 0 && ((int32_t)foc_abs_q15(speed) * 8 < (int32_t)cmd * 7 ||
                               (speed < 0) != (command < 0)));
    if (limited == 0u || behind == 0u) {
        follow_restart(s);
        return 0u;
    }
    /* |speed| <= 2^15; a window of at most 2^14 ticks (config.h) */
    s->follow_sum += speed;
    s->follow_ticks++;
    const uint8_t fast = (uint8_t)(cmd >= FOC_FOLLOW_SPEED_SPLIT);
    const uint16_t window = fast ? FOC_FOLLOW_FAST_TICKS : FOC_FOLLOW_SLOW_TICKS;
    if (s->follow_ticks < window) {
        return 0u;
    }
    /* a window over: its mean speed against the last window's */
    const int32_t mean = s->follow_sum / (int32_t)window;
    const int32_t last = s->follow_last;
    s->follow_ticks = 0;
    s->follow_sum = 0;
    s->follow_last = mean;
    const int32_t progress = fast ? (int32_t)FOC_FOLLOW_TRIP_FAST : (int32_t)FOC_FOLLOW_TRIP_SLOW;
    /* gaining: the speed moved toward the command's direction (a heavy
     * load accelerating), however far the command is and wherever it
     * moved meanwhile */
    if (last == FOC_SUP_FOLLOW_NONE ||
        ((command < 0) ? last - mean : mean - last) >= progress) {
        return 0u;
    }
    return (uint16_t)FOC_FAULT_SPEED_FEEDBACK;
}
