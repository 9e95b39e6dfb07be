/* The port-side state the core's port calls produce (bench_io.h), shared
 * by the recorder and the replay port.  In its own file because it runs
 * inside the measured control steps (the bench image keeps the rest of
 * the frame handling out of the simulator's timing hooks). */
#include "bench_io.h"

void bench_port_reset(bench_port_t *p)
{
    p->duty.a = 0;
    p->duty.b = 0;
    p->duty.c = 0;
    p->duty.sector = 0;
    p->set_count = 0;
    p->bridge = BENCH_BRIDGE_OFF;
    p->brake = 0;
    p->latch = 0;
    p->debug[0] = 0;
    p->debug[1] = 0;
}

/* The hardware latch turns the bridge off by itself. */
void bench_port_new_period(bench_port_t *p, uint8_t latch_after_read)
{
    p->set_count = 0;
    if (latch_after_read != 0u) {
        p->latch = 1;
        p->bridge = BENCH_BRIDGE_OFF;
    }
}

void bench_port_set_duties(bench_port_t *p, const foc_duty_t *d)
{
    p->duty = *d;
    if (p->set_count < 255u) {
        p->set_count++;
    }
}

void bench_port_pwm_enable(bench_port_t *p)
{
    if (p->latch == 0u) {
        p->bridge = BENCH_BRIDGE_PWM;
    }
}

void bench_port_pwm_disable(bench_port_t *p)
{
    p->bridge = BENCH_BRIDGE_OFF;
}

void bench_port_low_sides_on(bench_port_t *p)
{
    if (p->latch == 0u) {
        p->bridge = BENCH_BRIDGE_LOW;
    }
}
