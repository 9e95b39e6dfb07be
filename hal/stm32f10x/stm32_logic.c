#include "stm32_logic.h"

#define PHASE_BIT(i) ((uint8_t)(1u << (i)))
#define ALL_PHASES (FOC_PHASE_A | FOC_PHASE_B | FOC_PHASE_C)
#define JDR_MID 16384 /* mid-scale of a left-aligned injected result */
/* Functions on the interrupt's path to its deadline (the PWM plan) are
 * inlined into it whether or not the compiler would. */
#if defined(__GNUC__)
#define LOGIC_INLINE __attribute__((always_inline)) static inline
#else
#define LOGIC_INLINE static inline
#endif

uint16_t stm32_duty_to_ccr(q15_t duty, uint16_t period)
{
    const uint32_t d = (duty < 0) ? 0u : (uint32_t)duty;
    /* d <= 32767 and period <= 65535: the product fits 32 bits. */
    return (uint16_t)((d * period + 16384u) >> 15);
}

uint8_t stm32_unread_phase(uint8_t sector)
{
    switch (sector) {
    case 1:
    case 6:
        return 0u; /* A highest: read B, C */
    case 2:
    case 3:
        return 1u; /* B highest: read A, C */
    default:
        return 2u; /* 4, 5 (C highest) and invalid: read A, B */
    }
}

uint32_t stm32_jsqr(const uint8_t *ch, uint8_t n)
{
    /* n conversions use JSQ(5-n)..JSQ4 (RM0008, ADC_JSQR), 5 bits each. */
    uint32_t v = ((uint32_t)n - 1u) << 20;
    for (uint8_t i = 0; i < n; i++) {
        const uint32_t slot = (uint32_t)4u - n + i;
        v |= ((uint32_t)ch[i] & 0x1Fu) << (5u * slot);
    }
    return v;
}

/* Is a sample window starting at s clean: both read phases conducting and
 * settled throughout (cm = the higher of their compare values), and no
 * edge of the unread phase (compare value cx) within tw_after before it
 * or during it?  Timeline positions, see the header. */
static int window_clean(int32_t s, int32_t p, int32_t cx, int32_t cm,
                        int32_t ta, int32_t tb)
{
    const int32_t x_on = cx;          /* unread phase: low side turns on */
    const int32_t x_off = 2 * p - cx; /* and off */
    if (s < cm + ta || s + tb > 2 * p - cm) {
        return 0;
    }
    if (s > x_on - tb && s < x_on + ta) {
        return 0;
    }
    if (s > x_off - tb && s < x_off + ta) {
        return 0;
    }
    return 1;
}

/* Start s of the sample window on the timeline; returns 1 if clean. */
LOGIC_INLINE uint8_t sample_window(int32_t p, int32_t cx, int32_t cm, int32_t ta,
                             int32_t tb, int32_t *s)
{
    const int32_t candidates[3] = {
        p - tb / 2,  /* 1. centred on the top */
        cx + ta,     /* 2. inside the unread phase's low-side window */
        cx - tb,     /* 3. before the unread phase's first edge */
    };
    for (unsigned i = 0; i < 3u; i++) {
        if (window_clean(candidates[i], p, cx, cm, ta, tb) != 0) {
            *s = candidates[i];
            return 1u;
        }
    }
    /* 4. nothing clean: after the unread phase's first edge has settled,
     * but early enough for the read phases to be still conducting. */
    const int32_t latest = 2 * p - cm - tb;
    *s = (cx + ta < latest) ? cx + ta : latest;
    return 0u;
}

/* Timeline position to the CC4 compare value and counting direction.  A
 * trigger on the way up needs CNT to reach ccr4 < P (PWM mode 2 then
 * pulses for at least two counts); the top itself is taken one count
 * later, on the way down.  Returns the position the trigger really has. */
static int32_t set_trigger(stm32_plan_t *pl, int32_t s, uint16_t period)
{
    const int32_t p = (int32_t)period;
    int32_t ccr;
    pl->ccr4_down = (uint8_t)(s >= p);
    ccr = pl->ccr4_down ? 2 * p - s : s;
    if (ccr < 1) {
        ccr = 1;
    }
    if (ccr > p - 1) {
        ccr = p - 1;
    }
    pl->ccr4 = (uint16_t)ccr;
    return pl->ccr4_down ? 2 * p - ccr : ccr;
}

/* What both PWM plans share: compare values, phases read, sample window
 * (start *s, returns 1 if clean); the unread phase in *x, cm in *cm. */
