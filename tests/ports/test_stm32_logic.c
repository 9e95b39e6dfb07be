/*
 * STM32F10x port: the pure logic of hal/stm32f10x/stm32_logic.c on the host,
 * with RAM blocks standing in for TIM1 and the ADCs.
 *
 * Timing used unless a case says otherwise: the STM3210B-MCKIT's at 16 kHz
 * (72 MHz timer clock): P = 2250 counts per half period, tw_after = 241
 * (0.8 us dead time + 2.55 us settling), tw_before = 63 (3 + 7.5 ADC clocks
 * at 12 MHz).
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "foc/svm.h"
#include "stm32_logic.h"
#include "testkit.h"

#define PI 3.14159265358979323846

static const stm32_timing_t kit = { 2250, 241, 63 };
static const stm32_adc_map_t wiring = { { 11, 12, 13 }, 3, 10, 14, 1 };

static q15_t q(double x)
{
    return (q15_t)lround(fmin(fmax(x * 32768.0, -32768.0), 32767.0));
}

static foc_duty_t svm_at(double mag, double angle_rad)
{
    const foc_ab_t v = { q(mag * cos(angle_rad)), q(mag * sin(angle_rad)) };
    return foc_svm_q15(v);
}

/* ------------------------------------------------ duty -> compare value -- */
static void case_duty_to_ccr(void)
{
    TK_CHECK(stm32_duty_to_ccr(0, 2250) == 0, "0");
    TK_CHECK(stm32_duty_to_ccr(16384, 2250) == 1125, "half: %u",
             stm32_duty_to_ccr(16384, 2250));
    TK_CHECK(stm32_duty_to_ccr(32767, 2250) == 2250, "full: %u",
             stm32_duty_to_ccr(32767, 2250));
    TK_CHECK(stm32_duty_to_ccr(-5, 2250) == 0, "negative clamps to 0");
    unsigned prev = 0;
    int bad = 0;
    for (int32_t d = 0; d <= 32767 && bad < 5; d++) {
        const unsigned c = stm32_duty_to_ccr((q15_t)d, 2250);
        const double exact = d * 2250.0 / 32768.0;
        if (fabs(c - exact) > 0.5 + 1e-9 || c < prev) {
            TK_CHECK(0, "d=%d c=%u exact=%f prev=%u", (int)d, c, exact, prev);
            bad++;
        }
        prev = c;
    }
    TK_CHECK(stm32_duty_to_ccr(32767, 65535) == 65533, "largest period: %u",
             stm32_duty_to_ccr(32767, 65535));
}

/* --------------------------------------------- sector -> phases read -- */
static void case_unread_phase_table(void)
{
    static const uint8_t expected[8] = { 2, 0, 1, 1, 2, 2, 0, 2 };
    for (uint8_t s = 0; s < 8; s++) {
        TK_CHECK(stm32_unread_phase(s) == expected[s], "sector %u: %u", s,
                 stm32_unread_phase(s));
    }
}

/* The phase left out is the one with the highest duty, for the core's own
 * sector numbering, everywhere in the plane (ties within 2 LSB allowed). */
static void case_unread_phase_has_highest_duty(void)
{
    static const double mags[] = { 0.05, 0.3, 0.6, 0.9, 1.0, 1.2 };
    int bad = 0;
    for (size_t m = 0; m < sizeof mags / sizeof mags[0]; m++) {
        for (int a = 0; a < 4096; a++) {
            const foc_duty_t d = svm_at(mags[m], a * 2.0 * PI / 4096.0);
            const int duty[3] = { d.a, d.b, d.c };
            const int x = stm32_unread_phase(d.sector);
            const int top = (duty[0] > duty[1]) ? ((duty[0] > duty[2]) ? duty[0] : duty[2])
                                                : ((duty[1] > duty[2]) ? duty[1] : duty[2]);
            if (top - duty[x] > 2 && bad++ < 5) {
                TK_CHECK(0, "mag %.2f angle %d sector %u duties %d %d %d", mags[m], a,
                         d.sector, duty[0], duty[1], duty[2]);
            }
        }
    }
    TK_CHECK(bad == 0, "%d points read the wrong phases", bad);
}

