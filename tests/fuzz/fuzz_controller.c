/*
 * Fuzz harness: the controller driven by arbitrary ADC frames, bus
 * voltages, temperatures, position-sensor angles, over-current trips and
 * command sequences, through a port (port.h) that plays them back, with an
 * oracle checked after every call into the core.
 *
 * Built with libFuzzer (clang -fsanitize=fuzzer,address,undefined: `make
 * fuzz`) or with fuzz_main.c as a plain program that replays files (the
 * ctest fuzz.corpus runs the seed corpus under the host build, and under
 * ASan+UBSan in the sanitizer build).
 *
 * Input: an 8-byte header, then 16-byte records, each one or more PWM
 * periods (see decode_*).  Samples stay within port.h's contract (bus,
 * temperature and potentiometer readings >= 0, two or three valid phases);
 * currents and angles take any value.  The slow step runs every
 * CONTROL_SLOW_DIVIDER periods, as on the targets.  At most MAX_PERIODS
 * periods per input.
 *
 * Oracle (a violation aborts with a message, which libFuzzer reports):
 *   - every duty passed to foc_port_set_duties in [0, 32767], sector 1..6;
 *   - the state one of foc_state_t's;
 *   - FAULT if and only if a fault is active; faults.first one bit of
 *     faults.active (0 when none);
 *   - in FAULT the bridge is off (the last of enable/disable/low sides was
 *     a disable, or the hardware latch turned it off);
 *   - faults are latched: active bits never disappear except all at once,
 *     in a slow step with an acknowledge pending, with the hardware latch
 *     clear and every cleared fault's cause gone (config.h thresholds with
 *     their hysteresis);
 *   - a hardware over-current latch seen by a fast step means FAULT with
 *     OVERCURRENT active after it;
 *   - a bus or temperature reading beyond its trip threshold at a slow step
 *     means FAULT after it (with that fault active, unless another fault
 *     was already latched);
 *   - the current limit, as far as a harness without a plant can judge it:
 *     the current references (the slow step's and the fast step's slewed
 *     ones) never leave the circle of CURRENT_LIMIT_A, whatever the
 *     measurements and commands;
 *   - the speed limit: the stored command never beyond
 *     MOTOR_MAX_SPEED_RPM (the ramp may start from a rotor driven faster).
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "foc/config.h"
#include "foc/controller.h"
#include "foc/port.h"

#define HEADER_BYTES 8u
#define RECORD_BYTES 16u
#define MAX_PERIODS 20000u

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* ------------------------------------------------------------ the port -- */

enum { BRIDGE_OFF, BRIDGE_PWM, BRIDGE_LOW };

static struct {
    foc_samples_t samples;
    uint8_t trip_input;  /* comparator / fault input asserted this period */
    uint8_t latch;       /* hardware over-current latch */
    uint8_t bridge;
    uint8_t brake;
    uint8_t latched_at_read;
} port;

static void fail(const char *what, unsigned period)
{
    fprintf(stderr, "fuzz_controller: oracle violated at period %u: %s\n", period, what);
    abort();
}

static unsigned period_no;

void foc_port_read_samples(foc_samples_t *s)
{
    *s = port.samples;
    if (port.trip_input != 0u) {
        port.latch = 1;
    }
    if (port.latch != 0u) {
        port.bridge = BRIDGE_OFF; /* the latch turns the bridge off itself */
    }
    port.latched_at_read = port.latch;
}

void foc_port_set_duties(const foc_duty_t *d)
{
    if (d->a < 0 || d->b < 0 || d->c < 0) {
        fail("negative duty", period_no);
    }
    if (d->sector < 1u || d->sector > 6u) {
        fail("sector outside 1..6", period_no);
    }
}

void foc_port_pwm_enable(void)
{
    if (port.latch == 0u) {
        port.bridge = BRIDGE_PWM;
    }
}

void foc_port_pwm_enable_at_half(void)
{
    foc_port_pwm_enable();
}

void foc_port_pwm_disable(void)
{
    port.bridge = BRIDGE_OFF;
}

void foc_port_low_sides_on(void)
{
    if (port.latch == 0u) {
        port.bridge = BRIDGE_LOW;
    }
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
    if (port.trip_input == 0u) {
        port.latch = 0;
    }
}

void foc_port_debug_out(q15_t ch1, q15_t ch2)
{
    (void)ch1;
    (void)ch2;
}

uint32_t foc_port_timestamp(void)
{
    return period_no;
}

/* ---------------------------------------------------------- the oracle -- */

static unsigned popcount16(uint16_t v)
{
    unsigned n = 0;
    for (; v != 0u; v = (uint16_t)(v & (v - 1u))) {
        n++;
    }
    return n;
}