LOGIC_INLINE uint8_t plan_pwm_common(stm32_plan_t *p, const foc_duty_t *d,
                               const stm32_timing_t *t, uint8_t aux_is_pot,
                               int32_t *s, uint8_t *x, int32_t *cm)
{
    p->ccr[0] = stm32_duty_to_ccr(d->a, t->period);
    p->ccr[1] = stm32_duty_to_ccr(d->b, t->period);
    p->ccr[2] = stm32_duty_to_ccr(d->c, t->period);

    *x = stm32_unread_phase(d->sector);
    const uint8_t r1 = (*x == 0u) ? 1u : 0u;
    const uint8_t r2 = (*x == 2u) ? 1u : 2u;
    *cm = (p->ccr[r1] > p->ccr[r2]) ? p->ccr[r1] : p->ccr[r2];

    const uint8_t clean = sample_window(t->period, p->ccr[*x], *cm, t->tw_after,
                                        t->tw_before, s);
    p->trigger_cc4 = 1u;
    p->all_phases = 0u;
    p->adc1_phase = r1;
    p->adc2_phase = r2;
    p->aux_is_pot = aux_is_pot ? 1u : 0u;
    p->phases = (uint8_t)(PHASE_BIT(r1) | PHASE_BIT(r2));
    return clean;
}

void stm32_plan_pwm(stm32_plan_t *p, const foc_duty_t *d, const stm32_timing_t *t,
                    const stm32_adc_map_t *m, uint8_t aux_is_pot)
{
    int32_t s;
    uint8_t x;
    int32_t cm;
    const uint8_t clean = plan_pwm_common(p, d, t, aux_is_pot, &s, &x, &cm);
    s = set_trigger(p, s, t->period);
    p->window_start = (uint16_t)s;
    p->clean = (uint8_t)(clean && window_clean(s, t->period, p->ccr[x], cm,
                                               t->tw_after, t->tw_before));

    const uint8_t ch1[2] = { m->phase[p->adc1_phase], m->vbus };
    const uint8_t ch2[2] = { m->phase[p->adc2_phase], p->aux_is_pot ? m->pot : m->temp };
    p->jsqr1 = stm32_jsqr(ch1, 2u);
    p->jsqr2 = stm32_jsqr(ch2, 2u);
}

/* JSQR of a four-conversion sequence a, b, c, d (JL = 3: JSQ1..JSQ4). */
static uint32_t jsqr4(uint32_t a, uint32_t b, uint32_t c, uint32_t d)
{
    return ((uint32_t)3u << 20) | a | (b << 5) | (c << 10) | (d << 15);
}

/* Trigger on the way up, lead counts before the window start s; not earlier
 * than half a period less the lead, so that the end of the sequence still
 * comes after the middle of the way up (the interrupt's check for a
 * trigger that was not planned).  Returns the window start it gives. */
static int32_t set_trigger_lead(stm32_plan_t *p, int32_t s, int32_t per, int32_t lead)
{
    int32_t lo = per / 2 - lead;
    int32_t trig = s - lead;
    if (lo < 1) {
        lo = 1;
    }
    if (trig < lo) {
        trig = lo;
    }
    if (trig > per - 1) {
        trig = per - 1;
    }
    p->ccr4 = (uint16_t)trig;
    p->ccr4_down = 0u;
    return trig + lead;
}

void stm32_plan_pwm_four(stm32_plan_t *p, const foc_duty_t *d, const stm32_timing_t *t,
                         const stm32_seq4_t *q, uint8_t aux_is_pot, uint16_t lead)
{
    int32_t s;
    uint8_t x;
    int32_t cm;
    uint8_t clean = plan_pwm_common(p, d, t, aux_is_pot, &s, &x, &cm);
    const int32_t s2 = set_trigger_lead(p, s, (int32_t)t->period, (int32_t)lead);
    if (s2 != s) {
        clean = (uint8_t)(clean && window_clean(s2, t->period, p->ccr[x], cm,
                                                t->tw_after, t->tw_before));
    }
    p->window_start = (uint16_t)s2;
    p->clean = clean;
    p->jsqr1 = q->adc1[p->adc1_phase];
    p->jsqr2 = q->adc2[p->aux_is_pot][p->adc2_phase];
}

