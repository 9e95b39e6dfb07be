/*
 * The STM32F10x port's pure logic: no register access, so the host tests
 * run it as it is.  stm32_port.c moves the results into TIM1 and the ADCs.
 *
 * TIM1 runs centre-aligned: the counter goes 0 -> P -> 0 once per PWM
 * period (P = ARR), the update (new compare values, TRGO) comes at the
 * bottom.  In PWM mode 1 a phase's high side is on while CNT < CCR, so its
 * low side -- and its shunt -- conducts around the top, from CCR on the way
 * up to CCR on the way down, less the dead time.  On a "timeline" t = 0..2P
 * of one period (t = CNT going up, t = 2P - CNT going down) a phase with
 * compare value c switches at t = c and t = 2P - c.
 *
 * Sampling (3 shunts, two ADCs converting at the same instant): the phase
 * whose high side is on longest -- the one with the highest duty, named by
 * the SVM sector -- is not read; the other two are (sectors 1, 6: B and C;
 * 2, 3: A and C; 4, 5: A and B).  The sample window [s, s + tw_before]
 * must start at least tw_after after any switching edge (dead time plus the
 * amplifier settling) and end before the next, with both read phases' low
 * sides on.  In order of preference (stm32_plan_pwm):
 *   1. centred on the top of the count (nominal);
 *   2. at the start of the unread phase's low-side window, once it settled
 *      (that window is too short to reach the top, long enough to sample);
 *   3. just before the unread phase's first edge, if the middle phase has
 *      settled by then;
 *   4. no clean point exists (high modulation near a sector boundary): as
 *      close after the unread phase's first edge as the read phases allow;
 *      the plan is flagged not clean.
 * A window after the top is reached by triggering on the way down (TIM1
 * CC4 with inverted polarity), before it on the way up.
 *
 * The only register access here is through pointers (stm32_load_plan,
 * stm32_release_trigger), so a test can hand in RAM blocks.
 */
#ifndef STM32_LOGIC_H
#define STM32_LOGIC_H

#include <stdint.h>
#include "foc/port.h"
#include "foc/q15.h"
#include "foc/svm.h"
#include "stm32f10x_regs.h"

/* Timer facts, in TIM1 counts (timer clock periods). */
typedef struct {
    uint16_t period;    /* ARR: half a PWM period */
    uint16_t tw_after;  /* edge -> clean sample start: dead time + settling */
    uint16_t tw_before; /* trigger -> end of the sample-and-hold */
} stm32_timing_t;

/* Board's ADC wiring (channel numbers 0..17). */
typedef struct {
    uint8_t phase[3];          /* shunt amplifier of phases A, B, C */
    uint8_t vbus;              /* bus voltage divider */
    uint8_t temp;              /* heatsink temperature sensor */
    uint8_t pot;               /* potentiometer */
    uint8_t current_inverted;  /* 1: the amplifier output falls for */
                               /* current into the motor */
} stm32_adc_map_t;

/* What to convert in the next period and where the results land.
 * ADC1 converts [phase1, vbus] and ADC2 [phase2, aux] while the bridge
 * switches; with all three low sides conducting (outputs off, or all low
 * sides on) ADC1 converts [A, vbus, C] and ADC2 [B, temp, pot]. */
typedef struct {
    uint16_t ccr[3];     /* TIM1 CCR1..3 (phases A, B, C) */
    uint16_t ccr4;       /* sampling trigger */
    uint8_t ccr4_down;   /* 1: trigger on the way down (CC4P set) */
    uint8_t trigger_cc4; /* 1: TIM1 CC4 triggers; 0: TIM1 TRGO (update) */
    uint8_t all_phases;  /* 1: the three-phase sequence above */
    uint8_t clean;       /* 1: the sample window avoids every edge */
    uint8_t adc1_phase;  /* phase index 0..2 of ADC1's first conversion */
    uint8_t adc2_phase;  /* the same for ADC2 */
    uint8_t aux_is_pot;  /* ADC2's second conversion: pot (1) or temp (0) */
    uint8_t phases;      /* FOC_PHASE_* bits that will be valid */
    uint16_t window_start; /* timeline position s of the sample window */
    uint32_t jsqr1;      /* ADC1 JSQR */
    uint32_t jsqr2;      /* ADC2 JSQR */
} stm32_plan_t;

