/* Recorded control frames: see bench_io.h.  Portable C99, no library calls
 * (it runs in the Cortex-M3 bench image too). */
#include "bench_io.h"
#include "foc/config.h"

uint16_t bench_get16(const uint8_t *p)
{
    return (uint16_t)((uint16_t)p[0] | (uint16_t)((uint16_t)p[1] << 8));
}

uint32_t bench_get32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
           ((uint32_t)p[3] << 24);
}

void bench_put16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)(v >> 8);
}

void bench_put32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)((v >> 8) & 0xFFu);
    p[2] = (uint8_t)((v >> 16) & 0xFFu);
    p[3] = (uint8_t)(v >> 24);
}

static q15_t get_q15(const uint8_t *p)
{
    return (q15_t)(int16_t)bench_get16(p);
}

static void put_q15(uint8_t *p, q15_t v)
{
    bench_put16(p, (uint16_t)v);
}

int bench_file_open(bench_file_t *f, const uint8_t *data, uint32_t len)
{
    static const char magic[8] = { 'F', 'O', 'C', 'B', 'N', 'C', 'H', '1' };
    if (len < BENCH_HEADER_BYTES) {
        return -1;
    }
    for (uint32_t i = 0; i < 8u; i++) {
        if (data[i] != (uint8_t)magic[i]) {
            return -1;
        }
    }
    f->data = data;
    f->len = len;
    f->frame_count = bench_get32(data + 8);
    f->scenario_count = bench_get32(data + 12);
    if (bench_get32(data + 16) != BENCH_FRAME_BYTES ||
        bench_get32(data + 20) != (uint32_t)CONTROL_SLOW_DIVIDER) {
        return -1;
    }
    if (f->scenario_count > 32u || f->frame_count > 10000000u) {
        return -1;
    }
    const uint32_t table = BENCH_HEADER_BYTES + f->scenario_count * BENCH_SCENARIO_BYTES;
    if (len != table + f->frame_count * BENCH_FRAME_BYTES) {
        return -1;
    }
    f->frames = data + table;
    /* Scenarios back to back, each frame tagged with its own, the first
     * one of each (only) marked as a reset. */
    uint32_t next = 0;
    for (uint32_t i = 0; i < f->scenario_count; i++) {
        bench_scenario_t s;
        bench_scenario_get(f, i, &s);
        if (s.first_frame != next || s.frame_count == 0u ||
            s.frame_count > f->frame_count - s.first_frame) {
            return -1;
        }
        for (uint32_t k = s.first_frame; k < s.first_frame + s.frame_count; k++) {
            const uint8_t *p = f->frames + k * BENCH_FRAME_BYTES;
            const uint8_t reset = (uint8_t)((p[15] & BENCH_F_RESET) != 0u);
            if (bench_get16(p + 18) != i || reset != (uint8_t)(k == s.first_frame)) {
                return -1;
            }
        }
        next = s.first_frame + s.frame_count;
    }
    if (next != f->frame_count) {
        return -1;
    }
    return 0;
}

void bench_scenario_get(const bench_file_t *f, uint32_t i, bench_scenario_t *s)
{
    const uint8_t *p = f->data + BENCH_HEADER_BYTES + i * BENCH_SCENARIO_BYTES;
    for (uint32_t k = 0; k < BENCH_NAME_BYTES; k++) {
        s->name[k] = (char)p[k];
    }
    s->name[BENCH_NAME_BYTES - 1u] = '\0';
    s->first_frame = bench_get32(p + 32);
    s->frame_count = bench_get32(p + 36);
    s->estimator = p[40];
    s->fw_mode = p[41];
    s->stop_mode = p[42];
    s->brake_resistor = p[43];
    s->sensored_start = p[44];
    s->open_loop_only = p[45];
    s->tuning = p[46];
    s->shunts = p[47];
}