/* ------------------------------------------------------------ JSQR -- */
static void case_jsqr_layout(void)
{
    const uint8_t one[1] = { 11 };
    const uint8_t two[2] = { 11, 3 };
    const uint8_t three[3] = { 11, 3, 13 };
    const uint8_t four[4] = { 1, 2, 3, 4 };
    /* n conversions fill JSQ(5-n)..JSQ4, JL = n - 1 at bits 21:20. */
    TK_CHECK(stm32_jsqr(one, 1) == (11u << 15), "one: %x", (unsigned)stm32_jsqr(one, 1));
    TK_CHECK(stm32_jsqr(two, 2) == ((1u << 20) | (11u << 10) | (3u << 15)), "two: %x",
             (unsigned)stm32_jsqr(two, 2));
    TK_CHECK(stm32_jsqr(three, 3) == ((2u << 20) | (11u << 5) | (3u << 10) | (13u << 15)),
             "three: %x", (unsigned)stm32_jsqr(three, 3));
    TK_CHECK(stm32_jsqr(four, 4) ==
                 ((3u << 20) | 1u | (2u << 5) | (3u << 10) | (4u << 15)),
             "four: %x", (unsigned)stm32_jsqr(four, 4));
}

/* ----------------------------------------------------- PWM plans -- */
static void case_plan_phases_and_sequences(void)
{
    /* Sector by sector: which ADC reads which phase, and the sequences
     * [phase, vbus] / [phase, temp or pot]. */
    static const uint8_t adc1[7] = { 0, 1, 0, 0, 0, 0, 1 };
    static const uint8_t adc2[7] = { 0, 2, 2, 2, 1, 1, 2 };
    for (uint8_t s = 1; s <= 6; s++) {
        const foc_duty_t d = { 16384, 16384, 16384, s };
        for (uint8_t aux = 0; aux < 2; aux++) {
            stm32_plan_t p;
            stm32_plan_pwm(&p, &d, &kit, &wiring, aux);
            const uint8_t ch1[2] = { wiring.phase[adc1[s]], wiring.vbus };
            const uint8_t ch2[2] = { wiring.phase[adc2[s]], aux ? wiring.pot : wiring.temp };
            TK_CHECK(p.adc1_phase == adc1[s] && p.adc2_phase == adc2[s],
                     "sector %u: ADC1 %u ADC2 %u", s, p.adc1_phase, p.adc2_phase);
            TK_CHECK(p.phases == (uint8_t)((1u << adc1[s]) | (1u << adc2[s])),
                     "sector %u: phases %x", s, p.phases);
            TK_CHECK(p.jsqr1 == stm32_jsqr(ch1, 2) && p.jsqr2 == stm32_jsqr(ch2, 2),
                     "sector %u aux %u: sequences", s, aux);
            TK_CHECK(p.trigger_cc4 == 1 && p.all_phases == 0 && p.aux_is_pot == aux,
                     "sector %u: flags", s);
            TK_CHECK(p.ccr[0] == 1125 && p.ccr[1] == 1125 && p.ccr[2] == 1125,
                     "sector %u: compare values", s);
        }
    }
}

static void case_plan_all_phases(void)
{
    for (uint8_t cc4 = 0; cc4 < 2; cc4++) {
        stm32_plan_t p;
        stm32_plan_all_phases(&p, &kit, &wiring, cc4);
        const uint8_t ch1[3] = { 11, 3, 13 };
        const uint8_t ch2[3] = { 12, 10, 14 };
        TK_CHECK(p.phases == (FOC_PHASE_A | FOC_PHASE_B | FOC_PHASE_C), "phases");
        TK_CHECK(p.all_phases == 1 && p.trigger_cc4 == cc4 && p.clean == 1, "flags");
        TK_CHECK(p.ccr[0] == 1125 && p.ccr[1] == 1125 && p.ccr[2] == 1125, "50 %%");
        TK_CHECK(p.ccr4 == 2250 - 31 && p.ccr4_down == 0, "at the top: %u %u", p.ccr4,
                 p.ccr4_down);
        TK_CHECK(p.jsqr1 == stm32_jsqr(ch1, 3) && p.jsqr2 == stm32_jsqr(ch2, 3), "sequences");
    }
}