/* Temperature and potentiometer as last converted (they alternate). */
typedef struct {
    q15_t temp;
    q15_t pot;
} stm32_aux_t;

/* Duty (Q15 fraction of the period, clamped to [0, 32767]) to a compare
 * value in [0, period], rounded to nearest. */
uint16_t stm32_duty_to_ccr(q15_t duty, uint16_t period);

/* Index (0 = A, 1 = B, 2 = C) of the phase not read in an SVM sector; an
 * invalid sector reads A and B. */
uint8_t stm32_unread_phase(uint8_t sector);

/* JSQR value for n (1..4) conversions of channels ch[0..n-1], in order. */
uint32_t stm32_jsqr(const uint8_t *ch, uint8_t n);

/* Plan for a switching bridge with duties d (d->sector names the phases). */
void stm32_plan_pwm(stm32_plan_t *p, const foc_duty_t *d, const stm32_timing_t *t,
                    const stm32_adc_map_t *m, uint8_t aux_is_pot);

/* Plan with all three low sides conducting or all switches off: 50 %
 * compare values, three phases read at the top of the count, triggered by
 * CC4 (trigger_cc4 = 1, outputs on) or by the update (0, outputs off). */
void stm32_plan_all_phases(stm32_plan_t *p, const stm32_timing_t *t,
                           const stm32_adc_map_t *m, uint8_t trigger_cc4);

/* The same plans with four-conversion sequences (JL = 3), the port's
 * layout: RM0008 can be read as putting a sequence's k-th result in JDRk
 * or the result of slot JSQx in JDRx (tools/pil --jdr-order); with all
 * four slots used the two readings agree, JDRk = conversion k = JSQk.
 * The currents are converted third, so the end of the sequence (JEOC, the
 * interrupt) comes one conversion after them as with the two-conversion
 * sequences, and the trigger comes `lead` timer counts (two conversion
 * times) before the window.  It is always on the way up (ccr4_down = 0),
 * where OC4's rising edge and the CC4 compare event of centre-aligned
 * mode 2 coincide (tools/pil --cc4-trigger); not earlier than half a
 * period less the lead, not later than the top.  A window the trigger
 * cannot reach is re-checked where the trigger puts it (clean cleared if
 * it is not clean there).  Slots, ADC1 / ADC2:
 *   switching bridge: [vbus, vbus, phase, vbus] / [aux, aux, phase, aux]
 *   all phases:       [vbus, C, A, vbus]        / [pot, pot, B, temp]
 * The first two set the lead; no channel is converted by both ADCs in the
 * same slot (RM0008 11.9).  Read JDR3, JDR4, JDR2 of each ADC into
 * jdr1[0..2] / jdr2[0..2] of stm32_samples_from_jdr(). */
typedef struct {
    uint32_t adc1[3];    /* ADC1 JSQR reading phase i */
    uint32_t adc2[2][3]; /* ADC2 JSQR reading phase i, aux temp (0) / pot (1) */
} stm32_seq4_t;

/* The switching-bridge sequences for a board's wiring, computed once. */
void stm32_seq4_init(stm32_seq4_t *q, const stm32_adc_map_t *m);
void stm32_plan_pwm_four(stm32_plan_t *p, const foc_duty_t *d, const stm32_timing_t *t,
                         const stm32_seq4_t *q, uint8_t aux_is_pot, uint16_t lead);
void stm32_plan_all_phases_four(stm32_plan_t *p, const stm32_timing_t *t,
                                const stm32_adc_map_t *m, uint8_t trigger_cc4,
                                uint16_t lead);

