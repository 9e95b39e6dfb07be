#include "mclv_ui.h"

void mclv_button_init(mclv_button_t *b)
{
    b->stable = 0;
    b->count = 0;
}

uint8_t mclv_button_update(mclv_button_t *b, uint8_t pressed)
{
    const uint8_t now = (uint8_t)(pressed != 0u);
    if (now == b->stable) {
        b->count = 0;
        return 0;
    }
    b->count++;
    if (b->count < MCLV_DEBOUNCE_MS) {
        return 0;
    }
    b->stable = now;
    b->count = 0;
    return now; /* 1 on the press edge, 0 on release */
}

mclv_s2_action_t mclv_s2_action(foc_state_t state)
{
    switch (state) {
    case FOC_STATE_IDLE:
        return MCLV_S2_START;
    case FOC_STATE_CALIB:
    case FOC_STATE_ALIGN:
    case FOC_STATE_OPENLOOP:
    case FOC_STATE_RUN:
        return MCLV_S2_STOP;
    case FOC_STATE_FAULT:
        return MCLV_S2_ACK;
    default:
        return MCLV_S2_NOTHING;
    }
}

int32_t mclv_pot_to_rpm(q15_t pot, int32_t min_rpm, int32_t max_rpm)
{
    if (pot <= 0 || max_rpm <= min_rpm) {
        return min_rpm;
    }
    /* span <= 65535, pot <= 32767: the product < 2^31 */
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    const uint32_t span = (uint32_t)(max_rpm - min_rpm);
    return min_rpm + (int32_t)(((uint32_t)pot * span) >> 15);
}

uint8_t mclv_led_run(foc_state_t state, uint16_t ms)
{
    switch (state) {
    case FOC_STATE_IDLE:
        return 0;
    case FOC_STATE_RUN:
        return 1;
    case FOC_STATE_FAULT:
        return (uint8_t)((ms / 50u) & 1u); /* 10 Hz */
    default:
        return (uint8_t)((ms / 125u) & 1u); /* 4 Hz */
    }
}

q15_t mclv_rpm_to_q15(int32_t rpm, int32_t base_rpm)
{
    if (base_rpm <= 0 || base_rpm > 65535L) {
        return 0;
    }
    const uint8_t neg = (uint8_t)(rpm < 0);
    const uint32_t mag = (neg != 0u) ? (uint32_t)0 - (uint32_t)rpm : (uint32_t)rpm;
    if (mag >= (uint32_t)base_rpm) {
        return (neg != 0u) ? Q15_MIN : Q15_MAX;
    }
    /* mag < base <= 65535: mag x 32768 < 2^31 */
    const uint32_t base = (uint32_t)base_rpm;
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    const int32_t q = (int32_t)((mag * 32768u + base / 2u) / base);
    return foc_sat_q15((neg != 0u) ? -q : q);
}