/* --------------------------------------------------- sampling point -- */
/* The specification, written out independently: a window [s, s + tb] is
 * clean if both read phases conduct and have settled throughout, and no
 * edge of the unread phase lies within (s - ta, s + tb). */
static int clean_at(int s, int P, const int c[3], int x, int ta, int tb)
{
    for (int i = 0; i < 3; i++) {
        if (i == x) {
            const int e1 = c[i];
            const int e2 = 2 * P - c[i];
            if ((e1 > s - ta && e1 < s + tb) || (e2 > s - ta && e2 < s + tb)) {
                return 0;
            }
        } else if (s < c[i] + ta || s + tb > 2 * P - c[i]) {
            return 0;
        }
    }
    return 1;
}

typedef struct {
    int centred, inside, before, unclean, total, unclean_below_090, unclean_at_095;
} rule_count_t;

static void check_plan_window(const foc_duty_t *d, const stm32_timing_t *t, double mag,
                              rule_count_t *n)
{
    stm32_plan_t p;
    stm32_plan_pwm(&p, d, t, &wiring, 0);
    const int P = t->period;
    const int c[3] = { p.ccr[0], p.ccr[1], p.ccr[2] };
    const int x = stm32_unread_phase(d->sector);
    const int s = p.window_start;
    const int trig = p.ccr4_down ? 2 * P - p.ccr4 : p.ccr4;
    n->total++;

    TK_CHECK(p.ccr4 >= 1 && p.ccr4 <= P - 1, "CC4 %u out of range", p.ccr4);
    if (p.clean) {
        TK_CHECK(trig == s, "trigger at %d, window at %d", trig, s);
        TK_CHECK(clean_at(s, P, c, x, t->tw_after, t->tw_before),
                 "window at %d is not clean: c = %d %d %d, unread %d", s, c[0], c[1], c[2], x);
        if (clean_at(P - t->tw_before / 2, P, c, x, t->tw_after, t->tw_before)) {
            TK_CHECK(s == P - t->tw_before / 2, "the centred window was clean, got %d", s);
        }
    } else {
        int exists = -1;
        for (int k = 0; k < 2 * P && exists < 0; k++) {
            if (clean_at(k, P, c, x, t->tw_after, t->tw_before)) {
                exists = k;
            }
        }
        TK_CHECK(exists < 0, "plan not clean but a clean window exists at %d "
                 "(c = %d %d %d, unread %d)", exists, c[0], c[1], c[2], x);
        if (mag <= 0.9) {
            n->unclean_below_090++;
        } else if (mag <= 0.95) {
            n->unclean_at_095++;
        }
    }
    if (!p.clean) {
        n->unclean++;
    } else if (s == P - t->tw_before / 2) {
        n->centred++;
    } else if (s == c[x] + t->tw_after ||
               (c[x] + t->tw_after == P && s == P + 1)) { /* top: a count later */
        n->inside++;
    } else if (s == c[x] - t->tw_before) {
        n->before++;
    }
}