static void check_invariants(const foc_ctrl_t *c)
{
    if ((unsigned)c->state > (unsigned)FOC_STATE_LAST) {
        fail("state outside the state machine", period_no);
    }
    if ((c->faults.active != 0u) != (c->state == FOC_STATE_FAULT)) {
        fail("FAULT state and active faults disagree", period_no);
    }
    if (c->faults.active == 0u ? c->faults.first != 0u
                               : (popcount16(c->faults.first) != 1u ||
                                  (c->faults.first & c->faults.active) == 0u)) {
        fail("faults.first is not one of the active faults", period_no);
    }
    if (c->state == FOC_STATE_FAULT && port.bridge != BRIDGE_OFF) {
        fail("bridge on in FAULT", period_no);
    }
    const int32_t limit = FOC_I_Q15(CURRENT_LIMIT_A);
    const foc_dq_t *refs[2] = { &c->i_ref, &c->i_ref_slewed };
    for (unsigned k = 0; k < 2u; k++) {
        if ((int32_t)refs[k]->d * refs[k]->d + (int32_t)refs[k]->q * refs[k]->q > limit * limit) {
            fail(k == 0u ? "current reference beyond CURRENT_LIMIT_A"
                         : "slewed current reference beyond CURRENT_LIMIT_A",
                 period_no);
        }
    }
    if (c->req.speed > FOC_MAX_SPEED || c->req.speed < -FOC_MAX_SPEED) {
        fail("speed command beyond MOTOR_MAX_SPEED_RPM", period_no);
    }
    if (c->est.kind != FOC_EST_SENSORED && c->req.speed != 0 &&
        foc_abs_q15(c->req.speed) < c->opt.min_speed) {
        fail("sensorless speed command below SENSORLESS_MIN_SPEED_RPM", period_no);
    }
}

static q15_t overvoltage_trip(const foc_ctrl_t *c)
{
    return c->protection.resistor_enabled != 0u ? FOC_OVERVOLTAGE_HARD : FOC_OVERVOLTAGE;
}

/* The causes present in these samples (config.h thresholds). */
static uint16_t causes_present(const foc_ctrl_t *c, const foc_samples_t *s)
{
    uint16_t f = 0;
    if (s->vdc >= overvoltage_trip(c)) {
        f |= (uint16_t)FOC_FAULT_OVERVOLTAGE;
    }
    if (s->vdc <= FOC_UNDERVOLTAGE) {
        f |= (uint16_t)FOC_FAULT_UNDERVOLTAGE;
    }
    if (s->temp >= FOC_OVERTEMP) {
        f |= (uint16_t)FOC_FAULT_OVERTEMP;
    }
    return f;
}

/* 1 if a cleared fault's cause may count as gone (with hysteresis). */
static int cause_gone(const foc_ctrl_t *c, uint16_t bit, const foc_samples_t *s)
{
    switch (bit) {
    case FOC_FAULT_OVERVOLTAGE:
        return s->vdc < (q15_t)(overvoltage_trip(c) - (FOC_OVERVOLTAGE - FOC_OVERVOLTAGE_CLEAR));
    case FOC_FAULT_UNDERVOLTAGE:
        return s->vdc > FOC_UNDERVOLTAGE_CLEAR;
    case FOC_FAULT_OVERTEMP:
        return s->temp < FOC_OVERTEMP_CLEAR;
    default:
        return 1;
    }
}

static void check_fault_change(const foc_ctrl_t *c, uint16_t before, int slow, int ack_pending)
{
    const uint16_t lost = (uint16_t)(before & (uint16_t)~c->faults.active);
    if (lost == 0u) {
        return;
    }
    if (!slow || !ack_pending) {
        fail("a fault cleared without an acknowledge", period_no);
    }
    if (c->faults.active != 0u) {
        fail("faults cleared only in part", period_no);
    }
    if (port.latch != 0u) {
        fail("OVERCURRENT cleared while the hardware latch is set", period_no);
    }
    for (uint16_t bit = 1u; bit != 0u; bit = (uint16_t)(bit << 1)) {
        if ((lost & bit) != 0u && !cause_gone(c, bit, &c->samples)) {
            fail("a fault cleared while its cause is present", period_no);
        }
    }
}

/* -------------------------------------------------------------- input -- */

static int16_t get16(const uint8_t *p)
{
    return (int16_t)(uint16_t)((uint16_t)p[0] | (uint16_t)(p[1] << 8));
}

static const uint8_t phase_sets[4] = {
    FOC_PHASE_A | FOC_PHASE_B, FOC_PHASE_B | FOC_PHASE_C, FOC_PHASE_A | FOC_PHASE_C,
    FOC_PHASE_A | FOC_PHASE_B | FOC_PHASE_C,
};

/* Header: [0] estimator (mod 4; kept as foc_init chose it if not built),
 * [1] field-weakening mode (mod 3), [2] stop mode (mod 3), [3] bit 0
 * brake resistor enabled, bit 1 sensored start; [4..7] unused. */
