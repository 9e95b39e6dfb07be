/*
 * bench_record: runs focsim scenarios (the real core against the motor
 * model, through the host port) and records, per PWM period, everything
 * that crossed the core's boundary, into a frame file (bench_io.h):
 *
 *   bench_record [-v] <scenario dir> <out.bin>     (-v: state changes)
 *
 * How it sees the boundary: the executable is linked with GNU ld's --wrap
 * for the core's entry points (foc_fast_step, foc_slow_step, foc_cmd_*) and
 * for the port functions the core calls (tools/bench/CMakeLists.txt), so
 * every call goes through a __wrap_ function here that notes it and calls
 * the real one.  A frame is one foc_fast_step call: the commands issued
 * before it, the samples the port delivered to it, the state of the
 * hardware over-current latch after that read, whether foc_slow_step ran
 * after it; and after the period the outputs (bench_out_t: the duties and
 * bridge state the port was given, state, faults, angle, speed, references).
 *
 * The scenarios (table below) cover start-up (alignment, open loop,
 * hand-over), RUN on every estimator, field weakening, stop, and faults
 * with acknowledge and restart; the first one is the benchmark's target
 * configuration (PLL estimator with field weakening, three shunts).
 * Each is checked to have done what it is for (reached RUN, field
 * weakening active, fault latched and cleared...), so that the benchmark
 * cannot silently measure something else.  Exit status 0, or 1 with a
 * message.
 *
 * Three-shunt emulation: the host port reads fixed phases (A and B); for a
 * three-shunt scenario the recorder sets host_port()->phases before each
 * period as a three-shunt board would: all three phases when the bridge is
 * off or no duty exceeds BENCH_3SH_MAX_DUTY, else the two phases other than
 * the one with the largest duty (its low-side pulse is too short).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_io.h"
#include "foc/config.h"
#include "host_port.h"
#include "sim.h"

#define BENCH_3SH_MAX_DUTY 29491 /* 90 % of the period */
#define MAX_SCENARIOS 16

/* What each scenario must show in its recording. */
#define EXPECT_RUN 0x1u       /* reaches RUN */
#define EXPECT_FW 0x2u        /* negative Id reference (field weakening) */
#define EXPECT_FAULT 0x4u     /* enters FAULT, is acknowledged, RUNs again */
#define EXPECT_STARTUP 0x8u   /* goes through ALIGN and OPENLOOP */
#define EXPECT_IDLE_END 0x10u /* ends in IDLE (stopped cleanly) */

typedef struct {
    const char *name;
    const char *file;       /* in the scenario dir */
    const char *estimator;  /* sim_estimator_from_name */
    const char *fw_mode;    /* sim_fw_mode_from_name, NULL: userparms.h */
    int shunts;             /* 2: host port's A+B; 3: emulated 3-shunt */
    int sensored_start;
    unsigned expect;
} spec_t;

static const spec_t specs[] = {
    /* The benchmark's target configuration: first. */
    { "pll_fw_3shunt", "pll_fw.scn", "pll", "voltage", 3, 0,
      EXPECT_RUN | EXPECT_FW | EXPECT_STARTUP | EXPECT_IDLE_END },
    { "luenberger_3shunt", "run.scn", "luenberger", NULL, 3, 0,
      EXPECT_RUN | EXPECT_STARTUP | EXPECT_IDLE_END },
    { "flux_3shunt", "run.scn", "flux", NULL, 3, 0,
      EXPECT_RUN | EXPECT_STARTUP | EXPECT_IDLE_END },
    { "sensored_2shunt", "run.scn", "sensored", NULL, 2, 0,
      EXPECT_RUN | EXPECT_IDLE_END },
    { "pll_faults_fwtable_2shunt", "faults.scn", "pll", "table", 2, 0,
      EXPECT_RUN | EXPECT_FAULT },
};

/* ----------------------------------------------- the wrapped boundary -- */

