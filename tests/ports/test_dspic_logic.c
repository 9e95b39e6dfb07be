/*
 * dsPIC33FJ port, pure logic (hal/dspic33fj/dspic_logic.c) on the host:
 * ADC scaling with the MCLV's analog chain, duty -> PDC, period, dead time,
 * baud rate, and the port functions on a mocked register block.
 */
#include <math.h>
#include <stdint.h>

#include "dspic_logic.h"
#include "testkit.h"

/* The MCLV's current path (AN1292, DESIGN.md 3): 5 mohm shunt, amplifier
 * gain 75 around AVdd/2, 3.3 V reference: +-4.4 A spans the ADC.  The
 * shunt sits in the low side, so current into the motor (positive) makes
 * the amplifier output fall. */
#define VREF 3.3
#define SHUNT_OHM 0.005
#define AMP_GAIN 75.0
#define I_FULL_SCALE 4.4

/* The ADC: 10-bit code of a voltage, and the signed fractional word. */
static int adc_code(double volts)
{
    double c = floor(volts / VREF * 1024.0);
    if (c < 0.0) {
        c = 0.0;
    }
    if (c > 1023.0) {
        c = 1023.0;
    }
    return (int)c;
}

static uint16_t frac_word(int code)
{
    return (uint16_t)((uint32_t)((code - 512) * 64) & 0xFFFFu);
}

static uint16_t current_word(double amps_into_motor)
{
    return frac_word(adc_code(VREF / 2.0 - amps_into_motor * SHUNT_OHM * AMP_GAIN));
}

static void case_current_scaling(void)
{
    /* the fixed points of the conversion */
    TK_CHECK(dspic_adc_current_q15(0x0000u, 1) == 0, "mid-scale must read 0");
    TK_CHECK(dspic_adc_current_q15(0x8000u, 1) == 32767, "code 0 inverted saturates");
    TK_CHECK(dspic_adc_current_q15(0x7FC0u, 1) == -32704, "code 1023 inverted");
    TK_CHECK(dspic_adc_current_q15(0x7FC0u, 0) == 32704, "code 1023 as is");
    TK_CHECK(dspic_adc_current_q15(0x8000u, 0) == -32768, "code 0 as is");
    TK_CHECK(dspic_adc_current_q15(0xFFC0u, 1) == 64, "code 511 inverted");

    /* through the board's analog chain: Q15 of 4.4 A, positive into the
     * motor, within one ADC code (64 Q15 counts) of the true current */
    int worst = 0;
    for (double i = -4.35; i <= 4.35; i += 0.01) {
        const q15_t q = dspic_adc_current_q15(current_word(i), 1);
        const double expect = i / I_FULL_SCALE * 32768.0;
        const int err = (int)fabs((double)q - expect);
        if (err > worst) {
            worst = err;
        }
        TK_CHECK(err <= 65, "i=%.3f A: q=%d expected %.1f", i, q, expect);
    }
    printf("current scaling: worst error %d Q15 counts (1 ADC code = 64)\n", worst);

    /* sign: 1 A into the motor reads positive, 1 A out negative */
    TK_CHECK(dspic_adc_current_q15(current_word(1.0), 1) > 7000, "+1 A");
    TK_CHECK(dspic_adc_current_q15(current_word(-1.0), 1) < -7000, "-1 A");

    /* the same as AN1292's KCURR = Q15(-0.5) scaling, in a base twice as
     * large (AN1292: 1.0 = 8.8 A; here 1.0 = 4.4 A, the ADC full scale) */
    for (int code = 1; code < 1024; code += 7) {
        const uint16_t w = frac_word(code);
        const int32_t f = (int32_t)(code - 512) * 64;
        const int32_t an1292 = (f * -16384) >> 15; /* Q15(-0.5) = -16384 */
        const q15_t q = dspic_adc_current_q15(w, 1);
        TK_CHECK(q == 2 * an1292, "code %d: port %d, 2 x AN1292 %ld", code, q, (long)(2 * an1292));
    }
}

static void case_unipolar_scaling(void)
{
    /* code x 32 for every code */
    for (int code = 0; code < 1024; code++) {
        const q15_t q = dspic_adc_unipolar_q15(frac_word(code));
        TK_CHECK(q == code * 32, "code %d -> %d", code, q);
    }
    /* bus: divider 1/16, 52.8 V at full scale; 24 V within one code */
    const double vdc = 24.0;
    const q15_t q = dspic_adc_unipolar_q15(frac_word(adc_code(vdc / 16.0)));
    const double expect = vdc / 52.8 * 32768.0;
    TK_CHECK(fabs((double)q - expect) <= 32.0, "24 V -> %d, expected %.1f", q, expect);
    /* potentiometer at the ends */
    TK_CHECK(dspic_adc_unipolar_q15(frac_word(adc_code(0.0))) == 0, "pot 0");
    TK_CHECK(dspic_adc_unipolar_q15(frac_word(adc_code(3.3))) == 32736, "pot full");
}

