/*
 * The STM32 port's four-conversion ADC sequences (stm32_plan_pwm_four,
 * stm32_plan_all_phases_four): the samples the port reads must not depend
 * on how RM0008's JSQR/JDRx text is read (tools/pil --jdr-order):
 *   sequence: JDRk holds the k-th conversion of the sequence;
 *   slot:     JDRx holds the conversion of slot JSQx.
 * Both readings are written out here from the JSQR value alone, the JDRs
 * filled with a code per channel, and the port's reading (JDR3, JDR4,
 * JDR2 into stm32_samples_from_jdr) compared with the two-conversion
 * plan's meaning.  Also: the trigger on the way up, `lead` counts before
 * the window; no channel converted by both ADCs in one slot.
 */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "stm32_logic.h"
#include "testkit.h"

static const stm32_timing_t kit = { 2250, 241, 63 };
static const stm32_adc_map_t wiring = { { 11, 12, 13 }, 3, 10, 14, 1 };
#define LEAD 240u

/* a distinct left-aligned code for each channel */
static uint32_t code_of(unsigned ch)
{
    return (uint32_t)(1000u + 37u * ch) << 3;
}

/* JDR1..4 after a sequence, under a reading (0 sequence, 1 slot) */
static void fill(uint32_t jsqr, int slot_reading, uint32_t jdr[4])
{
    const unsigned jl = (jsqr >> 20) & 3u;
    for (unsigned i = 0; i < 4u; i++) {
        jdr[i] = 0xDEAD; /* stale */
    }
    unsigned k = 0;
    for (unsigned s = 4u - jl; s <= 4u; s++, k++) {
        const unsigned ch = (jsqr >> (5u * (s - 1u))) & 0x1Fu;
        jdr[slot_reading ? s - 1u : k] = code_of(ch);
    }
}

static void samples(const stm32_plan_t *p, int reading, foc_samples_t *s)
{
    uint32_t a[4], b[4];
    fill(p->jsqr1, reading, a);
    fill(p->jsqr2, reading, b);
    const uint32_t j1[3] = { a[2], a[3], a[1] };
    const uint32_t j2[3] = { b[2], b[3], b[1] };
    stm32_aux_t held = { 0, 0 };
    stm32_samples_from_jdr(p, &wiring, j1, j2, &held, s);
}

/* what a plan means: the samples from its channels, read directly */
static void expect(const stm32_plan_t *p, uint8_t aux_pot, foc_samples_t *s)
{
    q15_t i[3] = { 0, 0, 0 };
    memset(s, 0, sizeof *s);
    s->vdc = stm32_unipolar_from_jdr(code_of(wiring.vbus));
    if (p->all_phases) {
        for (unsigned k = 0; k < 3u; k++) {
            i[k] = stm32_current_from_jdr(code_of(wiring.phase[k]), 1);
        }
        s->temp = stm32_unipolar_from_jdr(code_of(wiring.temp));
        s->pot = stm32_unipolar_from_jdr(code_of(wiring.pot));
    } else {
        i[p->adc1_phase] = stm32_current_from_jdr(code_of(wiring.phase[p->adc1_phase]), 1);
        i[p->adc2_phase] = stm32_current_from_jdr(code_of(wiring.phase[p->adc2_phase]), 1);
        if (aux_pot) {
            s->pot = stm32_unipolar_from_jdr(code_of(wiring.pot));
        } else {
            s->temp = stm32_unipolar_from_jdr(code_of(wiring.temp));
        }
    }
    s->i_a = i[0];
    s->i_b = i[1];
    s->i_c = i[2];
}

static void check_plan(const stm32_plan_t *p, uint8_t aux_pot, const char *what)
{
    foc_samples_t e, s0, s1;
    expect(p, aux_pot, &e);
    samples(p, 0, &s0);
    samples(p, 1, &s1);
    TK_CHECK(((p->jsqr1 >> 20) & 3u) == 3u && ((p->jsqr2 >> 20) & 3u) == 3u,
             "%s: four conversions", what);
    TK_CHECK(s0.i_a == e.i_a && s0.i_b == e.i_b && s0.i_c == e.i_c && s0.vdc == e.vdc,
             "%s: reading 'sequence': %d %d %d %d", what, s0.i_a, s0.i_b, s0.i_c, s0.vdc);
    TK_CHECK(s1.i_a == e.i_a && s1.i_b == e.i_b && s1.i_c == e.i_c && s1.vdc == e.vdc,
             "%s: reading 'slot': %d %d %d %d", what, s1.i_a, s1.i_b, s1.i_c, s1.vdc);
    TK_CHECK((aux_pot ? s1.pot == e.pot : s1.temp == e.temp) &&
                 (aux_pot ? s0.pot == e.pot : s0.temp == e.temp),
             "%s: aux", what);
    /* currents third on both ADCs, nothing converted twice in one slot */
    for (unsigned slot = 0; slot < 4u; slot++) {
        const unsigned c1 = (p->jsqr1 >> (5u * slot)) & 0x1Fu;
        const unsigned c2 = (p->jsqr2 >> (5u * slot)) & 0x1Fu;
        TK_CHECK(c1 != c2, "%s: slot %u converts channel %u on both ADCs", what, slot + 1u, c1);
    }
}