void __real_foc_fast_step(foc_ctrl_t *c);
void __real_foc_slow_step(foc_ctrl_t *c);
void __real_foc_cmd_start(foc_ctrl_t *c);
void __real_foc_cmd_stop(foc_ctrl_t *c);
void __real_foc_cmd_ack(foc_ctrl_t *c);
void __real_foc_cmd_speed(foc_ctrl_t *c, q15_t speed);
void __real_foc_port_read_samples(foc_samples_t *s);
void __real_foc_port_set_duties(const foc_duty_t *d);
void __real_foc_port_pwm_enable(void);
void __real_foc_port_pwm_enable_at_half(void);
void __real_foc_port_pwm_disable(void);
void __real_foc_port_low_sides_on(void);
void __real_foc_port_brake_resistor(uint8_t on);
uint8_t __real_foc_port_overcurrent_latched(void);
void __real_foc_port_overcurrent_clear(void);
void __real_foc_port_debug_out(q15_t ch1, q15_t ch2);

void __wrap_foc_fast_step(foc_ctrl_t *c);
void __wrap_foc_slow_step(foc_ctrl_t *c);
void __wrap_foc_cmd_start(foc_ctrl_t *c);
void __wrap_foc_cmd_stop(foc_ctrl_t *c);
void __wrap_foc_cmd_ack(foc_ctrl_t *c);
void __wrap_foc_cmd_speed(foc_ctrl_t *c, q15_t speed);
void __wrap_foc_port_read_samples(foc_samples_t *s);
void __wrap_foc_port_set_duties(const foc_duty_t *d);
void __wrap_foc_port_pwm_enable(void);
void __wrap_foc_port_pwm_enable_at_half(void);
void __wrap_foc_port_pwm_disable(void);
void __wrap_foc_port_low_sides_on(void);
void __wrap_foc_port_brake_resistor(uint8_t on);
uint8_t __wrap_foc_port_overcurrent_latched(void);
void __wrap_foc_port_overcurrent_clear(void);
void __wrap_foc_port_debug_out(q15_t ch1, q15_t ch2);

static struct {
    bench_port_t port;      /* the port state as the replay port tracks it */
    uint8_t pending_flags;  /* commands since the last fast step */
    q15_t pending_speed;
    int in_period;          /* a fast step ran and the period is not closed */
    bench_in_t in;          /* the present period's inputs */
} rec;

static void die(const char *what)
{
    fprintf(stderr, "bench_record: %s\n", what);
    exit(1);
}

static void command(uint8_t flag)
{
    if (rec.in_period) {
        die("a command between the fast and the slow step cannot be replayed");
    }
    rec.pending_flags = (uint8_t)(rec.pending_flags | flag);
}

void __wrap_foc_cmd_start(foc_ctrl_t *c)
{
    command(BENCH_F_START);
    __real_foc_cmd_start(c);
}

void __wrap_foc_cmd_stop(foc_ctrl_t *c)
{
    command(BENCH_F_STOP);
    __real_foc_cmd_stop(c);
}

void __wrap_foc_cmd_ack(foc_ctrl_t *c)
{
    command(BENCH_F_ACK);
    __real_foc_cmd_ack(c);
}

void __wrap_foc_cmd_speed(foc_ctrl_t *c, q15_t speed)
{
    command(BENCH_F_SPEED);
    rec.pending_speed = speed;
    __real_foc_cmd_speed(c, speed);
}

void __wrap_foc_fast_step(foc_ctrl_t *c)
{
    if (rec.in_period) {
        die("two fast steps in one period");
    }
    rec.in.flags = (uint8_t)(rec.in.flags | rec.pending_flags);
    rec.in.speed_cmd = (rec.pending_flags & BENCH_F_SPEED) != 0u ? rec.pending_speed : 0;
    rec.pending_flags = 0;
    rec.in_period = 1;
    __real_foc_fast_step(c);
}

void __wrap_foc_slow_step(foc_ctrl_t *c)
{
    if (!rec.in_period || (rec.in.flags & BENCH_F_SLOW) != 0u) {
        die("a slow step not right after a fast step");
    }
    rec.in.flags = (uint8_t)(rec.in.flags | BENCH_F_SLOW);
    __real_foc_slow_step(c);
}

void __wrap_foc_port_read_samples(foc_samples_t *s)
{
    __real_foc_port_read_samples(s);
    rec.in.samples = *s;
    const uint8_t latch = host_port()->overcurrent_latch;
    if (latch) {
        rec.in.flags = (uint8_t)(rec.in.flags | BENCH_F_OC);
    }
    bench_port_new_period(&rec.port, latch);
}

