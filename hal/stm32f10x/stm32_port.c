/*
 * STM32F10x implementation of include/foc/port.h and its interrupts; see
 * stm32_port.h for the structure and stm32_logic.h for the sampling plan.
 * Registers are RM0008's; names are ST's CMSIS ones (stm32f10x_regs.h).
 */
#include "stm32_port.h"

#include "board.h"
#include "foc/config.h"
#include "foc/port.h"
#include "stm32_gpio.h"
#include "stm32_iwdg.h"
#include "stm32_logic.h"
#include "stm32_vectors.h"
#include "stm32f10x_regs.h"

/* ----------------------------------------------------------- timing -- */
#define PWM_PERIOD_D ((double)BOARD_SYSCLK_HZ / (2.0 * PWM_FREQUENCY_HZ))
#define PWM_PERIOD ((uint16_t)(PWM_PERIOD_D + 0.5))
#define DEADTIME_COUNTS ((uint32_t)(PWM_DEADTIME_S * BOARD_SYSCLK_HZ + 0.999))
#define TW_AFTER                                                               \
    ((uint16_t)((PWM_DEADTIME_S + BOARD_CURRENT_SETTLE_S) * BOARD_SYSCLK_HZ + 0.5))
#define TW_BEFORE                                                              \
    ((uint16_t)((BOARD_ADC_LATENCY_CYCLES + BOARD_ADC_SAMPLE_CYCLES) *           \
                    BOARD_SYSCLK_HZ / BOARD_ADC_CLOCK_HZ + 0.5))
/* Two conversion times in timer counts: how far the trigger comes before the
 * current sample (the two filler slots of stm32_plan_four_slots). */
#define LEAD_COUNTS                                                            \
    ((uint16_t)(2.0 * (BOARD_ADC_SAMPLE_CYCLES + 12.5) * BOARD_SYSCLK_HZ /      \
                    BOARD_ADC_CLOCK_HZ + 0.5))
#define SLOW_TICK_CYCLES (2UL * PWM_PERIOD * (uint32_t)CONTROL_SLOW_DIVIDER)

FOC_STATIC_ASSERT(PWM_PERIOD_D >= 200.0 && PWM_PERIOD_D <= 65535.0,
                  "PWM_FREQUENCY_HZ out of TIM1's range at 72 MHz (550 Hz .. 180 kHz)");
/* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
FOC_STATIC_ASSERT(PWM_PERIOD_D - PWM_PERIOD < 1e-3 * PWM_PERIOD_D &&
                  PWM_PERIOD - PWM_PERIOD_D < 1e-3 * PWM_PERIOD_D,
                  "PWM_FREQUENCY_HZ: 72 MHz / (2 x PWM_FREQUENCY_HZ) must be an "
                  "integer within 0.1 % (the core's constants assume the exact rate)");
FOC_STATIC_ASSERT(PWM_DEADTIME_S * BOARD_SYSCLK_HZ <= 1008.0,
                  "PWM_DEADTIME_S longer than TIM1's dead-time generator (14 us)");
/* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
FOC_STATIC_ASSERT(TW_AFTER + 2u * TW_BEFORE < PWM_PERIOD / 2u,
                  "PWM_FREQUENCY_HZ too high for the dead time and shunt settling time");
/* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
FOC_STATIC_ASSERT(LEAD_COUNTS + TW_BEFORE < PWM_PERIOD / 2u,
                  "PWM_FREQUENCY_HZ too high for the four-conversion ADC sequences");
/* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
FOC_STATIC_ASSERT(SLOW_TICK_CYCLES <= 0x1000000UL,
                  "CONTROL_SLOW_DIVIDER too large for SysTick at this PWM frequency");

/* STM32_UPDATE_AT_TOP (1, the default; 0 for the former update-at-bottom
 * build: STM32_DEFS=-DSTM32_UPDATE_AT_TOP=0, which the Makefile builds with
 * SAMPLE_DELAY_PERIODS=1.0): TIM1's update at the top of the count.  The
 * sample, centred on the top, then sits at the boundary between two duty
 * sets and the duties computed from it are loaded at the next top: 1.5
 * periods from the sample to the middle of their period, which the core
 * assumes (1.0 at the bottom, docs/porting.md), and the interrupt has a
 * whole period instead of half of one (issue 11's 60 % margin met, 0
 * overruns, docs/pil.md).  CCR4 is preloaded too, so the sampling point is
 * the fixed one centred on the top (the bottom build's moved windows are
 * not used), and CC4P never changes, so the trigger is not held.  Near full
 * modulation each phase is judged on its own at that point
 * (stm32_plan_pwm_top: its low side on for dead time + settling before the
 * window and through it, under the compare values of the way up and of
 * the way down); two valid phases are enough (the core reconstructs the
 * third), the unread phase stands in for an invalid one, and with fewer
 * than two the period is unclean and the core keeps its current.
 * High-modulation scenario (tests/pil/highmod.scn): 631 unclean periods
 * against the bottom build's 798, in the same stretches. */