static void case_sampling_point(void)
{
    static const double mags[] = { 0.0, 0.2, 0.5, 0.8, 0.9, 0.95, 1.0, 1.05, 1.2 };
    rule_count_t n = { 0, 0, 0, 0, 0, 0, 0 };
    for (size_t m = 0; m < sizeof mags / sizeof mags[0]; m++) {
        for (int a = 0; a < 1536; a++) {
            const foc_duty_t d = svm_at(mags[m], a * 2.0 * PI / 1536.0);
            check_plan_window(&d, &kit, mags[m], &n);
        }
    }
    /* Every rule is exercised.  With the board's timing at 16 kHz a clean
     * window exists up to |v| = 0.9 everywhere; at 0.95 not in a band of
     * a few degrees on both sides of the sector boundaries (60 of the 1536
     * angles: the unread phase's window too short, the middle phase too
     * close to it). */
    TK_CHECK(n.centred > 0 && n.inside > 0 && n.before > 0 && n.unclean > 0,
             "rules used: centred %d inside %d before %d unclean %d", n.centred, n.inside,
             n.before, n.unclean);
    TK_CHECK(n.centred + n.inside + n.before + n.unclean == n.total,
             "a clean window matched no rule");
    TK_CHECK(n.unclean_below_090 == 0, "%d unclean plans at |v| <= 0.9",
             n.unclean_below_090);
    TK_CHECK(n.unclean_at_095 > 0 && n.unclean_at_095 <= 72, "%d unclean plans at 0.95",
             n.unclean_at_095);
}

/* Specific points of each rule, by hand. */
static void case_sampling_point_rules(void)
{
    stm32_plan_t p;
    /* Low duties: centred on the top, triggered on the way up. */
    foc_duty_t d = { 18000, 16000, 14000, 1 };
    stm32_plan_pwm(&p, &d, &kit, &wiring, 0);
    TK_CHECK(p.clean && p.ccr4 == 2250 - 31 && p.ccr4_down == 0, "centred: %u %u",
             p.ccr4, p.ccr4_down);
    /* A at 90 %: its window (2 x 225 counts) is too short for the centred
     * sample but holds one after it settled: past the top, way down. */
    d.a = q(0.90);
    stm32_plan_pwm(&p, &d, &kit, &wiring, 0);
    TK_CHECK(p.clean && p.window_start == p.ccr[0] + 241, "inside A: start %u, A %u",
             p.window_start, p.ccr[0]);
    TK_CHECK(p.ccr4_down == 1 && p.ccr4 == 2 * 2250 - p.window_start, "way down: %u %u",
             p.ccr4, p.ccr4_down);
    /* A at 99 %, B low: sample before A switches, on the way up. */
    d.a = q(0.99);
    stm32_plan_pwm(&p, &d, &kit, &wiring, 0);
    TK_CHECK(p.clean && p.window_start == p.ccr[0] - 63 && p.ccr4_down == 0 &&
                 p.ccr4 == p.window_start,
             "before A: start %u, A %u", p.window_start, p.ccr[0]);
    /* A and B both at 99 %: nothing clean, flagged. */
    d.b = q(0.99);
    stm32_plan_pwm(&p, &d, &kit, &wiring, 0);
    TK_CHECK(!p.clean, "A = B = 99 %% cannot be clean");
    TK_CHECK(p.phases == (FOC_PHASE_B | FOC_PHASE_C), "still reads B, C");
}

/* ----------------------------------------------------- ADC scaling -- */
static void case_current_scaling(void)
{
    /* Left-aligned injected result: 12-bit code x 8; mid-scale 2048 x 8. */
    TK_CHECK(stm32_current_from_jdr(16384, 1) == 0, "mid-scale is zero");
    TK_CHECK(stm32_current_from_jdr(0, 1) == 32767, "bottom, inverted: %d",
             stm32_current_from_jdr(0, 1));
    TK_CHECK(stm32_current_from_jdr(4095u * 8u, 1) == -32752, "top, inverted: %d",
             stm32_current_from_jdr(4095u * 8u, 1));
    TK_CHECK(stm32_current_from_jdr(4095u * 8u, 0) == 32752, "top: %d",
             stm32_current_from_jdr(4095u * 8u, 0));
    TK_CHECK(stm32_current_from_jdr(0, 0) == -32768, "bottom: %d",
             stm32_current_from_jdr(0, 0));
    /* One code = 16 Q15 counts, either way round. */
    for (uint32_t code = 1; code < 4096; code++) {
        const int step = stm32_current_from_jdr(code * 8u, 0) -
                         stm32_current_from_jdr((code - 1u) * 8u, 0);
        const int inv = stm32_current_from_jdr(code * 8u, 1) -
                        stm32_current_from_jdr((code - 1u) * 8u, 1);
        /* (code 0 inverted saturates at +32767, one short) */
        TK_CHECK(step == 16 && (inv == -16 || (code == 1u && inv == -15)), "code %u: %d %d",
                 (unsigned)code, step, inv);
    }
    TK_CHECK(stm32_unipolar_from_jdr(0) == 0 && stm32_unipolar_from_jdr(4095u * 8u) == 32760,
             "unipolar range");
}