/* The duties of centred SVM for phase values a, b, c (Q15, 0..32767): the
 * zero sequence moves the middle of the span to 1/2; the sector by the
 * largest duty. */
static foc_duty_t centred_duties(int a, int b, int c)
{
    int hi = a > b ? a : b;
    hi = hi > c ? hi : c;
    int lo = a < b ? a : b;
    lo = lo < c ? lo : c;
    const int off = 16384 - (hi + lo) / 2;
    const int da = a + off, db = b + off, dc = c + off;
    const uint8_t sec = (da >= db && da >= dc) ? 1 : (db >= dc ? 3 : 5);
    const foc_duty_t d = { (q15_t)da, (q15_t)db, (q15_t)dc, sec };
    return d;
}

static void case_pwm_plans_both_readings(void)
{
    stm32_seq4_t q;
    stm32_seq4_init(&q, &wiring);
    for (uint8_t sec = 1; sec <= 6; sec++) {
        for (uint8_t aux = 0; aux < 2; aux++) {
            const foc_duty_t d = { 16384, 16384, 16384, sec };
            stm32_plan_t p, ref;
            stm32_plan_pwm_four(&p, &d, &kit, &q, aux, LEAD);
            stm32_plan_pwm(&ref, &d, &kit, &wiring, aux);
            check_plan(&p, aux, "pwm");
            TK_CHECK(p.adc1_phase == ref.adc1_phase && p.adc2_phase == ref.adc2_phase &&
                         p.window_start == ref.window_start && p.clean == ref.clean,
                     "sector %u: same phases and window as the two-conversion plan", sec);
            TK_CHECK(p.ccr4_down == 0 && p.ccr4 + LEAD == p.window_start,
                     "sector %u: trigger on the way up, lead before the window (%u, %u)", sec,
                     p.ccr4, p.window_start);
        }
    }
}

static void case_pwm_window_over_the_voltage_plane(void)
{
    /* duties of centred SVM over the plane: every window the two-conversion
     * plan chooses is reached, or the plan is flagged not clean */
    stm32_seq4_t q;
    stm32_seq4_init(&q, &wiring);
    unsigned reached = 0, total = 0;
    for (int a = 0; a <= 32767; a += 1024) {
        for (int b = 0; b <= 32767; b += 1024) {
            for (int c = 0; c <= 32767; c += 2048) {
                const foc_duty_t d = centred_duties(a, b, c);
                stm32_plan_t p, ref;
                stm32_plan_pwm_four(&p, &d, &kit, &q, 0, LEAD);
                stm32_plan_pwm(&ref, &d, &kit, &wiring, 0);
                total++;
                if (p.window_start == ref.window_start) {
                    reached++;
                    TK_CHECK(p.clean == ref.clean, "same window, same cleanliness");
                } else {
                    TK_CHECK(!p.clean || p.window_start == p.ccr4 + LEAD, "moved window");
                }
                TK_CHECK(p.ccr4_down == 0 && p.ccr4 >= 2250 / 2 - LEAD && p.ccr4 <= 2249,
                         "trigger on the way up in range: %u", p.ccr4);
            }
        }
    }
    TK_CHECK(reached * 100u >= total * 99u, "windows reached: %u of %u", reached, total);
}

static void case_all_phase_plans_both_readings(void)
{
    for (uint8_t cc4 = 0; cc4 < 2; cc4++) {
        stm32_plan_t p;
        stm32_plan_all_phases_four(&p, &kit, &wiring, cc4, LEAD);
        check_plan(&p, 0, cc4 ? "all phases, CC4" : "all phases, update");
        TK_CHECK(p.trigger_cc4 == cc4 && p.ccr4_down == 0 && p.ccr4 == 2250 - 31 - LEAD &&
                     p.window_start == 2250 - 31,
                 "centred window, trigger lead before it: %u %u", p.ccr4, p.window_start);
    }
}