static void case_pwm_period(void)
{
    const uint16_t ptper = dspic_pwm_ptper(40000000u, 20000u);
    TK_CHECK(ptper == 999, "40 MIPS, 20 kHz: PTPER %u, expected 999", ptper);
    TK_CHECK(dspic_pwm_pdc_full(ptper) == 2000, "100 %% duty: PDC %u", dspic_pwm_pdc_full(ptper));
    TK_CHECK(dspic_pwm_ptper(20000000u, 20000u) == 499, "20 MIPS");
    TK_CHECK(dspic_pwm_ptper(40000000u, 0u) == 0, "0 Hz");
    TK_CHECK(dspic_pwm_ptper(40000000u, 10000000u) == 0, "too fast");
    TK_CHECK(dspic_pwm_ptper(40000000u, 600u) == 0, "too slow for 15 bits");
    TK_CHECK(dspic_pwm_ptper(40000000u, 700u) == 28570, "700 Hz");
    TK_CHECK(dspic_pwm_pdc_full(0x7FFEu) == 0xFFFEu, "largest");
    TK_CHECK(dspic_pwm_pdc_full(0x7FFFu) == 0xFFFFu, "clamped");
}

static void case_duty_to_pdc(void)
{
    const uint16_t full = 2000;
    TK_CHECK(dspic_duty_to_pdc(0, full) == 0, "0");
    TK_CHECK(dspic_duty_to_pdc(16384, full) == 1000, "50 %%");
    TK_CHECK(dspic_duty_to_pdc(8192, full) == 500, "25 %%");
    TK_CHECK(dspic_duty_to_pdc(32767, full) == 2000, "100 %%");
    TK_CHECK(dspic_duty_to_pdc(-1, full) == 0, "negative");
    TK_CHECK(dspic_duty_to_pdc(-32768, full) == 0, "most negative");
    uint16_t prev = 0;
    for (int32_t d = 0; d <= 32767; d++) {
        const uint16_t pdc = dspic_duty_to_pdc((q15_t)d, full);
        const double exact = (double)d * full / 32768.0;
        TK_CHECK(fabs((double)pdc - exact) <= 0.5, "duty %ld -> %u (exact %.3f)", (long)d, pdc, exact);
        TK_CHECK(pdc >= prev && pdc <= full, "duty %ld: not monotonic/in range", (long)d);
        prev = pdc;
    }
    /* a large period: no overflow in the product */
    TK_CHECK(dspic_duty_to_pdc(32767, 65534u) == 65532u, "32767 of 65534");
    TK_CHECK(dspic_duty_to_pdc(16384, 65534u) == 32767u, "half of 65534");
}

static void case_deadtime(void)
{
    /* 2 us at 40 MIPS = 80 Tcy: prescaler 2 Tcy (DTAPS = 1), DTA = 40 */
    TK_CHECK(dspic_deadtime_dtcon(80) == ((1u << 6) | 40u), "80 Tcy -> 0x%04X",
             dspic_deadtime_dtcon(80));
    /* 1 us = 40 Tcy: DTAPS = 0, DTA = 40 (AN1160 writes 0x0028 for 2 us
     * at 20 MIPS, the same 40 Tcy) */
    TK_CHECK(dspic_deadtime_dtcon(40) == 0x0028u, "40 Tcy -> 0x%04X", dspic_deadtime_dtcon(40));
    TK_CHECK(dspic_deadtime_dtcon(0) == 0, "0");
    TK_CHECK(dspic_deadtime_dtcon(504) == 0x00FFu, "63 x 8");
    TK_CHECK(dspic_deadtime_dtcon(505) == 0xFFFFu, "too long");
    TK_CHECK(dspic_deadtime_dtcon(65535u) == 0xFFFFu, "no wrap");
    for (uint16_t t = 0; t <= 504u; t++) {
        const uint16_t dt = dspic_deadtime_dtcon(t);
        const uint16_t got = dspic_deadtime_tcy(dt);
        const uint16_t unit = (uint16_t)(1u << ((dt >> 6) & 3u));
        TK_CHECK(got >= t && got < t + unit, "%u Tcy -> 0x%04X = %u Tcy", t, dt, got);
        TK_CHECK(t <= 63u ? (dt >> 6) == 0u : 1, "%u Tcy: finest prescaler", t);
    }
}