static void case_samples_from_jdr(void)
{
    stm32_plan_t p;
    stm32_aux_t held = { 111, 222 };
    foc_samples_t s;
    const uint32_t j1[3] = { 16384 - 100, 8000, 16384 + 300 };
    const uint32_t j2[3] = { 16384 + 50, 4000, 12000 };

    /* Sector 1: ADC1 reads B, ADC2 reads C; ADC2's second is temperature. */
    const foc_duty_t d = { 20000, 16000, 12000, 1 };
    memset(&s, 0x55, sizeof s);
    stm32_plan_pwm(&p, &d, &kit, &wiring, 0);
    stm32_samples_from_jdr(&p, &wiring, j1, j2, &held, &s);
    TK_CHECK(s.phases == (FOC_PHASE_B | FOC_PHASE_C), "phases %x", s.phases);
    TK_CHECK(s.i_b == 200 && s.i_c == -100 && s.i_a == 0, "currents %d %d %d", s.i_a, s.i_b,
             s.i_c);
    TK_CHECK(s.vdc == 8000 && s.temp == 4000 && s.pot == 222, "bus %d temp %d pot %d", s.vdc,
             s.temp, s.pot);
    TK_CHECK(s.theta_sensor == 0, "no sensor");
    /* Next period the pot comes in and the temperature is held. */
    stm32_plan_pwm(&p, &d, &kit, &wiring, 1);
    stm32_samples_from_jdr(&p, &wiring, j1, j2, &held, &s);
    TK_CHECK(s.temp == 4000 && s.pot == 4000, "temp %d pot %d", s.temp, s.pot);

    /* Outputs off: three phases, bus, temperature and pot all at once. */
    stm32_plan_all_phases(&p, &kit, &wiring, 0);
    stm32_samples_from_jdr(&p, &wiring, j1, j2, &held, &s);
    TK_CHECK(s.phases == (FOC_PHASE_A | FOC_PHASE_B | FOC_PHASE_C), "all phases");
    TK_CHECK(s.i_a == 200 && s.i_b == -100 && s.i_c == -600, "currents %d %d %d", s.i_a,
             s.i_b, s.i_c);
    TK_CHECK(s.vdc == 8000 && s.temp == 4000 && s.pot == 12000, "bus %d temp %d pot %d",
             s.vdc, s.temp, s.pot);
}