#ifndef STM32_UPDATE_AT_TOP
#define STM32_UPDATE_AT_TOP 1
#endif

/* NVIC preemption priorities (ST library v2.0, docs/references.md [ST-FOC]). */
#define PRIO_BREAK 0u
#define PRIO_ADC 1u
#define PRIO_UPDATE 1u
#define PRIO_SLOW 3u

/* TIM1 output modes. */
#define OC123_PWM1                                                             \
    (TIM_CCMR1_OC1M_2 | TIM_CCMR1_OC1M_1 | TIM_CCMR1_OC2M_2 | TIM_CCMR1_OC2M_1)
#define OC123_FORCE_LOW (TIM_CCMR1_OC1M_2 | TIM_CCMR1_OC2M_2)
#define OC3_PWM1 (TIM_CCMR2_OC3M_2 | TIM_CCMR2_OC3M_1)
#define OC3_FORCE_LOW TIM_CCMR2_OC3M_2
#define OC4_PWM2 (TIM_CCMR2_OC4M_2 | TIM_CCMR2_OC4M_1 | TIM_CCMR2_OC4M_0)

/* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
static const stm32_timing_t timing = { PWM_PERIOD, TW_AFTER, TW_BEFORE };
static const stm32_adc_map_t adc_map = {
    { BOARD_ADC_CH_IA, BOARD_ADC_CH_IB, BOARD_ADC_CH_IC },
    BOARD_ADC_CH_VBUS, BOARD_ADC_CH_TEMP, BOARD_ADC_CH_POT, BOARD_CURRENT_INVERTED,
};

static foc_ctrl_t *ctrl;
static stm32_seq4_t seq4;        /* the PWM plans' ADC sequences */
static stm32_plan_t plan_off;    /* outputs off: update-triggered */
static stm32_plan_t plan_on_all; /* outputs on, 50 % or low sides on */
static stm32_plan_t armed;       /* the plan of the next/ongoing conversion */
static foc_duty_t next_duty = { 16384, 16384, 16384, 1 };
static stm32_aux_t aux;
static uint8_t aux_pot;
static volatile uint8_t low_sides;
static volatile uint8_t oc_latched;
/* foc_port_pwm_enable's request: MOE at the next update, with the duties
 * the fast step has just set (TIM1_UP_IRQHandler) */
static volatile uint8_t enable_pending;
static uint8_t timer_aligned; /* 0: the bridge is never enabled */
static volatile uint32_t fast_steps;
static volatile uint32_t slow_ticks;
static uint32_t watchdog_seen;
static stm32_isr_stats_t stats;
static uint32_t avg16; /* 16 x the average */

static uint32_t irq_save(void)
{
    const uint32_t m = __get_PRIMASK();
    __disable_irq();
    return m;
}

static void irq_restore(uint32_t m)
{
    __set_PRIMASK(m);
}

/* Loads a plan (stm32_load_plan) and remembers it as the one the next
 * conversion uses.  Call with interrupts masked. */
static void apply_plan(const stm32_plan_t *p, uint8_t hold_trigger)
{
    stm32_load_plan(TIM1, ADC1, ADC2, p, hold_trigger);
    armed = *p;
}

static void set_output_modes(uint8_t force_low_sides)
{
    const uint16_t m1 = force_low_sides ? OC123_FORCE_LOW : OC123_PWM1;
    const uint16_t m3 = force_low_sides ? OC3_FORCE_LOW : OC3_PWM1;
    TIM1->CCMR1 = (uint16_t)((TIM1->CCMR1 & (uint16_t)~(TIM_CCMR1_OC1M | TIM_CCMR1_OC2M)) | m1);
    TIM1->CCMR2 = (uint16_t)((TIM1->CCMR2 & (uint16_t)~TIM_CCMR2_OC3M) | m3);
}

