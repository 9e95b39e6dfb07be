#include "dspic_logic.h"

/* A 16-bit register word as the int16_t it encodes (two's complement),
 * without relying on the implementation-defined unsigned -> signed cast. */
static int32_t word_to_signed(uint16_t word)
{
    return (int32_t)word - (((word & 0x8000u) != 0u) ? 65536L : 0L);
}

q15_t dspic_adc_current_q15(uint16_t word, uint8_t inverted)
{
    const int32_t f = word_to_signed(word);
    return foc_sat_q15((inverted != 0u) ? -f : f);
}

q15_t dspic_adc_unipolar_q15(uint16_t word)
{
    /* Flipping the sign bit turns (c - 512) x 64 into c x 64. */
    const uint16_t code_x64 = (uint16_t)(word ^ 0x8000u);
    return (q15_t)(code_x64 >> 1);
}

uint16_t dspic_pwm_ptper(uint32_t fcy_hz, uint32_t fpwm_hz)
{
    if (fpwm_hz == 0u) {
        return 0;
    }
    const uint32_t half = fcy_hz / (2u * fpwm_hz);
    if (half < 3u || half > 0x7FFFu) { /* PTPER <= 0x7FFE: 2 (PTPER + 1) fits */
        return 0;
    }
    return (uint16_t)(half - 1u);
}

uint16_t dspic_pwm_pdc_full(uint16_t ptper)
{
    const uint32_t full = 2u * ((uint32_t)ptper + 1u);
    return (full > 0xFFFFu) ? 0xFFFFu : (uint16_t)full;
}

uint16_t dspic_duty_to_pdc(q15_t duty, uint16_t pdc_full)
{
    if (duty <= 0) {
        return 0;
    }
    const uint32_t pdc = ((uint32_t)duty * pdc_full + 16384u) >> 15;
    return (pdc > pdc_full) ? pdc_full : (uint16_t)pdc;
}

uint16_t dspic_deadtime_dtcon(uint16_t tcy)
{
    uint16_t ps;
    for (ps = 0; ps < 4u; ps++) {
        const uint32_t unit = (uint32_t)1u << ps;
        const uint32_t count = ((uint32_t)tcy + unit - 1u) / unit; /* round up */
        if (count <= 63u) {
            return (uint16_t)((uint16_t)(ps << 6) | (uint16_t)count);
        }
    }
    return 0xFFFFu;
}

uint16_t dspic_deadtime_tcy(uint16_t dtcon)
{
    const uint16_t ps = (uint16_t)((dtcon >> 6) & 0x3u);
    return (uint16_t)((dtcon & 0x3Fu) << ps);
}

uint16_t dspic_uart_brg(uint32_t fcy_hz, uint32_t baud)
{
    if (baud == 0u) {
        return 0xFFFFu;
    }
    const uint32_t div = (fcy_hz + 2u * baud) / (4u * baud); /* rounded */
    if (div < 1u || div > 0x10000u) {
        return 0xFFFFu;
    }
    return (uint16_t)(div - 1u);
}

static uint16_t adc_word(const dspic_port_cfg_t *cfg, uint8_t buf)
{
    return *cfg->regs->adcbuf[buf & 3u];
}

void dspic_read_samples(const dspic_port_cfg_t *cfg, foc_samples_t *s)
{
    s->i_a = dspic_adc_current_q15(adc_word(cfg, cfg->buf_ia), cfg->current_inverted);
    s->i_b = dspic_adc_current_q15(adc_word(cfg, cfg->buf_ib), cfg->current_inverted);
    s->i_c = 0;
    s->phases = (uint8_t)(FOC_PHASE_A | FOC_PHASE_B);
    s->vdc = dspic_adc_unipolar_q15(adc_word(cfg, cfg->buf_vdc));
    s->temp = 0; /* no temperature sensor on the board */
    s->pot = dspic_adc_unipolar_q15(adc_word(cfg, cfg->buf_pot));
    s->theta_sensor = 0;
}

void dspic_set_duties(const dspic_port_cfg_t *cfg, const foc_duty_t *d)
{
    *cfg->regs->pdc[0] = dspic_duty_to_pdc(d->a, cfg->pdc_full);
    *cfg->regs->pdc[1] = dspic_duty_to_pdc(d->b, cfg->pdc_full);
    *cfg->regs->pdc[2] = dspic_duty_to_pdc(d->c, cfg->pdc_full);
}

uint8_t dspic_fault_latched(const dspic_port_cfg_t *cfg)
{
    const dspic_regs_t *r = cfg->regs;
    const uint8_t flag = (uint8_t)((*r->ifs3 & DSPIC_IFS3_FLTA1IF) != 0u);
    const uint8_t pin_active = (uint8_t)((*r->fault_port & r->fault_pin_mask) == 0u);
    return (uint8_t)(flag | pin_active);
}

void dspic_pwm_enable(const dspic_port_cfg_t *cfg)
{
    if (dspic_fault_latched(cfg) == 0u) {
        *cfg->regs->ovdcon = DSPIC_OVD_PWM;
    }
}

void dspic_pwm_disable(const dspic_port_cfg_t *cfg)
{
    *cfg->regs->ovdcon = DSPIC_OVD_ALL_OFF;
}

void dspic_low_sides_on(const dspic_port_cfg_t *cfg)
{
    if (dspic_fault_latched(cfg) == 0u) {
        *cfg->regs->ovdcon = DSPIC_OVD_LOW_SIDES;
    }
}

void dspic_fault_clear(const dspic_port_cfg_t *cfg)
{
    const dspic_regs_t *r = cfg->regs;
    if ((*r->fault_port & r->fault_pin_mask) == 0u) {
        return; /* the input is still active: the latch stays */
    }
    *r->ovdcon = DSPIC_OVD_ALL_OFF;
    *r->ifs3 = (uint16_t)(*r->ifs3 & (uint16_t)~DSPIC_IFS3_FLTA1IF);
}

void dspic_stats_reset(dspic_stats_t *st)
{
    st->min = 0xFFFFu;
    st->max = 0;
    st->avg = 0;
    st->sum = 0;
    st->count = 0;
}

void dspic_stats_add(dspic_stats_t *st, uint32_t start, uint32_t end)
{
    const uint32_t d32 = end - start; /* modulo 2^32: wrap-safe */
    const uint16_t d = (d32 > 0xFFFFu) ? 0xFFFFu : (uint16_t)d32;
    if (d < st->min) {
        st->min = d;
    }
    if (d > st->max) {
        st->max = d;
    }
    st->sum += d;
    st->count++;
    if (st->count >= ((uint16_t)1u << DSPIC_STATS_LOG2)) {
        st->avg = (uint16_t)((st->sum + (1uL << (DSPIC_STATS_LOG2 - 1u))) >> DSPIC_STATS_LOG2);
        st->sum = 0;
        st->count = 0;
    }
}