/* ------------------------------------------- registers (RAM blocks) -- */
static void case_load_plan_registers(void)
{
    TIM_TypeDef tim;
    ADC_TypeDef adc1, adc2;
    memset(&tim, 0, sizeof tim);
    memset(&adc1, 0, sizeof adc1);
    memset(&adc2, 0, sizeof adc2);
    adc1.CR2 = ADC_CR2_ADON | ADC_CR2_ALIGN | ADC_CR2_JEXTTRIG; /* TRGO, running */
    tim.CCER = TIM_CCER_CC1E | TIM_CCER_CC4E;

    /* A plan triggered on the way down, held: trigger off, CC4P set. */
    foc_duty_t d = { q(0.90), q(0.6), q(0.3), 1 };
    stm32_plan_t p;
    stm32_plan_pwm(&p, &d, &kit, &wiring, 0);
    TK_CHECK(p.ccr4_down == 1, "test needs a way-down trigger");
    stm32_load_plan(&tim, &adc1, &adc2, &p, 1);
    TK_CHECK(tim.CCR1 == p.ccr[0] && tim.CCR2 == p.ccr[1] && tim.CCR3 == p.ccr[2] &&
                 tim.CCR4 == p.ccr4,
             "compare values");
    TK_CHECK((tim.CCER & TIM_CCER_CC4P) != 0 && (tim.CCER & TIM_CCER_CC1E) != 0,
             "CC4P set, other bits kept: %x", tim.CCER);
    TK_CHECK(adc1.JSQR == p.jsqr1 && adc2.JSQR == p.jsqr2, "sequences");
    TK_CHECK((adc1.CR2 & ADC_CR2_JEXTTRIG) == 0, "trigger held off until the update");
    TK_CHECK((adc1.CR2 & ADC_CR2_JEXTSEL) == STM32_JEXTSEL_TIM1_CC4, "source CC4: %x",
             (unsigned)adc1.CR2);
    TK_CHECK((adc1.CR2 & (ADC_CR2_ADON | ADC_CR2_ALIGN)) == (ADC_CR2_ADON | ADC_CR2_ALIGN),
             "other CR2 bits kept");

    /* The update releases it. */
    stm32_release_trigger(&adc1);
    TK_CHECK((adc1.CR2 & ADC_CR2_JEXTTRIG) != 0 &&
                 (adc1.CR2 & ADC_CR2_JEXTSEL) == STM32_JEXTSEL_TIM1_CC4,
             "released: %x", (unsigned)adc1.CR2);

    /* Outputs off: update-triggered, enabled at once, CC4P cleared. */
    stm32_plan_all_phases(&p, &kit, &wiring, 0);
    stm32_load_plan(&tim, &adc1, &adc2, &p, 0);
    TK_CHECK((adc1.CR2 & ADC_CR2_JEXTSEL) == STM32_JEXTSEL_TIM1_TRGO &&
                 (adc1.CR2 & ADC_CR2_JEXTTRIG) != 0,
             "TRGO, enabled: %x", (unsigned)adc1.CR2);
    TK_CHECK((tim.CCER & TIM_CCER_CC4P) == 0, "CC4P cleared");
    TK_CHECK(tim.CCR1 == 1125 && tim.CCR4 == 2250 - 31, "50 %%, sample at the top");
}

/* One period late, as the hardware does it: the duties of period k are
 * loaded into the preload registers and become active at the update; the
 * conversion of period k+1 must then read the phases chosen for them.
 * Simulated with the register blocks: a conversion uses the JSQR and
 * CC4 polarity at its time, and the active (not the preload) compare
 * values; it can happen only while the trigger is enabled. */