static uint8_t outputs_on(void)
{
    return (TIM1->BDTR & TIM_BDTR_MOE) != 0u;
}

/* on, or turning on at the next update: the next period's plan drives */
static uint8_t outputs_driving(void)
{
    return (uint8_t)(outputs_on() || enable_pending != 0u);
}

/* ------------------------------------------------------- port.h -- */
void foc_port_read_samples(foc_samples_t *s)
{
    /* four-conversion sequences: JDRk holds conversion k under either
     * reading of RM0008 (stm32_plan_four_slots) */
    const uint32_t jdr1[3] = { ADC1->JDR3, ADC1->JDR4, ADC1->JDR2 };
    const uint32_t jdr2[3] = { ADC2->JDR3, ADC2->JDR4, ADC2->JDR2 };
    stm32_samples_from_jdr(&armed, &adc_map, jdr1, jdr2, &aux, s);
    if (!armed.clean) {
        stats.unclean++;
    }
}

void foc_port_set_duties(const foc_duty_t *d)
{
    const uint32_t m = irq_save(); /* start_run calls this from the slow step */
    next_duty = *d;
    irq_restore(m);
}

void foc_port_pwm_enable(void)
{
    const uint32_t m = irq_save();
    if (timer_aligned && !foc_port_overcurrent_latched()) {
        low_sides = 0u;
        set_output_modes(0u);
        if (!outputs_driving()) {
            /* 50 % until the fast step's duties: all three phases are
             * readable at the top; conversions resume at the next update,
             * where MOE is set with the duties that load there.  Set now,
             * the outputs would apply this period's 50 %, a zero vector,
             * to a turning rotor's back-EMF until then. */
            apply_plan(&plan_on_all, 1u);
            enable_pending = 1u;
        }
    }
    irq_restore(m);
}

/* The sample sits at a turning point of the count (the top, or the
 * bottom in the update-at-bottom build), so half a period after it is the
 * next one: the count's direction changes there.  The bridge-off plan
 * stays armed: its conversion, at the next update, ends the short. */
void foc_port_pwm_enable_at_half(void)
{
    const uint32_t t0 = DWT->CYCCNT;
    const uint16_t dir0 = (uint16_t)(TIM1->CR1 & TIM_CR1_DIR);
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    while ((uint16_t)(TIM1->CR1 & TIM_CR1_DIR) == dir0 && DWT->CYCCNT - t0 < PWM_PERIOD) {
        /* at most half a period (PWM_PERIOD cycles) */
    }
    const uint32_t m = irq_save();
    if (timer_aligned && !foc_port_overcurrent_latched()) {
        low_sides = 0u;
        set_output_modes(0u);
        enable_pending = 0u;
        TIM1->BDTR = (uint16_t)(TIM1->BDTR | TIM_BDTR_MOE);
    }
    irq_restore(m);
}

void foc_port_pwm_disable(void)
{
    const uint32_t m = irq_save();
    TIM1->BDTR = (uint16_t)(TIM1->BDTR & (uint16_t)~TIM_BDTR_MOE);
    enable_pending = 0u;
    low_sides = 0u;
    set_output_modes(0u);
    apply_plan(&plan_off, 0u);
    irq_restore(m);
}

void foc_port_low_sides_on(void)
{
    const uint32_t m = irq_save();
    if (timer_aligned && !foc_port_overcurrent_latched()) {
        low_sides = 1u;
        set_output_modes(1u); /* OCxREF forced low: high sides off, low on */
        enable_pending = 0u;
        if (!outputs_on()) {
            apply_plan(&plan_on_all, 1u);
            TIM1->BDTR = (uint16_t)(TIM1->BDTR | TIM_BDTR_MOE);
        }
    }
    irq_restore(m);
}

void foc_port_brake_resistor(uint8_t on)
{
    stm32_gpio_write(BOARD_BRAKE_PORT, BOARD_BRAKE_PIN, on);
}