/* The plan of the update-at-top build (stm32_port.c STM32_UPDATE_AT_TOP):
 * TIM1's update at the top of the count, so the sample window, fixed and
 * centred on the top (window_start, trigger ccr4 on the way up, `lead`
 * before it: stm32_plan_all_phases_four's), straddles two duty sets: the
 * way up runs on the compare values active now (ccr_up, the previous
 * plan's), the way down on those of d, loaded at the top.  With three
 * shunts a phase is valid at the window if its low side has conducted
 * for tw_after (dead time + settling) when the window starts, under
 * ccr_up, and still conducts when it ends, under d's compare values:
 *   ccr_up[i] + tw_after <= s  and  s + tw_before <= 2 P - ccr[i].
 * The sector's two phases (stm32_unread_phase) are read when both are
 * valid; otherwise the unread phase replaces an invalid one if it is
 * valid itself.  `phases` holds the read phases that are valid, `clean`
 * is 1 when both are (the core reconstructs the third); with fewer the
 * core keeps the previous period's current (foc_samples_t).  Each phase
 * is judged on its own leg: another leg's edge near the window does not
 * disqualify it (the two-window rules of stm32_plan_pwm do). */
void stm32_plan_pwm_top(stm32_plan_t *p, const uint16_t ccr_up[3], const foc_duty_t *d,
                        const stm32_timing_t *t, const stm32_seq4_t *q, uint8_t aux_is_pot,
                        uint16_t window_start, uint16_t ccr4);

/* Injected data register (left aligned: 12-bit result x 8, 0..32760) to
 * a bipolar current, Q15 of the ADC's half range around mid-scale (16384),
 * sign-corrected so current into the motor is positive; saturated. */
q15_t stm32_current_from_jdr(uint32_t jdr, uint8_t inverted);

/* Injected data register to a unipolar reading, Q15 of the ADC range. */
q15_t stm32_unipolar_from_jdr(uint32_t jdr);

/* Fills s from the converted results of a plan: jdr1[i] / jdr2[i] are
 * ADC1 / ADC2 JDR(i+1).  Updates the held temperature/pot readings. */
void stm32_samples_from_jdr(const stm32_plan_t *p, const stm32_adc_map_t *m,
                            const uint32_t jdr1[3], const uint32_t jdr2[3],
                            stm32_aux_t *held, foc_samples_t *s);

/* TIM1 BDTR.DTG code for a dead time of `counts` timer clocks (CKD = 1),
 * rounded up to the next value the generator can make; 0xFF if longer
 * than the longest (1008 counts). */
uint8_t stm32_deadtime_dtg(uint32_t counts);

/* Dead time in timer clocks that a DTG code gives. */
uint32_t stm32_deadtime_counts(uint8_t dtg);

/* Loads a plan into TIM1 (compare values, CC4 polarity) and the ADCs
 * (sequences, trigger source).  The ADC1 trigger is disabled while things
 * change; with hold_trigger it stays disabled until stm32_release_trigger()
 * (call that at the next TIM1 update, when the compare values written now
 * become the active ones).  ADC1 CR2 is written only when it changes:
 * rewriting ADON alone would start a regular conversion (RM0008). */
void stm32_load_plan(TIM_TypeDef *tim, ADC_TypeDef *adc1, ADC_TypeDef *adc2,
                     const stm32_plan_t *p, uint8_t hold_trigger);

/* Re-enables ADC1's external injected trigger if it is off. */
void stm32_release_trigger(ADC_TypeDef *adc1);

/* ADC1 CR2 trigger source codes (JEXTSEL, RM0008 table "External trigger
 * for injected channels"). */
#define STM32_JEXTSEL_TIM1_TRGO 0u
#define STM32_JEXTSEL_TIM1_CC4 ADC_CR2_JEXTSEL_0
#define STM32_JEXTSEL_JSWSTART ADC_CR2_JEXTSEL

/* Signed Q15 value to a "DAC" PWM compare value in [0, arr]: -1.0 -> 0,
 * 0 -> mid, +1.0 -> arr. */
uint16_t stm32_debug_ccr(q15_t v, uint16_t arr);

#endif /* STM32_LOGIC_H */