static void case_one_period_delay(void)
{
    TIM_TypeDef tim;
    ADC_TypeDef adc1, adc2;
    memset(&tim, 0, sizeof tim);
    memset(&adc1, 0, sizeof adc1);
    memset(&adc2, 0, sizeof adc2);
    stm32_plan_t p;
    stm32_plan_all_phases(&p, &kit, &wiring, 1);
    stm32_load_plan(&tim, &adc1, &adc2, &p, 0);
    uint16_t active[3] = { tim.CCR1, tim.CCR2, tim.CCR3 };

    int checked = 0;
    for (int k = 0; k < 600; k++) {
        /* The fast step of period k: duties for k+1, sector changing. */
        const foc_duty_t d = svm_at(0.7, k * 2.0 * PI / 97.0);
        stm32_plan_pwm(&p, &d, &kit, &wiring, (uint8_t)(k & 1));
        stm32_load_plan(&tim, &adc1, &adc2, &p, 1);
        /* Rest of period k: the trigger is off, nothing converts with the
         * new sequence against the old compare values. */
        TK_CHECK((adc1.CR2 & ADC_CR2_JEXTTRIG) == 0, "period %d: trigger on early", k);
        /* Update: preload -> active, trigger released. */
        active[0] = tim.CCR1;
        active[1] = tim.CCR2;
        active[2] = tim.CCR3;
        stm32_release_trigger(&adc1);
        /* Conversion in period k+1: the phases in the sequence must not be
         * the one with the highest active duty. */
        const uint32_t ch1 = (adc1.JSQR >> 10) & 0x1Fu;
        const uint32_t ch2 = (adc2.JSQR >> 10) & 0x1Fu;
        int top = 0;
        for (int i = 1; i < 3; i++) {
            if (active[i] > active[top]) {
                top = i;
            }
        }
        const uint32_t top_ch = wiring.phase[top];
        const int tie = (active[0] == active[top]) + (active[1] == active[top]) +
                        (active[2] == active[top]);
        if (tie == 1) {
            TK_CHECK(ch1 != top_ch && ch2 != top_ch,
                     "period %d: converts channel %u/%u, highest duty on %u", k + 1,
                     (unsigned)ch1, (unsigned)ch2, (unsigned)top_ch);
            checked++;
        }
    }
    TK_CHECK(checked > 500, "only %d periods checked", checked);
}

/* ---------------------------------------------------------- dead time -- */
static void case_deadtime_encoding(void)
{
    for (uint32_t n = 0; n <= 1100; n++) {
        const uint8_t dtg = stm32_deadtime_dtg(n);
        const uint32_t got = stm32_deadtime_counts(dtg);
        const uint32_t step = (n <= 127) ? 1 : (n <= 254) ? 2 : (n <= 504) ? 8 : 16;
        if (n <= 1008) {
            TK_CHECK(got >= n && got - n < step + 2, "n=%u dtg=%02x gives %u", (unsigned)n, dtg,
                     (unsigned)got);
        } else {
            TK_CHECK(dtg == 0xFF && got == 1008, "n=%u beyond the generator", (unsigned)n);
        }
    }
    /* The kit's 800 ns at 72 MHz: 57.6 counts -> 58. */
    TK_CHECK(stm32_deadtime_dtg(58) == 58, "800 ns");
    TK_CHECK(stm32_deadtime_counts(0xBF) == 254 && stm32_deadtime_counts(0xC0) == 256 &&
                 stm32_deadtime_counts(0xE0) == 512,
             "range boundaries");
}

/* ------------------------------------------------------------- "DAC" -- */
static void case_debug_dac(void)
{
    TK_CHECK(stm32_debug_ccr(-32768, 1023) == 0, "-1");
    TK_CHECK(stm32_debug_ccr(0, 1023) == 512, "0: %u", stm32_debug_ccr(0, 1023));
    TK_CHECK(stm32_debug_ccr(32767, 1023) == 1023, "+1: %u", stm32_debug_ccr(32767, 1023));
    unsigned prev = 0;
    int bad = 0;
    for (int32_t v = -32768; v <= 32767 && bad < 5; v += 7) {
        const unsigned c = stm32_debug_ccr((q15_t)v, 1023);
        if (c < prev || c > 1023) {
            TK_CHECK(0, "v=%d c=%u prev=%u", (int)v, c, prev);
            bad++;
        }
        prev = c;
    }
}

TK_CASES(TK_CASE(case_duty_to_ccr), TK_CASE(case_unread_phase_table),
         TK_CASE(case_unread_phase_has_highest_duty), TK_CASE(case_jsqr_layout),
         TK_CASE(case_plan_phases_and_sequences), TK_CASE(case_plan_all_phases),
         TK_CASE(case_sampling_point), TK_CASE(case_sampling_point_rules),
         TK_CASE(case_current_scaling), TK_CASE(case_samples_from_jdr),
         TK_CASE(case_load_plan_registers), TK_CASE(case_one_period_delay),
         TK_CASE(case_deadtime_encoding), TK_CASE(case_debug_dac))