static void case_uart_brg(void)
{
    /* BRGH = 1: baud = Fcy / (4 (BRG + 1)) */
    TK_CHECK(dspic_uart_brg(40000000u, 115200u) == 86, "115200 -> %u", dspic_uart_brg(40000000u, 115200u));
    TK_CHECK(dspic_uart_brg(40000000u, 9600u) == 1041, "9600 -> %u", dspic_uart_brg(40000000u, 9600u));
    const double actual = 40e6 / (4.0 * (86 + 1));
    TK_CHECK(fabs(actual / 115200.0 - 1.0) < 0.01, "115200 error %.3f %%", (actual / 115200.0 - 1.0) * 100.0);
    TK_CHECK(dspic_uart_brg(40000000u, 0u) == 0xFFFFu, "0 baud");
    TK_CHECK(dspic_uart_brg(40000000u, 50u) == 0xFFFFu, "too slow");
}

/* ------------------------------------------------ mocked register block -- */
typedef struct {
    uint16_t pdc[3];
    uint16_t ovdcon;
    uint16_t ifs3;
    uint16_t portb;
    uint16_t adcbuf[4];
    dspic_regs_t regs;
    dspic_port_cfg_t cfg;
} mock_t;

#define FAULT_PIN 0x0100u /* RB8 */

static void mock_init(mock_t *m)
{
    for (int i = 0; i < 3; i++) {
        m->pdc[i] = 0xAAAAu;
        m->regs.pdc[i] = &m->pdc[i];
    }
    for (int i = 0; i < 4; i++) {
        m->adcbuf[i] = 0;
        m->regs.adcbuf[i] = &m->adcbuf[i];
    }
    m->ovdcon = 0x1234u;
    m->ifs3 = 0;
    m->portb = FAULT_PIN; /* fault input inactive (high) */
    m->regs.ovdcon = &m->ovdcon;
    m->regs.ifs3 = &m->ifs3;
    m->regs.fault_port = &m->portb;
    m->regs.fault_pin_mask = FAULT_PIN;
    m->cfg.regs = &m->regs;
    m->cfg.pdc_full = 2000;
    m->cfg.buf_pot = 0;
    m->cfg.buf_ia = 1;
    m->cfg.buf_ib = 2;
    m->cfg.buf_vdc = 3;
    m->cfg.current_inverted = 1;
}

static void case_read_samples(void)
{
    mock_t m;
    mock_init(&m);
    m.adcbuf[0] = frac_word(1000);          /* pot */
    m.adcbuf[1] = current_word(2.0);        /* ia: 2 A into the motor */
    m.adcbuf[2] = current_word(-1.0);       /* ib: 1 A out */
    m.adcbuf[3] = frac_word(adc_code(1.5)); /* bus 24 V */
    foc_samples_t s;
    s.i_c = 1234;
    s.temp = 99;
    s.theta_sensor = 77;
    dspic_read_samples(&m.cfg, &s);
    TK_CHECK(fabs(s.i_a - 2.0 / 4.4 * 32768.0) <= 65.0, "i_a %d", s.i_a);
    TK_CHECK(fabs(s.i_b + 1.0 / 4.4 * 32768.0) <= 65.0, "i_b %d", s.i_b);
    TK_CHECK(s.phases == (FOC_PHASE_A | FOC_PHASE_B), "phases 0x%x", s.phases);
    TK_CHECK(s.i_c == 0, "i_c %d", s.i_c);
    TK_CHECK(s.pot == 32000, "pot %d", s.pot);
    TK_CHECK(s.vdc == adc_code(1.5) * 32, "vdc %d", s.vdc);
    TK_CHECK(s.temp == 0 && s.theta_sensor == 0, "no sensors: %d %u", s.temp, s.theta_sensor);

    /* another buffer assignment is honoured */
    m.cfg.buf_ia = 2;
    m.cfg.buf_ib = 1;
    dspic_read_samples(&m.cfg, &s);
    TK_CHECK(s.i_a < 0 && s.i_b > 0, "swapped buffers: %d %d", s.i_a, s.i_b);
}

static void case_set_duties(void)
{
    mock_t m;
    mock_init(&m);
    const foc_duty_t d = { 16384, 0, 32767, 1 };
    dspic_set_duties(&m.cfg, &d);
    TK_CHECK(m.pdc[0] == 1000 && m.pdc[1] == 0 && m.pdc[2] == 2000, "PDC %u %u %u", m.pdc[0],
             m.pdc[1], m.pdc[2]);
    TK_CHECK(m.ovdcon == 0x1234u, "duties must not touch the override");
}