uint8_t foc_port_overcurrent_latched(void)
{
    return (uint8_t)(oc_latched || (TIM1->SR & TIM_SR_BIF) != 0u);
}

void foc_port_overcurrent_clear(void)
{
    const uint32_t m = irq_save();
    if (stm32_gpio_read(BOARD_BKIN_PORT, BOARD_BKIN_PIN)) { /* input released */
        TIM1->SR = (uint16_t)~TIM_SR_BIF;
        oc_latched = 0u;
        TIM1->DIER = (uint16_t)(TIM1->DIER | TIM_DIER_BIE);
    }
    irq_restore(m);
}

void foc_port_debug_out(q15_t ch1, q15_t ch2)
{
    TIM3->CCR3 = stm32_debug_ccr(ch1, BOARD_DAC_ARR);
    TIM3->CCR4 = stm32_debug_ccr(ch2, BOARD_DAC_ARR);
}

uint32_t foc_port_timestamp(void)
{
    return DWT->CYCCNT;
}

/* -------------------------------------------------- interrupts -- */
/* The next period's plan from the duties the fast step has just set. */
static void arm_next_period(void)
{
    uint32_t m = irq_save();
    const foc_duty_t d = next_duty;
    irq_restore(m);
    stm32_plan_t pwm;
    aux_pot ^= 1u;
#if STM32_UPDATE_AT_TOP
    /* the window centred on the next top: the way up on the compare values
     * active now (the armed plan's), the way down on d's; the phases valid
     * there are read, each judged on its own leg */
    stm32_plan_pwm_top(&pwm, armed.ccr, &d, &timing, &seq4, aux_pot,
                       plan_on_all.window_start, plan_on_all.ccr4);
#else
    stm32_plan_pwm_four(&pwm, &d, &timing, &seq4, aux_pot, LEAD_COUNTS);
#endif
    m = irq_save();
    if (!outputs_driving()) {
        apply_plan(&plan_off, 0u);
    } else {
        apply_plan(low_sides ? &plan_on_all : &pwm, (uint8_t)!STM32_UPDATE_AT_TOP);
    }
    irq_restore(m);
}

static void record_cycles(uint32_t cycles)
{
    if (cycles < stats.min) {
        stats.min = cycles;
    }
    if (cycles > stats.max) {
        stats.max = cycles;
    }
    avg16 = avg16 - avg16 / 16u + cycles;
    stats.avg = avg16 / 16u;
}

void ADC1_2_IRQHandler(void)
{
    const uint32_t t0 = DWT->CYCCNT;
    ADC1->SR = ~(uint32_t)ADC_SR_JEOC;
    ADC2->SR = ~(uint32_t)ADC_SR_JEOC;
    const uint8_t cc4 = armed.trigger_cc4;
    /* A CC4-triggered conversion ends near the top of the count; one seen
     * early on the way up did not come from the planned trigger. */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    if (cc4 && (TIM1->CR1 & TIM_CR1_DIR) == 0u && TIM1->CNT < PWM_PERIOD / 2u) {
        stats.spurious++;
        return;
    }
    foc_fast_step(ctrl);
    arm_next_period();
    fast_steps++;
    if (cc4 && (TIM1->SR & TIM_SR_UIF) != 0u) {
        stats.overruns++; /* the update came before the new duties */
    }
    record_cycles(DWT->CYCCNT - t0);
}

void TIM1_UP_IRQHandler(void)
{
    TIM1->SR = (uint16_t)~TIM_SR_UIF;
    if (enable_pending != 0u) {
        enable_pending = 0u;
        if (!foc_port_overcurrent_latched()) {
            TIM1->BDTR = (uint16_t)(TIM1->BDTR | TIM_BDTR_MOE);
        }
    }
    stm32_release_trigger(ADC1);
}

void TIM1_BRK_IRQHandler(void)
{
    /* The hardware has already cleared MOE.  BIF stays set while the input
     * is active, so the interrupt is re-enabled only by the clear. */
    TIM1->DIER = (uint16_t)(TIM1->DIER & (uint16_t)~TIM_DIER_BIE);
    oc_latched = 1u;
    enable_pending = 0u;
    low_sides = 0u;
    set_output_modes(0u);
    apply_plan(&plan_off, 0u); /* keep converting: the fast step sees it */
    stats.breaks++;
}

