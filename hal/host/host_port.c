#include "host_port.h"

#include <math.h>

#include "foc/config.h"
#include "foc/port.h"

static host_port_t port;

void host_port_attach(pmsm_model_t *model)
{
    port.model = model;
    port.phases = FOC_PHASE_A | FOC_PHASE_B;
    port.fault_input = 0;
    port.overcurrent_latch = 0;
    port.pwm_enabled = 0;
    port.temp_degc = 25.0;
    port.pot_fraction = 0.0;
    port.debug[0] = 0;
    port.debug[1] = 0;
    port.periods = 0;
    pmsm_set_bridge(model, PMSM_BRIDGE_OFF);
}

host_port_t *host_port(void)
{
    return &port;
}

/* ADC code (0 .. 2^bits - 1, mid-scale = 0) to signed Q15 of full scale. */
static q15_t bipolar_code_to_q15(int32_t code)
{
    /* cppcheck-suppress misra-c2012-10.1 ; D1 Q-format shift */
    const int32_t mid = 1L << (port.model->p.adc_bits - 1);
    return foc_sat_q15((code - mid) * (32768L / mid));
}

/* A unipolar analog value, fraction of full scale, through an ADC of the
 * board's resolution, to Q15 [0, 32767]. */
static q15_t unipolar_to_q15(double fraction)
{
    /* cppcheck-suppress [misra-c2012-10.1, misra-c2012-10.8] ; D1 Q-format shift, D4 value in range */
    const double levels = (double)(1L << BOARD_ADC_BITS);
    double code = floor(fraction * levels);
    if (code < 0.0) {
        code = 0.0;
    }
    if (code > levels - 1.0) {
        code = levels - 1.0;
    }
    return (q15_t)(code * (32768.0 / levels));
}

static void latch_overcurrent(void)
{
    port.overcurrent_latch = 1;
    foc_port_pwm_disable();
}

void foc_port_read_samples(foc_samples_t *s)
{
    pmsm_sample(port.model, &port.last_sample);
    const pmsm_sample_t m = port.last_sample;
    port.periods++;

    /* The comparator trips on the true current, like the board's. */
    const double limit = BOARD_CURRENT_FULL_SCALE_A;
    if (port.fault_input || fabs(m.ia_a) > limit || fabs(m.ib_a) > limit ||
        fabs(m.ic_a) > limit) {
        latch_overcurrent();
    }

    s->i_a = bipolar_code_to_q15(m.ia_code);
    s->i_b = bipolar_code_to_q15(m.ib_code);
    s->i_c = bipolar_code_to_q15(m.ic_code);
    s->phases = port.phases;
    s->vdc = unipolar_to_q15(m.vdc_v / BOARD_VDC_FULL_SCALE_V);
    s->temp = unipolar_to_q15((BOARD_TEMP_V_AT_0C + BOARD_TEMP_V_PER_DEGC * port.temp_degc) /
                              BOARD_ADC_VREF_V);
    s->pot = unipolar_to_q15(port.pot_fraction);
    /* cppcheck-suppress misra-c2012-10.8 ; D3 modular angle */
    s->theta_sensor = (uint16_t)((uint32_t)(m.theta_e_rad * (65536.0 / (2.0 * FOC_PI_D))) & 0xFFFFu);
}

void foc_port_set_duties(const foc_duty_t *d)
{
    pmsm_set_duties(port.model, d->a / 32768.0, d->b / 32768.0, d->c / 32768.0);
}

/* From the next period boundary, with the duties set now (port.h). */
void foc_port_pwm_enable(void)
{
    if (!port.overcurrent_latch) {
        port.pwm_enabled = 1;
        pmsm_set_bridge(port.model, PMSM_BRIDGE_PWM);
    }
}

void foc_port_pwm_enable_at_half(void)
{
    if (!port.overcurrent_latch) {
        port.pwm_enabled = 1;
        pmsm_set_bridge_at(port.model, PMSM_BRIDGE_PWM,
                           port.model->period_pos_s + 0.5 / port.model->p.pwm_hz);
    }
}

/* At once, as on both boards (MOE, OVDCON with OSYNC = 0): the rest of
 * this period is off (or shorted) too. */
void foc_port_pwm_disable(void)
{
    port.pwm_enabled = 0;
    pmsm_set_bridge_now(port.model, PMSM_BRIDGE_OFF);
}

void foc_port_low_sides_on(void)
{
    if (!port.overcurrent_latch) {
        port.pwm_enabled = 0;
        pmsm_set_bridge_now(port.model, PMSM_BRIDGE_LOW_SIDES);
    }
}

void foc_port_brake_resistor(uint8_t on)
{
    pmsm_set_brake_resistor(port.model, on);
}

uint8_t foc_port_overcurrent_latched(void)
{
    return port.overcurrent_latch;
}

void foc_port_overcurrent_clear(void)
{
    if (!port.fault_input) {
        port.overcurrent_latch = 0;
    }
}

void foc_port_debug_out(q15_t ch1, q15_t ch2)
{
    port.debug[0] = ch1;
    port.debug[1] = ch2;
}

uint32_t foc_port_timestamp(void)
{
    return port.periods;
}