void stm32_plan_pwm_top(stm32_plan_t *p, const uint16_t ccr_up[3], const foc_duty_t *d,
                        const stm32_timing_t *t, const stm32_seq4_t *q, uint8_t aux_is_pot,
                        uint16_t window_start, uint16_t ccr4)
{
    const int32_t s = (int32_t)window_start;
    const int32_t end = s + (int32_t)t->tw_before;
    const int32_t two_p = 2 * (int32_t)t->period;
    uint8_t valid = 0u;
    p->ccr[0] = stm32_duty_to_ccr(d->a, t->period);
    p->ccr[1] = stm32_duty_to_ccr(d->b, t->period);
    p->ccr[2] = stm32_duty_to_ccr(d->c, t->period);
    for (uint8_t i = 0; i < 3u; i++) {
        if ((int32_t)ccr_up[i] + (int32_t)t->tw_after <= s && end <= two_p - (int32_t)p->ccr[i]) {
            valid = (uint8_t)(valid | PHASE_BIT(i));
        }
    }
    const uint8_t x = stm32_unread_phase(d->sector);
    uint8_t r1 = (x == 0u) ? 1u : 0u;
    uint8_t r2 = (x == 2u) ? 1u : 2u;
    if ((valid & PHASE_BIT(x)) != 0u) {
        if ((valid & PHASE_BIT(r1)) == 0u) {
            r1 = x;
        } else if ((valid & PHASE_BIT(r2)) == 0u) {
            r2 = x;
        } else {
            /* both read phases valid: the plan stays */
        }
    }
    p->phases = (uint8_t)((PHASE_BIT(r1) | PHASE_BIT(r2)) & valid);
    p->clean = (uint8_t)(p->phases == (PHASE_BIT(r1) | PHASE_BIT(r2)));
    p->ccr4 = ccr4;
    p->ccr4_down = 0u;
    p->trigger_cc4 = 1u;
    p->all_phases = 0u;
    p->adc1_phase = r1;
    p->adc2_phase = r2;
    p->aux_is_pot = aux_is_pot ? 1u : 0u;
    p->window_start = window_start;
    p->jsqr1 = q->adc1[r1];
    p->jsqr2 = q->adc2[p->aux_is_pot][r2];
}

void stm32_seq4_init(stm32_seq4_t *q, const stm32_adc_map_t *m)
{
    const uint32_t v = m->vbus;
    for (unsigned i = 0; i < 3u; i++) {
        q->adc1[i] = jsqr4(v, v, m->phase[i], v);
        q->adc2[0][i] = jsqr4(m->temp, m->temp, m->phase[i], m->temp);
        q->adc2[1][i] = jsqr4(m->pot, m->pot, m->phase[i], m->pot);
    }
}

void stm32_plan_all_phases(stm32_plan_t *p, const stm32_timing_t *t,
                           const stm32_adc_map_t *m, uint8_t trigger_cc4)
{
    const uint16_t half = (uint16_t)(t->period / 2u);
    p->ccr[0] = half;
    p->ccr[1] = half;
    p->ccr[2] = half;
    p->clean = 1u;
    p->window_start = (uint16_t)set_trigger(p, t->period - t->tw_before / 2u, t->period);
    p->trigger_cc4 = trigger_cc4 ? 1u : 0u;
    p->all_phases = 1u;
    p->adc1_phase = 0u;
    p->adc2_phase = 1u;
    p->aux_is_pot = 0u;
    p->phases = ALL_PHASES;

    const uint8_t ch1[3] = { m->phase[0], m->vbus, m->phase[2] };
    const uint8_t ch2[3] = { m->phase[1], m->temp, m->pot };
    p->jsqr1 = stm32_jsqr(ch1, 3u);
    p->jsqr2 = stm32_jsqr(ch2, 3u);
}

void stm32_plan_all_phases_four(stm32_plan_t *p, const stm32_timing_t *t,
                                const stm32_adc_map_t *m, uint8_t trigger_cc4,
                                uint16_t lead)
{
    stm32_plan_all_phases(p, t, m, trigger_cc4);
    p->window_start = (uint16_t)set_trigger_lead(p, (int32_t)t->period - (int32_t)t->tw_before / 2,
                                                 (int32_t)t->period, (int32_t)lead);
    p->jsqr1 = jsqr4(m->vbus, m->phase[2], m->phase[0], m->vbus);
    p->jsqr2 = jsqr4(m->pot, m->pot, m->phase[1], m->temp);
}

q15_t stm32_current_from_jdr(uint32_t jdr, uint8_t inverted)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    int32_t v = (int32_t)(jdr & 0x7FFFu) - JDR_MID;
    if (inverted != 0u) {
        v = -v;
    }
    return foc_sat_q15(v * 2);
}

q15_t stm32_unipolar_from_jdr(uint32_t jdr)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    return (q15_t)(jdr & 0x7FFFu);
}

