/*
 * Recorded control frames: the file format shared by the recorder (host),
 * the frame-replay port (host and Cortex-M3) and the instruction-set
 * simulator's report (tools/bench/bench.py reads the same layout).
 *
 * All integers little-endian, byte-packed, read and written byte by byte
 * (no struct layout is relied on, so the host and the target agree).
 *
 *   header    BENCH_HEADER_BYTES
 *     0  "FOCBNCH1"
 *     8  u32 frame count       12 u32 scenario count
 *    16  u32 BENCH_FRAME_BYTES 20 u32 CONTROL_SLOW_DIVIDER of the recording
 *    24  u32 PWM frequency, Hz (rounded)       28..63 zero
 *   scenario table, BENCH_SCENARIO_BYTES each
 *     0  name, 32 bytes, NUL-padded
 *    32  u32 first frame       36 u32 frame count
 *    40  u8 estimator (foc_est_kind_t)   41 u8 fw mode   42 u8 stop mode
 *    43  u8 brake resistor enabled  44 u8 sensored start  45 u8 open-loop
 *        only  46 u8 tuning  47 u8 shunts (2 or 3, informative)
 *   frames, BENCH_FRAME_BYTES each: the inputs of one PWM period (what the
 *   port delivered, the commands issued before the fast step, whether the
 *   slow step ran after it) and the outputs expected after the period.
 *     0  i16 i_a  2 i16 i_b  4 i16 i_c  6 i16 vdc  8 i16 temp  10 i16 pot
 *    12  u16 theta_sensor  14 u8 phases  15 u8 flags (BENCH_F_*)
 *    16  i16 speed command (with BENCH_F_SPEED)   18 u16 scenario index
 *    20  outputs, BENCH_OUT_BYTES (bench_out_t, encoded by bench_out_encode)
 */
#ifndef BENCH_IO_H
#define BENCH_IO_H

#include <stdint.h>
#include "foc/controller.h"

#define BENCH_HEADER_BYTES 64u
#define BENCH_SCENARIO_BYTES 48u
#define BENCH_FRAME_BYTES 52u
#define BENCH_IN_BYTES 20u
#define BENCH_OUT_BYTES 32u
#define BENCH_NAME_BYTES 32u

/* Frame flags. */
#define BENCH_F_RESET 0x01u /* first frame of a scenario: controller set up */
#define BENCH_F_OC 0x02u    /* hardware over-current latch set after the read */
#define BENCH_F_START 0x04u
#define BENCH_F_STOP 0x08u
#define BENCH_F_ACK 0x10u
#define BENCH_F_SPEED 0x20u
#define BENCH_F_SLOW 0x40u  /* foc_slow_step ran after foc_fast_step */

/* Bridge as the port drives it (bench_port_t.bridge). */
#define BENCH_BRIDGE_OFF 0u
#define BENCH_BRIDGE_PWM 1u
#define BENCH_BRIDGE_LOW 2u

/* The port-side state the core's calls produce, tracked the same way by
 * the recorder (around the host port) and by the replay port. */
typedef struct {
    foc_duty_t duty;        /* last foc_port_set_duties */
    uint8_t set_count;      /* foc_port_set_duties calls this period */
    uint8_t bridge;         /* BENCH_BRIDGE_* */
    uint8_t brake;          /* brake resistor on */
    uint8_t latch;          /* hardware over-current latch */
    q15_t debug[2];         /* last foc_port_debug_out */
} bench_port_t;

typedef struct {
    foc_samples_t samples;
    uint8_t flags;
    q15_t speed_cmd;
    uint16_t scenario;
} bench_in_t;

/* What is compared after every period. */
typedef struct {
    q15_t duty_a, duty_b, duty_c;
    uint8_t sector;
    uint8_t port;           /* bridge | brake << 2 | latch << 3 */
    uint8_t state;
    uint8_t set_count;
    uint16_t faults_active, faults_first;
    uint16_t theta;
    q15_t speed;
    q15_t id_ref, iq_ref, vd, vq;
    q15_t debug1, debug2;
} bench_out_t;

typedef struct {
    char name[BENCH_NAME_BYTES];
    uint32_t first_frame;
    uint32_t frame_count;
    uint8_t estimator, fw_mode, stop_mode, brake_resistor;
    uint8_t sensored_start, open_loop_only, tuning, shunts;
} bench_scenario_t;

typedef struct {
    const uint8_t *data;
    uint32_t len;
    uint32_t frame_count;
    uint32_t scenario_count;
    const uint8_t *frames;  /* first frame */
} bench_file_t;

/* 0 if `data` is a well-formed frame file recorded with this build's
 * CONTROL_SLOW_DIVIDER; -1 otherwise. */
int bench_file_open(bench_file_t *f, const uint8_t *data, uint32_t len);

void bench_scenario_get(const bench_file_t *f, uint32_t i, bench_scenario_t *s);
void bench_in_get(const bench_file_t *f, uint32_t i, bench_in_t *in);
/* The expected outputs of frame i, as stored (encoded). */
const uint8_t *bench_expected(const bench_file_t *f, uint32_t i);

/* Port model (bench_port.c): reset (bridge off, latch clear) and the
 * effect of each port call the core makes. */
void bench_port_reset(bench_port_t *p);
void bench_port_new_period(bench_port_t *p, uint8_t latch_after_read);
void bench_port_set_duties(bench_port_t *p, const foc_duty_t *d);
void bench_port_pwm_enable(bench_port_t *p);
void bench_port_pwm_disable(bench_port_t *p);
void bench_port_low_sides_on(bench_port_t *p);

/* The controller's configuration a scenario starts from (what the
 * recorder found after sim_init), and applying it after foc_init: 0, or
 * -1 if this core does not contain the scenario's estimator. */
void bench_scenario_from_ctrl(bench_scenario_t *s, const foc_ctrl_t *c);
int bench_scenario_apply(const bench_scenario_t *s, foc_ctrl_t *c);

void bench_out_from(bench_out_t *o, const foc_ctrl_t *c, const bench_port_t *p);
void bench_out_encode(const bench_out_t *o, uint8_t buf[BENCH_OUT_BYTES]);

/* 1 if the n bytes at a and b are equal. */
uint8_t bench_same(const uint8_t *a, const uint8_t *b, uint32_t n);

/* FNV-1a, 32 bits, continued from `h` (start with BENCH_HASH_INIT). */
#define BENCH_HASH_INIT 2166136261u
uint32_t bench_hash(uint32_t h, const uint8_t *buf, uint32_t len);

/* Little-endian helpers. */
uint16_t bench_get16(const uint8_t *p);
uint32_t bench_get32(const uint8_t *p);
void bench_put16(uint8_t *p, uint16_t v);
void bench_put32(uint8_t *p, uint32_t v);

#endif /* BENCH_IO_H */
