#include "foc/sensored.h"
#include "foc/config.h"

void foc_sensored_reset(foc_sensored_t *s, uint16_t theta_sensor)
{
    s->theta = theta_sensor;
    foc_lpf_init(&s->speed, 0);
}

void foc_sensored_step(foc_sensored_t *s, uint16_t theta_sensor)
{
    /* Modular difference: the change per period is below 90 degrees
     * (checked in config.h), so the int16 reading is unambiguous. */
    const uint16_t diff = (uint16_t)(theta_sensor - s->theta);
    const q15_t d_theta = (q15_t)(diff >= 32768u ? (int32_t)diff - (int32_t)65536 : (int32_t)diff);
    const q15_t speed = foc_mul_q15_shift(d_theta, FOC_DTHETA_TO_SPEED_MANT,
                                          FOC_DTHETA_TO_SPEED_SHIFT);
    s->theta = theta_sensor;
    (void)foc_lpf_step(&s->speed, speed, FOC_SPEED_FILTER_K);
}