/* The update-at-top plan, judged count by count: the centre-aligned
 * counter runs up (positions 0..P-1, counter = position) on the compare
 * values `up`, then down (positions P..2P-1, counter = 2P - position) on
 * the new ones `down`; a low side conducts where the counter is at or
 * above its compare value.  A phase may be read only if its low side has
 * conducted for tw_after counts when the window opens and conducts until
 * it closes (tw_before later). */
static int low_side_clean(uint16_t up, uint16_t down, int32_t start, const stm32_timing_t *t)
{
    const int32_t P = t->period;
    for (int32_t x = start - (int32_t)t->tw_after; x < start + (int32_t)t->tw_before; x++) {
        const int32_t counter = (x < P) ? x : 2 * P - x;
        const uint16_t ccr = (x < P) ? up : down;
        if (x < 0 || counter < (int32_t)ccr) {
            return 0;
        }
    }
    return 1;
}

static void case_top_plan_over_the_voltage_plane(void)
{
    stm32_seq4_t q;
    stm32_seq4_init(&q, &wiring);
    stm32_plan_t centre;
    stm32_plan_all_phases_four(&centre, &kit, &wiring, 1, LEAD);
    unsigned sets = 0, clean = 0, none_lost = 0;
    for (int a = 0; a <= 32767; a += 2048) {
        for (int b = 0; b <= 32767; b += 2048) {
            for (int c = 0; c <= 32767; c += 4096) {
                const foc_duty_t d = centred_duties(a, b, c);
                const int da = d.a, db = d.b, dc = d.c;
                /* the way up: the same set, or one moved by up to 1/8 */
                for (int shift = -4096; shift <= 4096; shift += 4096) {
                    const uint16_t up[3] = {
                        stm32_duty_to_ccr((q15_t)(da + shift < 0 ? 0 : da + shift > 32767 ? 32767 : da + shift), 2250),
                        stm32_duty_to_ccr((q15_t)(db - shift < 0 ? 0 : db - shift > 32767 ? 32767 : db - shift), 2250),
                        stm32_duty_to_ccr((q15_t)dc, 2250) };
                    const uint16_t down[3] = { stm32_duty_to_ccr(d.a, 2250), stm32_duty_to_ccr(d.b, 2250),
                                               stm32_duty_to_ccr(d.c, 2250) };
                    stm32_plan_t p;
                    stm32_plan_pwm_top(&p, up, &d, &kit, &q, 0, centre.window_start, centre.ccr4);
                    uint8_t ok = 0;
                    for (unsigned i = 0; i < 3u; i++) {
                        if (low_side_clean(up[i], down[i], p.window_start, &kit)) {
                            ok = (uint8_t)(ok | (1u << i));
                        }
                    }
                    sets++;
                    TK_CHECK((p.phases & (uint8_t)~ok) == 0u,
                             "duties %d %d %d: a phase read whose low side is not on (%x, %x)", da,
                             db, dc, p.phases, ok);
                    const unsigned n_ok = (unsigned)((ok & 1u) + ((ok >> 1) & 1u) + ((ok >> 2) & 1u));
                    TK_CHECK(p.clean == (n_ok >= 2u), "duties %d %d %d: clean %u with %u phases on",
                             da, db, dc, p.clean, n_ok);
                    if (p.clean) {
                        clean++;
                        TK_CHECK(p.adc1_phase != p.adc2_phase &&
                                     p.phases == (uint8_t)((1u << p.adc1_phase) | (1u << p.adc2_phase)),
                                 "clean: two distinct phases, both read");
                    }
                    none_lost += (n_ok >= 2u);
                    TK_CHECK(p.window_start == centre.window_start && p.ccr4 == centre.ccr4 &&
                                 p.ccr4_down == 0 && p.trigger_cc4 == 1,
                             "the fixed centred window and trigger");
                }
            }
        }
    }
    printf("top plan: %u duty sets, %u clean (%u with two low sides on)\n", sets, clean, none_lost);
    TK_CHECK(clean * 10u >= sets * 9u, "clean in %u of %u sets", clean, sets);
}

TK_CASES(TK_CASE(case_pwm_plans_both_readings), TK_CASE(case_pwm_window_over_the_voltage_plane),
         TK_CASE(case_all_phase_plans_both_readings), TK_CASE(case_top_plan_over_the_voltage_plane))
