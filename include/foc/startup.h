/*
 * Sensorless start-up: the forced (open-loop) angle, alignment and the
 * open-loop ramp (seeds 000 and 002).
 *
 * The forced current is applied along the d axis of the forced frame, like
 * a stepper: the rotor's magnet lines up with it and follows it as it turns,
 * lagging by the load angle (torque = Kt I sin(lag)).
 *
 * ALIGN, first half: the current rises from 0 at 90 degrees before the start
 * angle; second half: at the start angle, from half the current back to
 * the whole at four times the first half's rate, then held.  OPENLOOP: the forced
 * speed rises by a fixed step per slow tick (no division anywhere, so no
 * division by zero at ramp start) to the final start-up speed in the
 * commanded direction, the current moves from the first to the final
 * value.  Every start resets every variable here.
 *
 * Units: angle uint32 (2^32 = 360 deg), speed Q15 of SPEED_BASE_RPM,
 * current Q15 of the current base.
 */
#ifndef FOC_STARTUP_H
#define FOC_STARTUP_H

#include <stdint.h>
#include "foc/q15.h"

typedef struct {
    uint32_t theta32;  /* forced angle */
    int32_t speed16;   /* forced speed, Q15.16 (x 65536): the ramp's */
                       /* exact accumulator */
    q15_t speed;       /* forced speed, signed (speed16 >> 16) */
    q15_t current;     /* forced d current, >= 0 */
    int8_t direction;  /* +1 or -1 */
    uint16_t ticks;    /* slow ticks since the start of the phase */
} foc_startup_t;

/* Starts the alignment for a run in `direction` (+1 / -1). */
void foc_startup_begin(foc_startup_t *s, int8_t direction);

/* One slow tick of alignment; returns 1 when the alignment is complete. */
uint8_t foc_startup_align_tick(foc_startup_t *s);

/* One slow tick of the open-loop ramp toward `speed_limit` (a magnitude:
 * the final start-up speed, or less/more in OPEN_LOOP_FUNCTIONING). */
void foc_startup_ramp_tick(foc_startup_t *s, q15_t speed_limit);

/* One PWM period: advances the forced angle at the forced speed. */
void foc_startup_fast(foc_startup_t *s);

static inline uint16_t foc_startup_angle(const foc_startup_t *s)
{
    return (uint16_t)(s->theta32 >> 16);
}

#endif /* FOC_STARTUP_H */