void SysTick_Handler(void)
{
    foc_slow_step(ctrl);
    slow_ticks++;
    const uint32_t n = fast_steps;
    if (n != watchdog_seen) {
        watchdog_seen = n;
        stm32_iwdg_refresh();
    }
}

/* ------------------------------------------------------------ setup -- */
static void delay_cycles(uint32_t n)
{
    const uint32_t t0 = DWT->CYCCNT;
    while (DWT->CYCCNT - t0 < n) {
    }
}

static void setup_tim1(void)
{
    /* Centre-aligned mode 2 (compare flags counting up, RM0008 14.4.1
     * CMS): the sampling trigger is always on the way up, where the CC4
     * compare event and OC4's rising edge coincide; CKD = 1. */
    TIM1->CR1 = TIM_CR1_CMS_1 | TIM_CR1_ARPE;
    TIM1->CR2 = TIM_CR2_MMS_1;                /* TRGO = update; idle low */
    TIM1->PSC = 0u;
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    TIM1->ARR = PWM_PERIOD;
    TIM1->RCR = 1u; /* one update per period */
    TIM1->CCMR1 = (uint16_t)(OC123_PWM1 | TIM_CCMR1_OC1PE | TIM_CCMR1_OC2PE);
    TIM1->CCMR2 = (uint16_t)(OC3_PWM1 | TIM_CCMR2_OC3PE | OC4_PWM2 | TIM_CCMR2_OC4PE);
    TIM1->CCER = TIM_CCER_CC1E | TIM_CCER_CC1NE | TIM_CCER_CC2E | TIM_CCER_CC2NE |
                 TIM_CCER_CC3E | TIM_CCER_CC3NE | TIM_CCER_CC4E;
    /* Dead time, break input active low, outputs driven to their idle
     * (off) level while MOE = 0, MOE only by software, then locked. */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    TIM1->BDTR = (uint16_t)(stm32_deadtime_dtg(DEADTIME_COUNTS) | TIM_BDTR_LOCK_0 |
                            TIM_BDTR_OSSI | TIM_BDTR_OSSR | TIM_BDTR_BKE);
    TIM1->CCR1 = plan_off.ccr[0];
    TIM1->CCR2 = plan_off.ccr[1];
    TIM1->CCR3 = plan_off.ccr[2];
    TIM1->CCR4 = plan_off.ccr4;
    TIM1->EGR = TIM_EGR_UG; /* load the preloads */
    TIM1->SR = 0u;
    TIM1->DIER = TIM_DIER_UIE | TIM_DIER_BIE;

    /* Full remap: PE8..PE13 carry the six gate signals, PE15 the break
     * input.  Pins switch to the timer only now, driven to the off level. */
    AFIO->MAPR = (AFIO->MAPR & ~AFIO_MAPR_SWJ_CFG) | AFIO_MAPR_TIM1_REMAP_FULLREMAP;
    for (uint32_t pin = 8u; pin <= 13u; pin++) {
        stm32_gpio_mode(GPIOE, pin, STM32_GPIO_AF_PP_50MHZ);
    }
    stm32_gpio_mode(BOARD_BKIN_PORT, BOARD_BKIN_PIN, STM32_GPIO_IN_FLOATING);
}

/* Waits for TIM1's next update (at most two periods); 1 if it came at the
 * bottom of the count (counter low and counting up right after it), 0 if
 * at the top, 2 if none came. */
static uint8_t next_update_at_bottom(void)
{
    TIM1->SR = 0u;
    const uint32_t t0 = DWT->CYCCNT;
    while ((TIM1->SR & TIM_SR_UIF) == 0u) {
        /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
        if (DWT->CYCCNT - t0 > 4u * PWM_PERIOD) {
            return 2u;
        }
    }
    const uint32_t cnt = TIM1->CNT; /* 32 bits wide in STM32Cube's headers */
    const uint8_t bottom = (uint8_t)((TIM1->CR1 & TIM_CR1_DIR) == 0u && cnt < PWM_PERIOD / 2u);
    /* with STM32_UPDATE_AT_TOP the wanted end of the count is the top */
    return STM32_UPDATE_AT_TOP ? (uint8_t)(bottom == 0u) : bottom;
}