void stm32_samples_from_jdr(const stm32_plan_t *p, const stm32_adc_map_t *m,
                            const uint32_t jdr1[3], const uint32_t jdr2[3],
                            stm32_aux_t *held, foc_samples_t *s)
{
    q15_t i[3] = { 0, 0, 0 };
    s->vdc = stm32_unipolar_from_jdr(jdr1[1]);
    if (p->all_phases != 0u) {
        i[0] = stm32_current_from_jdr(jdr1[0], m->current_inverted);
        i[1] = stm32_current_from_jdr(jdr2[0], m->current_inverted);
        i[2] = stm32_current_from_jdr(jdr1[2], m->current_inverted);
        held->temp = stm32_unipolar_from_jdr(jdr2[1]);
        held->pot = stm32_unipolar_from_jdr(jdr2[2]);
    } else {
        i[p->adc1_phase] = stm32_current_from_jdr(jdr1[0], m->current_inverted);
        i[p->adc2_phase] = stm32_current_from_jdr(jdr2[0], m->current_inverted);
        if (p->aux_is_pot != 0u) {
            held->pot = stm32_unipolar_from_jdr(jdr2[1]);
        } else {
            held->temp = stm32_unipolar_from_jdr(jdr2[1]);
        }
    }
    s->i_a = i[0];
    s->i_b = i[1];
    s->i_c = i[2];
    s->phases = p->phases;
    s->temp = held->temp;
    s->pot = held->pot;
    s->theta_sensor = 0;
}

void stm32_load_plan(TIM_TypeDef *tim, ADC_TypeDef *adc1, ADC_TypeDef *adc2,
                     const stm32_plan_t *p, uint8_t hold_trigger)
{
    const uint32_t cr2 = adc1->CR2;
    const uint32_t quiet =
        (cr2 & ~(ADC_CR2_JEXTSEL | ADC_CR2_JEXTTRIG)) |
        (p->trigger_cc4 ? STM32_JEXTSEL_TIM1_CC4 : STM32_JEXTSEL_TIM1_TRGO);
    if (cr2 != quiet) {
        adc1->CR2 = quiet;
    }
    tim->CCR1 = p->ccr[0];
    tim->CCR2 = p->ccr[1];
    tim->CCR3 = p->ccr[2];
    tim->CCR4 = p->ccr4;
    if (p->ccr4_down != 0u) {
        tim->CCER = (uint16_t)(tim->CCER | TIM_CCER_CC4P);
    } else {
        tim->CCER = (uint16_t)(tim->CCER & (uint16_t)~TIM_CCER_CC4P);
    }
    adc1->JSQR = p->jsqr1;
    adc2->JSQR = p->jsqr2;
    if (!hold_trigger) {
        adc1->CR2 = quiet | ADC_CR2_JEXTTRIG;
    }
}

void stm32_release_trigger(ADC_TypeDef *adc1)
{
    const uint32_t cr2 = adc1->CR2;
    if ((cr2 & ADC_CR2_JEXTTRIG) == 0u) {
        adc1->CR2 = cr2 | ADC_CR2_JEXTTRIG;
    }
}

uint8_t stm32_deadtime_dtg(uint32_t counts)
{
    /* RM0008 TIMx_BDTR.DTG: four ranges of growing step. */
    if (counts <= 127u) {
        return (uint8_t)counts;
    }
    if (counts <= 254u) {
        return (uint8_t)(0x80u | ((counts + 1u) / 2u - 64u));
    }
    if (counts <= 504u) {
        return (uint8_t)(0xC0u | ((counts + 7u) / 8u - 32u));
    }
    if (counts <= 1008u) {
        return (uint8_t)(0xE0u | ((counts + 15u) / 16u - 32u));
    }
    return 0xFFu;
}

uint32_t stm32_deadtime_counts(uint8_t dtg)
{
    if ((dtg & 0x80u) == 0u) {
        return dtg;
    }
    if ((dtg & 0xC0u) == 0x80u) {
        return 2u * (64u + (dtg & 0x3Fu));
    }
    if ((dtg & 0xE0u) == 0xC0u) {
        return 8u * (32u + (dtg & 0x1Fu));
    }
    return 16u * (32u + (dtg & 0x1Fu));
}

uint16_t stm32_debug_ccr(q15_t v, uint16_t arr)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    const uint32_t u = (uint32_t)((int32_t)v + 32768); /* 0..65535 */
    return (uint16_t)((u * ((uint32_t)arr + 1u)) >> 16);
}