void __wrap_foc_port_set_duties(const foc_duty_t *d)
{
    bench_port_set_duties(&rec.port, d);
    __real_foc_port_set_duties(d);
}

void __wrap_foc_port_pwm_enable(void)
{
    bench_port_pwm_enable(&rec.port);
    __real_foc_port_pwm_enable();
}

void __wrap_foc_port_pwm_enable_at_half(void)
{
    bench_port_pwm_enable(&rec.port);
    __real_foc_port_pwm_enable_at_half();
}

void __wrap_foc_port_pwm_disable(void)
{
    bench_port_pwm_disable(&rec.port);
    __real_foc_port_pwm_disable();
}

void __wrap_foc_port_low_sides_on(void)
{
    bench_port_low_sides_on(&rec.port);
    __real_foc_port_low_sides_on();
}

void __wrap_foc_port_brake_resistor(uint8_t on)
{
    rec.port.brake = (uint8_t)(on != 0u);
    __real_foc_port_brake_resistor(on);
}

uint8_t __wrap_foc_port_overcurrent_latched(void)
{
    const uint8_t v = __real_foc_port_overcurrent_latched();
    if (v != rec.port.latch) {
        die("host port latch differs from the replay model");
    }
    return v;
}

void __wrap_foc_port_overcurrent_clear(void)
{
    __real_foc_port_overcurrent_clear();
    rec.port.latch = 0;
    if (host_port()->overcurrent_latch != 0u) {
        die("host port kept its latch on clear: not replayable");
    }
}

void __wrap_foc_port_debug_out(q15_t ch1, q15_t ch2)
{
    rec.port.debug[0] = ch1;
    rec.port.debug[1] = ch2;
    __real_foc_port_debug_out(ch1, ch2);
}

/* ------------------------------------------------------------ output -- */

typedef struct {
    uint8_t *data;
    size_t len, cap;
} buf_t;

static void buf_add(buf_t *b, const uint8_t *p, size_t n)
{
    if (b->len + n > b->cap) {
        b->cap = (b->len + n) * 2u;
        b->data = realloc(b->data, b->cap);
        if (b->data == NULL) {
            die("out of memory");
        }
    }
    memcpy(b->data + b->len, p, n);
    b->len += n;
}

static void encode_in(const bench_in_t *in, uint8_t p[BENCH_IN_BYTES])
{
    bench_put16(p + 0, (uint16_t)in->samples.i_a);
    bench_put16(p + 2, (uint16_t)in->samples.i_b);
    bench_put16(p + 4, (uint16_t)in->samples.i_c);
    bench_put16(p + 6, (uint16_t)in->samples.vdc);
    bench_put16(p + 8, (uint16_t)in->samples.temp);
    bench_put16(p + 10, (uint16_t)in->samples.pot);
    bench_put16(p + 12, in->samples.theta_sensor);
    p[14] = in->samples.phases;
    p[15] = in->flags;
    bench_put16(p + 16, (uint16_t)in->speed_cmd);
    bench_put16(p + 18, in->scenario);
}

static uint8_t three_shunt_phases(const bench_port_t *p)
{
    const uint8_t all = FOC_PHASE_A | FOC_PHASE_B | FOC_PHASE_C;
    if (p->bridge != BENCH_BRIDGE_PWM) {
        return all;
    }
    const foc_duty_t d = p->duty;
    if (d.a >= d.b && d.a >= d.c) {
        return d.a > BENCH_3SH_MAX_DUTY ? (uint8_t)(FOC_PHASE_B | FOC_PHASE_C) : all;
    }
    if (d.b >= d.c) {
        return d.b > BENCH_3SH_MAX_DUTY ? (uint8_t)(FOC_PHASE_A | FOC_PHASE_C) : all;
    }
    return d.c > BENCH_3SH_MAX_DUTY ? (uint8_t)(FOC_PHASE_A | FOC_PHASE_B) : all;
}

typedef struct {
    unsigned seen_states;   /* bit per foc_state_t */
    int fault_then_run;     /* RUN after a FAULT was acknowledged */
    int min_id_ref;
    unsigned phase_sets;    /* bit per `phases` value used */
    foc_state_t final_state;
} summary_t;

static int verbose;