/* Starts TIM1 with its update (new compare values, TRGO) at the bottom of
 * the count.  With a repetition count of 1 the update comes every other
 * over/underflow; which of the two depends on when the repetition counter
 * was reloaded.  First as ST's library does it: an update generated while
 * counting (the counter restarts at the bottom).  If the first update
 * still comes at the top: updates at every over/underflow (RCR = 0), and
 * RCR = 1 written just after a top, which takes effect at the next update,
 * a bottom (RM0008: the repetition counter reloads only at its update).
 * Returns 1 when two updates in a row came at the bottom. */
static uint8_t start_tim1_aligned(void)
{
    TIM1->CR1 = (uint16_t)(TIM1->CR1 | TIM_CR1_CEN);
    TIM1->EGR = TIM_EGR_UG;
    uint8_t r = next_update_at_bottom();
    if (r == 0u) {
        TIM1->RCR = 0u;
        for (unsigned n = 0; n < 4u && r != 2u; n++) {
            r = next_update_at_bottom();
            if (r == 0u) { /* just after a top */
                TIM1->RCR = 1u;
                break;
            }
        }
        r = next_update_at_bottom();
    }
    if (r == 1u) {
        r = next_update_at_bottom();
    }
    TIM1->SR = 0u;
    return (uint8_t)(r == 1u);
}

static void set_sample_time(uint32_t ch)
{
    if (ch < 10u) {
        ADC1->SMPR2 |= BOARD_ADC_SMP_CODE << (3u * ch);
        ADC2->SMPR2 |= BOARD_ADC_SMP_CODE << (3u * ch);
    } else {
        ADC1->SMPR1 |= BOARD_ADC_SMP_CODE << (3u * (ch - 10u));
        ADC2->SMPR1 |= BOARD_ADC_SMP_CODE << (3u * (ch - 10u));
    }
}

static void calibrate_adc(ADC_TypeDef *adc)
{
    adc->CR2 = ADC_CR2_ALIGN | ADC_CR2_ADON; /* power up */
    delay_cycles(BOARD_SYSCLK_HZ / 500000u); /* tSTAB, 1 us, and margin */
    adc->CR2 = ADC_CR2_ALIGN | ADC_CR2_ADON | ADC_CR2_RSTCAL;
    while ((adc->CR2 & ADC_CR2_RSTCAL) != 0u) {
    }
    adc->CR2 = ADC_CR2_ALIGN | ADC_CR2_ADON | ADC_CR2_CAL;
    while ((adc->CR2 & ADC_CR2_CAL) != 0u) {
    }
}

static void setup_adcs(void)
{
    stm32_gpio_mode(GPIOC, 0u, STM32_GPIO_ANALOG);
    stm32_gpio_mode(GPIOC, 1u, STM32_GPIO_ANALOG);
    stm32_gpio_mode(GPIOC, 2u, STM32_GPIO_ANALOG);
    stm32_gpio_mode(GPIOC, 3u, STM32_GPIO_ANALOG);
    stm32_gpio_mode(GPIOC, 4u, STM32_GPIO_ANALOG);
    stm32_gpio_mode(GPIOA, 3u, STM32_GPIO_ANALOG);

    for (uint32_t i = 0; i < 3u; i++) {
        set_sample_time(adc_map.phase[i]);
    }
    set_sample_time(adc_map.vbus);
    set_sample_time(adc_map.temp);
    set_sample_time(adc_map.pot);

    calibrate_adc(ADC1);
    calibrate_adc(ADC2);
    /* Injected simultaneous mode: ADC1 is triggered by TIM1, ADC2 follows
     * (its own trigger set to software, RM0008 dual mode notes). */
    ADC1->CR1 = ADC_CR1_DUALMOD_2 | ADC_CR1_DUALMOD_0 | ADC_CR1_SCAN | ADC_CR1_JEOCIE;
    ADC2->CR1 = ADC_CR1_SCAN;
    ADC2->CR2 = ADC_CR2_ALIGN | ADC_CR2_ADON | STM32_JEXTSEL_JSWSTART | ADC_CR2_JEXTTRIG;
    ADC1->SR = 0u;
    ADC2->SR = 0u;
}

