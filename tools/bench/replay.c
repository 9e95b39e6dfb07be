/* Frame replay port and loop: see replay.h.  Portable C99, no library
 * calls. */
#include "replay.h"

foc_ctrl_t bench_ctrl;
uint32_t bench_scenario_mask = 0xFFFFFFFFu;

static bench_port_t port;
static bench_in_t frame;  /* the present period's inputs */

/* ------------------------------------------------------------ the port -- */

void foc_port_read_samples(foc_samples_t *s)
{
    *s = frame.samples;
    bench_port_new_period(&port, (uint8_t)((frame.flags & BENCH_F_OC) != 0u));
}

void foc_port_set_duties(const foc_duty_t *d)
{
    bench_port_set_duties(&port, d);
}

void foc_port_pwm_enable(void)
{
    bench_port_pwm_enable(&port);
}

void foc_port_pwm_enable_at_half(void)
{
    bench_port_pwm_enable(&port);
}

void foc_port_pwm_disable(void)
{
    bench_port_pwm_disable(&port);
}

void foc_port_low_sides_on(void)
{
    bench_port_low_sides_on(&port);
}

void foc_port_brake_resistor(uint8_t on)
{
    port.brake = (uint8_t)(on != 0u);
}

uint8_t foc_port_overcurrent_latched(void)
{
    return port.latch;
}

void foc_port_overcurrent_clear(void)
{
    port.latch = 0;
}

void foc_port_debug_out(q15_t ch1, q15_t ch2)
{
    port.debug[0] = ch1;
    port.debug[1] = ch2;
}

uint32_t foc_port_timestamp(void)
{
    return 0u;
}

/* ------------------------------------------------------------ the loop -- */

void bench_replay(const uint8_t *data, uint32_t len, bench_result_t *res)
{
    bench_file_t f;
    res->status = 0;
    res->frames = 0;
    res->mismatches = 0;
    res->first_mismatch = BENCH_NO_MISMATCH;
    res->hash = BENCH_HASH_INIT;
    res->skipped = 0;
    if (bench_file_open(&f, data, len) != 0) {
        res->status = 1;
        return;
    }
    foc_ctrl_t *const c = &bench_ctrl;
    uint32_t i = 0;
    while (i < f.frame_count) {
        bench_in_get(&f, i, &frame);
        if ((frame.flags & BENCH_F_RESET) != 0u) {
            bench_scenario_t s;
            bench_scenario_get(&f, frame.scenario, &s);
            const uint32_t bit = (frame.scenario < 32u) ? (1u << frame.scenario) : 0u;
            bench_port_reset(&port);
            foc_init(c);
            if ((bench_scenario_mask & bit) == 0u || bench_scenario_apply(&s, c) != 0) {
                res->skipped |= bit;
                i = s.first_frame + s.frame_count;
                continue;
            }
        }
        if ((frame.flags & BENCH_F_START) != 0u) {
            foc_cmd_start(c);
        }
        if ((frame.flags & BENCH_F_STOP) != 0u) {
            foc_cmd_stop(c);
        }
        if ((frame.flags & BENCH_F_ACK) != 0u) {
            foc_cmd_ack(c);
        }
        if ((frame.flags & BENCH_F_SPEED) != 0u) {
            foc_cmd_speed(c, frame.speed_cmd);
        }
        foc_fast_step(c);
        if ((frame.flags & BENCH_F_SLOW) != 0u) {
            foc_slow_step(c);
        }

        bench_out_t out;
        uint8_t buf[BENCH_OUT_BYTES];
        bench_out_from(&out, c, &port);
        bench_out_encode(&out, buf);
        res->hash = bench_hash(res->hash, buf, BENCH_OUT_BYTES);
        if (bench_same(buf, bench_expected(&f, i), BENCH_OUT_BYTES) == 0u) {
            if (res->mismatches == 0u) {
                res->first_mismatch = i;
                for (uint32_t k = 0; k < BENCH_OUT_BYTES; k++) {
                    res->first_actual[k] = buf[k];
                }
            }
            res->mismatches++;
        }
        res->frames++;
        i++;
    }
}
