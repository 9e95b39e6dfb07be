#include "foc/startup.h"
#include "foc/config.h"

/* The start angle is 0; the first alignment position 90 degrees before it
 * in the direction of rotation. */
#define QUARTER_TURN ((uint32_t)0x40000000u)

void foc_startup_begin(foc_startup_t *s, int8_t direction)
{
    s->direction = (direction < 0) ? (int8_t)-1 : (int8_t)1;
    s->theta32 = (s->direction > 0) ? (uint32_t)(0u - QUARTER_TURN) : QUARTER_TURN;
    s->speed16 = 0;
    s->speed = 0;
    s->current = 0;
    s->ticks = 0;
}

uint8_t foc_startup_align_tick(foc_startup_t *s)
{
    s->ticks++;
    if (s->ticks <= FOC_ALIGN_HALF_TICKS) {
        s->current = foc_slew_q15(s->current, FOC_ALIGN_CURRENT, FOC_ALIGN_CURRENT_STEP);
        return 0;
    }
    /* second half: on to the start angle, turned over its first twelfth
     * rather than in one step (a 90-degree jump of a current vector
     * overshoots the current; Shinano's 12 starts: peak 2.18 A with the
     * jump, 2.05 A turned, for a 2.1 A limit), with the current back to
     * half, ramped up again at four times the first half's rate: a rotor
     * friction held at the first position's dead point swings a quarter
     * turn when the vector turns, with kinetic energy in proportion to the
     * current (campaign seed 109: the Shinano at 0.27 x its inertia and
     * 0.53 x its inductance swung to 970 rpm at the full current, 1.06 x
     * the limit; 0.95 x now).  Half, not less: a heavy rotor still turning
     * when the alignment began (the fan reversed, regress/11) must still
     * be caught on the start angle. */
    s->current = (s->ticks == FOC_ALIGN_HALF_TICKS + 1u)
                     ? FOC_ALIGN_CURRENT / 2
                     : foc_slew_q15(s->current, FOC_ALIGN_CURRENT, FOC_ALIGN_RERAMP_STEP);
    const int32_t pos = (int32_t)s->theta32; /* signed: -90 .. +90 deg */
    if (pos > FOC_ALIGN_TURN_STEP32) {
        /* cppcheck-suppress misra-c2012-10.8 ; D3 modular angle */
        s->theta32 = (uint32_t)(pos - FOC_ALIGN_TURN_STEP32);
    } else if (pos < -FOC_ALIGN_TURN_STEP32) {
        /* cppcheck-suppress misra-c2012-10.8 ; D3 modular angle */
        s->theta32 = (uint32_t)(pos + FOC_ALIGN_TURN_STEP32);
    } else {
        s->theta32 = 0;
    }
    if (s->ticks < 2u * FOC_ALIGN_HALF_TICKS) {
        return 0;
    }
    /* Open loop begins from the first start-up current. */
    s->current = FOC_OL_CURRENT_FIRST;
    s->ticks = 0;
    return 1;
}

void foc_startup_ramp_tick(foc_startup_t *s, q15_t speed_limit)
{
    /* |speed16| <= 2^31 - 2^16, step < 2^31 / 2: no overflow. */
    const int32_t target = (int32_t)((s->direction > 0) ? speed_limit : -speed_limit) * 65536;
    const int32_t diff = target - s->speed16;
    if (diff > FOC_OL_SPEED_STEP16) {
        s->speed16 += FOC_OL_SPEED_STEP16;
    } else if (diff < -FOC_OL_SPEED_STEP16) {
        s->speed16 -= FOC_OL_SPEED_STEP16;
    } else {
        s->speed16 = target;
    }
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    s->speed = (q15_t)(s->speed16 >> 16);
    if (s->ticks < FOC_OL_RAMP_TICKS) {
        s->ticks++;
        s->current = foc_add_q15(s->current, FOC_OL_CURRENT_STEP);
    } else {
        s->current = FOC_OL_CURRENT_FINAL;
    }
}

void foc_startup_fast(foc_startup_t *s)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D3 modular angle */
    s->theta32 += (uint32_t)((int32_t)s->speed * FOC_THETA32_PER_SPEED);
}