static void setup_debug_dac(void)
{
    stm32_gpio_mode(GPIOB, 0u, STM32_GPIO_AF_PP_2MHZ);
    stm32_gpio_mode(GPIOB, 1u, STM32_GPIO_AF_PP_2MHZ);
    TIM3->PSC = 0u; /* APB1 x 2 = 72 MHz */
    TIM3->ARR = BOARD_DAC_ARR;
    TIM3->CCMR2 = (uint16_t)(OC3_PWM1 | TIM_CCMR2_OC3PE | TIM_CCMR2_OC4M_2 |
                             TIM_CCMR2_OC4M_1 | TIM_CCMR2_OC4PE);
    TIM3->CCER = (uint16_t)(TIM_CCER_CC3E | TIM_CCER_CC4E);
    foc_port_debug_out(0, 0);
    TIM3->EGR = TIM_EGR_UG;
    TIM3->CR1 = (uint16_t)(TIM_CR1_ARPE | TIM_CR1_CEN);
}

uint8_t stm32_port_init(foc_ctrl_t *c)
{
    ctrl = c;
    stm32_seq4_init(&seq4, &adc_map);
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    stm32_plan_all_phases_four(&plan_off, &timing, &adc_map, 0u, LEAD_COUNTS);
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    stm32_plan_all_phases_four(&plan_on_all, &timing, &adc_map, 1u, LEAD_COUNTS);
    stats.min = UINT32_MAX;

    RCC->APB2ENR |= RCC_APB2ENR_AFIOEN | RCC_APB2ENR_IOPAEN | RCC_APB2ENR_IOPBEN |
                    RCC_APB2ENR_IOPCEN | RCC_APB2ENR_IOPDEN | RCC_APB2ENR_IOPEEN |
                    RCC_APB2ENR_ADC1EN | RCC_APB2ENR_ADC2EN | RCC_APB2ENR_TIM1EN;
    RCC->APB1ENR |= RCC_APB1ENR_TIM3EN;
    CoreDebug->DEMCR |= CoreDebug_DEMCR_TRCENA_Msk;
    DWT->CYCCNT = 0u;
    DWT->CTRL |= DWT_CTRL_CYCCNTENA_Msk;

    stm32_gpio_write(BOARD_BRAKE_PORT, BOARD_BRAKE_PIN, 0u);
    stm32_gpio_mode(BOARD_BRAKE_PORT, BOARD_BRAKE_PIN, STM32_GPIO_OUT_PP_2MHZ);

    setup_tim1();
    setup_adcs();
    apply_plan(&plan_off, 0u);
    setup_debug_dac();

    NVIC_SetPriority(TIM1_BRK_IRQn, PRIO_BREAK);
    NVIC_SetPriority(ADC1_2_IRQn, PRIO_ADC);
    NVIC_SetPriority(TIM1_UP_IRQn, PRIO_UPDATE);
    NVIC_SetPriority(SysTick_IRQn, PRIO_SLOW);
    timer_aligned = start_tim1_aligned();
    NVIC_EnableIRQ(TIM1_BRK_IRQn);
    NVIC_EnableIRQ(ADC1_2_IRQn);
    NVIC_EnableIRQ(TIM1_UP_IRQn);

    /* The slow tick: exactly CONTROL_SLOW_DIVIDER PWM periods of the same
     * clock, so it never drifts against the fast step. */
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    SysTick->LOAD = SLOW_TICK_CYCLES - 1u;
    SysTick->VAL = 0u;
    SysTick->CTRL = SysTick_CTRL_CLKSOURCE_Msk | SysTick_CTRL_TICKINT_Msk |
                    SysTick_CTRL_ENABLE_Msk;
    return timer_aligned;
}

void stm32_port_isr_stats(stm32_isr_stats_t *out)
{
    const uint32_t m = irq_save();
    *out = stats;
    irq_restore(m);
}

void stm32_port_isr_stats_reset(void)
{
    const uint32_t m = irq_save();
    const stm32_isr_stats_t zero = { UINT32_MAX, 0u, 0u, 0u, 0u, 0u, 0u };
    stats = zero;
    avg16 = 0u;
    irq_restore(m);
}

uint32_t stm32_port_slow_ticks(void)
{
    return slow_ticks;
}

uint32_t stm32_port_period_cycles(void)
{
    /* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
    return 2u * PWM_PERIOD;
}