static int record(const char *dir, const spec_t *sp, uint16_t index, buf_t *frames,
                  uint32_t first_frame, bench_scenario_t *sc, summary_t *sum)
{
    char path[1024], err[256];
    snprintf(path, sizeof path, "%s/%s", dir, sp->file);
    scn_t scn;
    if (scn_parse_file(path, &scn, err, sizeof err) != 0) {
        fprintf(stderr, "bench_record: %s\n", err);
        return -1;
    }
    sim_options_t o;
    sim_default_options(&o);
    if (sim_estimator_from_name(sp->estimator, &o.estimator) != 0 ||
        (sp->fw_mode != NULL && sim_fw_mode_from_name(sp->fw_mode, &o.fw_mode) != 0)) {
        fprintf(stderr, "bench_record: %s: bad estimator or fw mode\n", sp->name);
        scn_free(&scn);
        return -1;
    }
    o.sensored_start = sp->sensored_start;

    static sim_t sim; /* large: not on the stack */
    memset(&rec, 0, sizeof rec);
    bench_port_reset(&rec.port);
    if (sim_init(&sim, &o, &scn, err, sizeof err) != 0) {
        fprintf(stderr, "bench_record: %s: %s\n", sp->name, err);
        scn_free(&scn);
        return -1;
    }
    memset(sc, 0, sizeof *sc);
    snprintf(sc->name, sizeof sc->name, "%s", sp->name);
    sc->first_frame = first_frame;
    bench_scenario_from_ctrl(sc, &sim.ctrl);
    sc->shunts = (uint8_t)sp->shunts;

    memset(sum, 0, sizeof *sum);
    uint32_t n = 0;
    int fault_acked = 0;
    for (;;) {
        if (sp->shunts == 3) {
            host_port()->phases = three_shunt_phases(&rec.port);
        }
        memset(&rec.in, 0, sizeof rec.in);
        rec.in.scenario = index;
        rec.in.flags = (uint8_t)(n == 0u ? BENCH_F_RESET : 0u);
        rec.in_period = 0;
        sim_row_t row;
        if (!sim_step(&sim, &row)) {
            break;
        }
        if (!rec.in_period) {
            die("a period without a fast step");
        }
        rec.in_period = 0;

        bench_out_t out;
        uint8_t p[BENCH_FRAME_BYTES];
        bench_out_from(&out, &sim.ctrl, &rec.port);
        encode_in(&rec.in, p);
        bench_out_encode(&out, p + BENCH_IN_BYTES);
        buf_add(frames, p, sizeof p);
        n++;

        const foc_state_t st = sim.ctrl.state;
        if (verbose && (n == 1u || st != sum->final_state)) {
            printf("  %-26s t=%.4f %s fault=%s speed=%.0f rpm (est %.0f)\n", sp->name,
                   row.t_s, foc_state_name(st), foc_fault_name(sim.ctrl.faults.first),
                   row.speed_rpm, row.speed_est_rpm);
        }
        if ((unsigned)st < 32u) {
            sum->seen_states |= 1u << (unsigned)st;
        }
        if ((sum->seen_states & (1u << FOC_STATE_FAULT)) != 0u &&
            (rec.in.flags & BENCH_F_ACK) != 0u) {
            fault_acked = 1;
        }
        if (fault_acked && st == FOC_STATE_RUN) {
            sum->fault_then_run = 1;
        }
        if (sim.ctrl.i_ref.d < sum->min_id_ref) {
            sum->min_id_ref = sim.ctrl.i_ref.d;
        }
        sum->phase_sets |= 1u << (rec.in.samples.phases & 7u);
        sum->final_state = st;
    }
    sc->frame_count = n;
    scn_free(&scn);
    return 0;
}