static void case_fault_latch(void)
{
    mock_t m;
    mock_init(&m);
    m.ifs3 = 0x0200u; /* another flag in IFS3 (PWM1IF) */

    TK_CHECK(dspic_fault_latched(&m.cfg) == 0, "no fault at rest");
    dspic_pwm_enable(&m.cfg);
    TK_CHECK(m.ovdcon == DSPIC_OVD_PWM, "enable: 0x%04X", m.ovdcon);
    dspic_pwm_disable(&m.cfg);
    TK_CHECK(m.ovdcon == DSPIC_OVD_ALL_OFF, "disable: 0x%04X", m.ovdcon);
    dspic_low_sides_on(&m.cfg);
    TK_CHECK(m.ovdcon == 0x0015u, "low sides: 0x%04X", m.ovdcon);
    dspic_pwm_enable(&m.cfg);

    /* the comparator trips: pin low, the MCPWM sets FLTA1IF */
    m.portb = 0;
    m.ifs3 |= DSPIC_IFS3_FLTA1IF;
    TK_CHECK(dspic_fault_latched(&m.cfg) == 1, "latched while the pin is low");
    dspic_pwm_disable(&m.cfg); /* what the core does on the trip */
    dspic_pwm_enable(&m.cfg);
    TK_CHECK(m.ovdcon == DSPIC_OVD_ALL_OFF, "enable refused while latched");
    dspic_low_sides_on(&m.cfg);
    TK_CHECK(m.ovdcon == DSPIC_OVD_ALL_OFF, "low sides refused while latched");

    /* clear while the pin is still active: nothing changes */
    dspic_fault_clear(&m.cfg);
    TK_CHECK((m.ifs3 & DSPIC_IFS3_FLTA1IF) != 0u, "flag kept while the pin is low");
    TK_CHECK(dspic_fault_latched(&m.cfg) == 1, "still latched");

    /* pin released: the flag alone keeps the latch */
    m.portb = FAULT_PIN;
    TK_CHECK(dspic_fault_latched(&m.cfg) == 1, "the flag latches after the pin clears");

    /* a pin active without the flag also reads as latched */
    m.ifs3 = 0x0200u;
    m.portb = 0;
    TK_CHECK(dspic_fault_latched(&m.cfg) == 1, "pin alone");
    m.portb = FAULT_PIN;
    m.ifs3 |= DSPIC_IFS3_FLTA1IF;

    /* clear: outputs forced off first, the flag cleared, other flags kept */
    m.ovdcon = DSPIC_OVD_PWM;
    dspic_fault_clear(&m.cfg);
    TK_CHECK((m.ifs3 & DSPIC_IFS3_FLTA1IF) == 0u, "flag cleared");
    TK_CHECK((m.ifs3 & 0x0200u) != 0u, "other IFS3 flags kept: 0x%04X", m.ifs3);
    TK_CHECK(m.ovdcon == DSPIC_OVD_ALL_OFF, "outputs stay off after the clear: 0x%04X", m.ovdcon);
    TK_CHECK(dspic_fault_latched(&m.cfg) == 0, "released");
    dspic_pwm_enable(&m.cfg);
    TK_CHECK(m.ovdcon == DSPIC_OVD_PWM, "enable works again");
}

static void case_stats(void)
{
    dspic_stats_t st;
    dspic_stats_reset(&st);
    TK_CHECK(st.min == 0xFFFFu && st.max == 0 && st.avg == 0, "reset");
    dspic_stats_add(&st, 100, 700);
    dspic_stats_add(&st, 0xFFFFFFF0u, 0x10u); /* time base wrapped: 32 */
    dspic_stats_add(&st, 5, 5 + 100000u);     /* clamped to 65535 */
    TK_CHECK(st.min == 32, "min %u", st.min);
    TK_CHECK(st.max == 65535u, "max %u", st.max);
    TK_CHECK(st.avg == 0, "no mean before a full window");

    dspic_stats_reset(&st);
    for (uint32_t i = 0; i < (1u << DSPIC_STATS_LOG2); i++) {
        dspic_stats_add(&st, i * 1000u, i * 1000u + 400u + (i & 1u) * 200u); /* 400, 600 */
    }
    TK_CHECK(st.avg == 500, "mean %u", st.avg);
    TK_CHECK(st.min == 400 && st.max == 600, "min %u max %u", st.min, st.max);
    TK_CHECK(st.count == 0 && st.sum == 0, "window restarted");
}

TK_CASES(TK_CASE(case_current_scaling), TK_CASE(case_unipolar_scaling),
         TK_CASE(case_pwm_period), TK_CASE(case_duty_to_pdc), TK_CASE(case_deadtime),
         TK_CASE(case_uart_brg), TK_CASE(case_read_samples), TK_CASE(case_set_duties),
         TK_CASE(case_fault_latch), TK_CASE(case_stats))
