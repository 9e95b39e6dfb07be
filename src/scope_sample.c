/* The scope's per-period part: the sample the fast step's tick takes
 * (foc_scope_tick, scope.h).  Apart from scope.c so that a firmware image
 * can compile the rest (configuration, variable table, read-back: main
 * loop only) for size and this for speed (Makefile: STM32_OS_OBJ). */
#include "foc/scope.h"

/* The trigger variable as a count in its own range (0..65535 unsigned). */
static int32_t trigger_counts(const foc_scope_t *s)
{
    const int16_t raw = *s->trig_src;
    return (s->trig_unsigned != 0u) ? (int32_t)(uint16_t)raw : (int32_t)raw;
}

static uint8_t fired(const foc_scope_t *s, int32_t now)
{
    if (s->edge == (uint8_t)FOC_TRIG_IMMEDIATE) {
        return 1u;
    }
    if (s->stored < 2u) {
        return 0u; /* an edge needs the frame before */
    }
    const uint8_t rising = (uint8_t)(s->prev < s->level && now >= s->level);
    const uint8_t falling = (uint8_t)(s->prev >= s->level && now < s->level);
    switch (s->edge) {
    case FOC_TRIG_RISING: return rising;
    case FOC_TRIG_FALLING: return falling;
    default: return (uint8_t)(rising | falling);
    }
}

void foc_scope_sample(foc_scope_t *s)
{
    if (--s->decim_left != 0u) {
        return;
    }
    s->decim_left = s->decim;
    s->state_shadow = (int16_t)s->ctrl->state;
    int16_t *frame = &s->buf[s->wr];
    const uint8_t n = s->nch;
    for (uint8_t ch = 0; ch < n; ch++) {
        frame[ch] = *s->src[ch];
    }
    const uint16_t next = (uint16_t)(s->wr + n);
    s->wr = (next >= s->end) ? 0u : next;

    if (s->mode == (uint8_t)FOC_SCOPE_TRIGGERED) {
        if (--s->post_left == 0u) {
            s->mode = (uint8_t)FOC_SCOPE_DONE;
        }
        return;
    }
    /* ARMED */
    const int32_t now = trigger_counts(s);
    if (s->stored < UINT16_MAX) {
        s->stored++;
    }
    if (s->stored > s->pre && fired(s, now) != 0u) {
        s->post_left = (uint16_t)(s->frames - s->pre - 1u);
        s->mode = (uint8_t)((s->post_left == 0u) ? FOC_SCOPE_DONE : FOC_SCOPE_TRIGGERED);
    }
    s->prev = now;
}