void bench_in_get(const bench_file_t *f, uint32_t i, bench_in_t *in)
{
    const uint8_t *p = f->frames + i * BENCH_FRAME_BYTES;
    in->samples.i_a = get_q15(p + 0);
    in->samples.i_b = get_q15(p + 2);
    in->samples.i_c = get_q15(p + 4);
    in->samples.vdc = get_q15(p + 6);
    in->samples.temp = get_q15(p + 8);
    in->samples.pot = get_q15(p + 10);
    in->samples.theta_sensor = bench_get16(p + 12);
    in->samples.phases = p[14];
    in->flags = p[15];
    in->speed_cmd = get_q15(p + 16);
    in->scenario = bench_get16(p + 18);
}

const uint8_t *bench_expected(const bench_file_t *f, uint32_t i)
{
    return f->frames + i * BENCH_FRAME_BYTES + BENCH_IN_BYTES;
}

void bench_scenario_from_ctrl(bench_scenario_t *s, const foc_ctrl_t *c)
{
    s->estimator = (uint8_t)c->est.kind;
    s->fw_mode = (uint8_t)c->fw.mode;
    s->stop_mode = (uint8_t)c->opt.stop_mode;
    s->brake_resistor = c->protection.resistor_enabled;
    s->sensored_start = c->opt.sensored_start;
    s->open_loop_only = c->opt.open_loop_only;
    s->tuning = c->opt.tuning;
}

int bench_scenario_apply(const bench_scenario_t *s, foc_ctrl_t *c)
{
    if (foc_est_select(&c->est, (foc_est_kind_t)s->estimator) != 0) {
        return -1;
    }
    c->fw.mode = s->fw_mode;
    c->opt.stop_mode = (foc_stop_mode_t)s->stop_mode;
    c->protection.resistor_enabled = s->brake_resistor;
    c->opt.sensored_start = s->sensored_start;
    c->opt.open_loop_only = s->open_loop_only;
    c->opt.tuning = s->tuning;
    return 0;
}

void bench_out_from(bench_out_t *o, const foc_ctrl_t *c, const bench_port_t *p)
{
    o->duty_a = p->duty.a;
    o->duty_b = p->duty.b;
    o->duty_c = p->duty.c;
    o->sector = p->duty.sector;
    o->port = (uint8_t)(p->bridge | (uint8_t)(p->brake << 2) | (uint8_t)(p->latch << 3));
    o->state = (uint8_t)c->state;
    o->set_count = p->set_count;
    o->faults_active = c->faults.active;
    o->faults_first = c->faults.first;
    o->theta = c->est.theta;
    o->speed = c->est.speed;
    o->id_ref = c->i_ref.d;
    o->iq_ref = c->i_ref.q;
    o->vd = c->v_dq.d;
    o->vq = c->v_dq.q;
    o->debug1 = p->debug[0];
    o->debug2 = p->debug[1];
}

void bench_out_encode(const bench_out_t *o, uint8_t buf[BENCH_OUT_BYTES])
{
    put_q15(buf + 0, o->duty_a);
    put_q15(buf + 2, o->duty_b);
    put_q15(buf + 4, o->duty_c);
    buf[6] = o->sector;
    buf[7] = o->port;
    buf[8] = o->state;
    buf[9] = o->set_count;
    bench_put16(buf + 10, o->faults_active);
    bench_put16(buf + 12, o->faults_first);
    bench_put16(buf + 14, o->theta);
    put_q15(buf + 16, o->speed);
    put_q15(buf + 18, o->id_ref);
    put_q15(buf + 20, o->iq_ref);
    put_q15(buf + 22, o->vd);
    put_q15(buf + 24, o->vq);
    put_q15(buf + 26, o->debug1);
    put_q15(buf + 28, o->debug2);
    bench_put16(buf + 30, 0u);
}

uint8_t bench_same(const uint8_t *a, const uint8_t *b, uint32_t n)
{
    uint8_t diff = 0;
    for (uint32_t i = 0; i < n; i++) {
        diff = (uint8_t)(diff | (uint8_t)(a[i] ^ b[i]));
    }
    return (uint8_t)(diff == 0u);
}

uint32_t bench_hash(uint32_t h, const uint8_t *buf, uint32_t len)
{
    for (uint32_t i = 0; i < len; i++) {
        h ^= buf[i];
        h *= 16777619u;
    }
    return h;
}