static void decode_header(const uint8_t *h, foc_ctrl_t *c)
{
    (void)foc_est_select(&c->est, (foc_est_kind_t)(h[0] % 4u));
    c->fw.mode = (uint8_t)(h[1] % 3u);
    c->opt.stop_mode = (foc_stop_mode_t)(h[2] % 3u);
    c->protection.resistor_enabled = (uint8_t)(h[3] & 1u);
    c->opt.sensored_start = (uint8_t)((h[3] >> 1) & 1u);
}

/* Record: [0..5] i_a, i_b, i_c (any int16), [6..7] vdc, [8..9] temp (the
 * low 15 bits: >= 0), [10..11] theta_sensor, [12] bits 0-1 the valid phases
 * (AB, BC, AC, ABC), bit 2 over-current input, bit 3 start, bit 4 stop,
 * bit 5 acknowledge, bit 6 speed command, bit 7 the sensor angle advances
 * by the speed command each period; [13] repeat: the record lasts
 * 1 + [13] periods (commands on the first only); [14..15] speed command. */
typedef struct {
    foc_samples_t s;
    uint8_t ctl;
    unsigned repeat;
    q15_t speed;
} record_t;

static void decode_record(const uint8_t *p, record_t *r)
{
    r->s.i_a = get16(p);
    r->s.i_b = get16(p + 2);
    r->s.i_c = get16(p + 4);
    r->s.vdc = (q15_t)(get16(p + 6) & 0x7FFF);
    r->s.temp = (q15_t)(get16(p + 8) & 0x7FFF);
    r->s.pot = (q15_t)(get16(p + 4) & 0x7FFF);
    r->s.theta_sensor = (uint16_t)get16(p + 10);
    r->s.phases = phase_sets[p[12] & 3u];
    r->ctl = p[12];
    r->repeat = 1u + p[13];
    r->speed = get16(p + 14);
}

static foc_ctrl_t ctrl;

/* FUZZ_TRACE=1 in the environment: state changes on stderr (to check what
 * an input reaches). */
static int trace = -1;

static void trace_state(const foc_ctrl_t *c, foc_state_t *last, unsigned period)
{
    if (trace && c->state != *last) {
        fprintf(stderr, "  period %u: %s -> %s (faults 0x%x)\n", period, foc_state_name(*last),
                foc_state_name(c->state), (unsigned)c->faults.active);
        *last = c->state;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < HEADER_BYTES) {
        return 0;
    }
    if (trace < 0) {
        trace = getenv("FUZZ_TRACE") != NULL;
    }
    memset(&port, 0, sizeof port);
    period_no = 0;
    foc_ctrl_t *const c = &ctrl;
    foc_init(c);
    decode_header(data, c);
    check_invariants(c);
    foc_state_t last = c->state;

    unsigned period = 0;
    for (size_t off = HEADER_BYTES; off + RECORD_BYTES <= size; off += RECORD_BYTES) {
        record_t r;
        decode_record(data + off, &r);
        for (unsigned k = 0; k < r.repeat && period < MAX_PERIODS; k++, period++) {
            period_no = period;
            if (k == 0u) {
                if (r.ctl & 0x08u) {
                    foc_cmd_start(c);
                }
                if (r.ctl & 0x10u) {
                    foc_cmd_stop(c);
                }
                if (r.ctl & 0x20u) {
                    foc_cmd_ack(c);
                }
                if (r.ctl & 0x40u) {
                    foc_cmd_speed(c, r.speed);
                }
            } else if (r.ctl & 0x80u) {
                r.s.theta_sensor = (uint16_t)(r.s.theta_sensor + (uint16_t)(r.speed / 64));
            }
            port.samples = r.s;
            port.trip_input = (uint8_t)((r.ctl >> 2) & 1u);

            uint16_t before = c->faults.active;
            foc_fast_step(c);
            check_invariants(c);
            check_fault_change(c, before, 0, 0);
            if (port.latched_at_read != 0u &&
                (c->faults.active & (uint16_t)FOC_FAULT_OVERCURRENT) == 0u) {
                fail("hardware over-current latch without OVERCURRENT", period);
            }

            if (period % CONTROL_SLOW_DIVIDER == 0u) {
                const int ack = c->req.asked.ack != c->seen.ack;
                const int was_fault = c->state == FOC_STATE_FAULT;
                before = c->faults.active;
                foc_slow_step(c);
                check_invariants(c);
                check_fault_change(c, before, 1, ack);
                const uint16_t causes = causes_present(c, &c->samples);
                if (causes != 0u) {
                    if (c->state != FOC_STATE_FAULT) {
                        fail("bus/temperature beyond its trip level, not in FAULT", period);
                    }
                    if (!was_fault && (c->faults.active & causes) != causes) {
                        fail("bus/temperature fault not latched", period);
                    }
                }
            }
            trace_state(c, &last, period);
        }
    }
    return 0;
}