static int check_expectations(const spec_t *sp, const summary_t *s)
{
    int ok = 1;
    if ((sp->expect & EXPECT_RUN) && !(s->seen_states & (1u << FOC_STATE_RUN))) {
        fprintf(stderr, "bench_record: %s: never reached RUN\n", sp->name);
        ok = 0;
    }
    if ((sp->expect & EXPECT_STARTUP) &&
        (!(s->seen_states & (1u << FOC_STATE_ALIGN)) ||
         !(s->seen_states & (1u << FOC_STATE_OPENLOOP)))) {
        fprintf(stderr, "bench_record: %s: no ALIGN/OPENLOOP start-up\n", sp->name);
        ok = 0;
    }
    if ((sp->expect & EXPECT_FW) && s->min_id_ref >= 0) {
        fprintf(stderr, "bench_record: %s: field weakening never active\n", sp->name);
        ok = 0;
    }
    if ((sp->expect & EXPECT_FAULT) && !s->fault_then_run) {
        fprintf(stderr, "bench_record: %s: no fault, acknowledge and restart\n", sp->name);
        ok = 0;
    }
    if ((sp->expect & EXPECT_IDLE_END) && s->final_state != FOC_STATE_IDLE) {
        fprintf(stderr, "bench_record: %s: ends in %s, not IDLE\n", sp->name,
                foc_state_name(s->final_state));
        ok = 0;
    }
    if (sp->shunts == 3 && !(s->phase_sets & (1u << 7))) {
        fprintf(stderr, "bench_record: %s: three-shunt emulation never read 3 phases\n",
                sp->name);
        ok = 0;
    }
    return ok ? 0 : -1;
}

int main(int argc, char **argv)
{
    if (argc == 4 && strcmp(argv[1], "-v") == 0) {
        verbose = 1;
        argv++;
        argc--;
    }
    if (argc != 3) {
        fprintf(stderr, "usage: bench_record [-v] <scenario dir> <out.bin>\n");
        return 1;
    }
    const size_t count = sizeof specs / sizeof specs[0];
    if (count > MAX_SCENARIOS) {
        die("too many scenarios");
    }
    bench_scenario_t sc[MAX_SCENARIOS];
    buf_t frames = { NULL, 0, 0 };
    uint32_t total = 0;
    int failed = 0;
    for (size_t i = 0; i < count; i++) {
        summary_t sum;
        if (record(argv[1], &specs[i], (uint16_t)i, &frames, total, &sc[i], &sum) != 0) {
            return 1;
        }
        if (check_expectations(&specs[i], &sum) != 0) {
            failed = 1;
        }
        printf("bench_record: %-26s %6u frames  est=%s fw=%u shunts=%d states=0x%02x "
               "min_id_ref=%d end=%s\n",
               sc[i].name, (unsigned)sc[i].frame_count, specs[i].estimator,
               (unsigned)sc[i].fw_mode, specs[i].shunts, sum.seen_states, sum.min_id_ref,
               foc_state_name(sum.final_state));
        total += sc[i].frame_count;
    }
    if (failed) {
        return 1;
    }

    buf_t out = { NULL, 0, 0 };
    uint8_t h[BENCH_HEADER_BYTES];
    memset(h, 0, sizeof h);
    memcpy(h, "FOCBNCH1", 8);
    bench_put32(h + 8, total);
    bench_put32(h + 12, (uint32_t)count);
    bench_put32(h + 16, BENCH_FRAME_BYTES);
    bench_put32(h + 20, (uint32_t)CONTROL_SLOW_DIVIDER);
    bench_put32(h + 24, (uint32_t)(PWM_FREQUENCY_HZ + 0.5));
    buf_add(&out, h, sizeof h);
    for (size_t i = 0; i < count; i++) {
        uint8_t p[BENCH_SCENARIO_BYTES];
        memset(p, 0, sizeof p);
        memcpy(p, sc[i].name, strlen(sc[i].name));
        bench_put32(p + 32, sc[i].first_frame);
        bench_put32(p + 36, sc[i].frame_count);
        p[40] = sc[i].estimator;
        p[41] = sc[i].fw_mode;
        p[42] = sc[i].stop_mode;
        p[43] = sc[i].brake_resistor;
        p[44] = sc[i].sensored_start;
        p[45] = sc[i].open_loop_only;
        p[46] = sc[i].tuning;
        p[47] = sc[i].shunts;
        buf_add(&out, p, sizeof p);
    }
    buf_add(&out, frames.data, frames.len);

    FILE *f = fopen(argv[2], "wb");
    if (f == NULL || fwrite(out.data, 1, out.len, f) != out.len || fclose(f) != 0) {
        fprintf(stderr, "bench_record: cannot write %s\n", argv[2]);
        return 1;
    }
    printf("bench_record: %u frames, %zu bytes -> %s\n", (unsigned)total, out.len, argv[2]);
    free(out.data);
    free(frames.data);
    return 0;
}
