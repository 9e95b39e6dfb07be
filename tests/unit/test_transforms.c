/*
 * Clarke, Park and inverse transforms against double-precision references.
 *
 * Limits (LSB of Q15):
 *   ARITH_LSB  1.5  the fixed-point formula against the same formula in
 *                   double on the same integer inputs, saturated like the
 *                   result: round-off 0.5 LSB plus the error of the Q15
 *                   constants (1/sqrt(3) is 0.42 LSB off: up to 0.73 LSB on
 *                   an unsaturated beta; 1/3 up to 1 LSB on a large zero
 *                   sequence);
 *   IDEAL_LSB  3.0  a quantised balanced set / vector against the exact
 *                   waveform it came from: the above plus input rounding and,
 *                   for Park, the 2-LSB sin/cos error.
 */
#include <math.h>
#include <stdint.h>

#include "foc/transforms.h"
#include "testkit.h"

#define PI 3.14159265358979323846
#define SQRT3 1.73205080756887729
#define ARITH_LSB 1.5
#define IDEAL_LSB 3.0

/* Magnitudes (LSB) of the test vectors and balanced sets. */
static const double MAGS[] = { 32767.0, 30000.0, 16384.0, 1000.0, 100.0 };
#define N_MAGS (sizeof MAGS / sizeof MAGS[0])

/* Inputs on a stride over the full Q15 range, with its ends. */
static const int32_t GRID_STEP = 1489;

static double sat(double x)
{
    return fmin(fmax(x, -32768.0), 32767.0);
}

static double angle_rad(uint32_t a)
{
    return a * (PI / 32768.0);
}

static q15_t q(double x)
{
    return (q15_t)lround(sat(x));
}

/* Records the worst |got - want| of a case. */
typedef struct {
    double worst;
} err_t;

static void track(err_t *e, double got, double want)
{
    e->worst = fmax(e->worst, fabs(got - want));
}

static void report(const char *what, const err_t *e, double limit)
{
    printf("%s: max error %.3f LSB (limit %.1f)\n", what, e->worst, limit);
    TK_CHECK(e->worst <= limit, "%s: %.3f LSB > %.1f", what, e->worst, limit);
}

/* Grid values: the stride plus both ends of the range. */
static int32_t grid(int32_t i)
{
    const int32_t v = -32768 + i * GRID_STEP;
    return (v > 32767) ? 32767 : v;
}

#define GRID_N (65535 / 1489 + 2)

static void case_clarke2(void)
{
    err_t arith = { 0 };
    err_t ideal = { 0 };
    for (int32_t i = 0; i < GRID_N; i++) {
        for (int32_t j = 0; j < GRID_N; j++) {
            const q15_t a = (q15_t)grid(i);
            const q15_t b = (q15_t)grid(j);
            const foc_ab_t ab = foc_clarke2_q15(a, b);
            track(&arith, ab.alpha, a);
            track(&arith, ab.beta, sat((a + 2.0 * b) / SQRT3));
        }
    }
    for (size_t m = 0; m < N_MAGS; m++) {
        for (uint32_t t = 0; t < 65536u; t += 3u) {
            const double th = angle_rad(t);
            const q15_t a = q(MAGS[m] * cos(th));
            const q15_t b = q(MAGS[m] * cos(th - 2 * PI / 3));
            const foc_ab_t ab = foc_clarke2_q15(a, b);
            track(&ideal, ab.alpha, MAGS[m] * cos(th));
            track(&ideal, ab.beta, MAGS[m] * sin(th));
        }
    }
    report("clarke2 formula", &arith, ARITH_LSB);
    report("clarke2 balanced", &ideal, IDEAL_LSB);
}

static void case_clarke3(void)
{
    err_t arith = { 0 };
    err_t ideal = { 0 };
    for (int32_t i = 0; i < GRID_N; i++) {
        for (int32_t j = 0; j < GRID_N; j++) {
            for (int32_t k = 0; k < GRID_N; k += 3) {
                const foc_abc_t abc = { (q15_t)grid(i), (q15_t)grid(j),
                                        (q15_t)grid(k) };
                const foc_ab_t ab = foc_clarke3_q15(abc);
                track(&arith, ab.alpha,
                      sat((2.0 * abc.a - abc.b - abc.c) / 3.0));
                track(&arith, ab.beta, sat((abc.b - abc.c) / SQRT3));
            }
        }
    }
    /* Balanced sets plus a common-mode offset, which must drop out. */
    static const double offsets[] = { 0.0, 2000.0, -5000.0 };
    for (size_t m = 2; m < N_MAGS; m++) { /* no input clipping */
        for (size_t o = 0; o < sizeof offsets / sizeof offsets[0]; o++) {
            for (uint32_t t = 0; t < 65536u; t += 3u) {
                const double th = angle_rad(t);
                const foc_abc_t abc = {
                    q(offsets[o] + MAGS[m] * cos(th)),
                    q(offsets[o] + MAGS[m] * cos(th - 2 * PI / 3)),
                    q(offsets[o] + MAGS[m] * cos(th + 2 * PI / 3)) };
                const foc_ab_t ab = foc_clarke3_q15(abc);
                track(&ideal, ab.alpha, MAGS[m] * cos(th));
                track(&ideal, ab.beta, MAGS[m] * sin(th));
            }
        }
    }
    report("clarke3 formula", &arith, ARITH_LSB);
    report("clarke3 balanced+offset", &ideal, IDEAL_LSB);
}

/* Park and inverse Park over every angle, for vectors of several
 * magnitudes and directions: against the same formula on the table's
 * sin/cos (ARITH) and against an exact rotation (IDEAL). */
static void case_park(void)
{
    err_t arith = { 0 };
    err_t ideal = { 0 };
    for (size_t m = 0; m < N_MAGS; m++) {
        for (uint32_t phi = 0; phi < 65536u; phi += 4099u) {
            const double vx = MAGS[m] * cos(angle_rad(phi));
            const double vy = MAGS[m] * sin(angle_rad(phi));
            const foc_ab_t ab = { q(vx), q(vy) };
            for (uint32_t t = 0; t < 65536u; t++) {
                const foc_sincos_t sc = foc_sincos_q15((uint16_t)t);
                const double s = sc.sin / 32768.0;
                const double c = sc.cos / 32768.0;
                const foc_dq_t dq = foc_park_q15(ab, sc);
                track(&arith, dq.d, sat(ab.alpha * c + ab.beta * s));
                track(&arith, dq.q, sat(ab.beta * c - ab.alpha * s));
                const double ct = cos(angle_rad(t));
                const double st = sin(angle_rad(t));
                track(&ideal, dq.d, vx * ct + vy * st);
                track(&ideal, dq.q, vy * ct - vx * st);
            }
        }
    }
    report("park formula", &arith, ARITH_LSB);
    report("park exact rotation", &ideal, IDEAL_LSB);
}

static void case_ipark(void)
{
    err_t arith = { 0 };
    err_t ideal = { 0 };
    for (size_t m = 0; m < N_MAGS; m++) {
        for (uint32_t phi = 0; phi < 65536u; phi += 4099u) {
            const double vd = MAGS[m] * cos(angle_rad(phi));
            const double vq = MAGS[m] * sin(angle_rad(phi));
            const foc_dq_t dq = { q(vd), q(vq) };
            for (uint32_t t = 0; t < 65536u; t++) {
                const foc_sincos_t sc = foc_sincos_q15((uint16_t)t);
                const double s = sc.sin / 32768.0;
                const double c = sc.cos / 32768.0;
                const foc_ab_t ab = foc_ipark_q15(dq, sc);
                track(&arith, ab.alpha, sat(dq.d * c - dq.q * s));
                track(&arith, ab.beta, sat(dq.d * s + dq.q * c));
                const double ct = cos(angle_rad(t));
                const double st = sin(angle_rad(t));
                track(&ideal, ab.alpha, vd * ct - vq * st);
                track(&ideal, ab.beta, vd * st + vq * ct);
            }
        }
    }
    report("ipark formula", &arith, ARITH_LSB);
    report("ipark exact rotation", &ideal, IDEAL_LSB);
}

static void case_iclarke(void)
{
    err_t arith = { 0 };
    err_t ideal = { 0 };
    for (int32_t i = 0; i < GRID_N; i++) {
        for (int32_t j = 0; j < GRID_N; j++) {
            const foc_ab_t ab = { (q15_t)grid(i), (q15_t)grid(j) };
            const foc_abc_t abc = foc_iclarke_q15(ab);
            track(&arith, abc.a, ab.alpha);
            track(&arith, abc.b, sat(-ab.alpha / 2.0 + SQRT3 / 2.0 * ab.beta));
            track(&arith, abc.c, sat(-ab.alpha / 2.0 - SQRT3 / 2.0 * ab.beta));
        }
    }
    for (size_t m = 0; m < N_MAGS; m++) {
        for (uint32_t t = 0; t < 65536u; t += 3u) {
            const double th = angle_rad(t);
            const foc_ab_t ab = { q(MAGS[m] * cos(th)), q(MAGS[m] * sin(th)) };
            const foc_abc_t abc = foc_iclarke_q15(ab);
            track(&ideal, abc.a, MAGS[m] * cos(th));
            track(&ideal, abc.b, MAGS[m] * cos(th - 2 * PI / 3));
            track(&ideal, abc.c, MAGS[m] * cos(th + 2 * PI / 3));
        }
    }
    report("iclarke formula", &arith, ARITH_LSB);
    report("iclarke balanced", &ideal, IDEAL_LSB);
}

/* Full-scale corner inputs, including sin/cos pairs that are not unit
 * vectors: every result equals the saturated double result (no wrap). */
static void case_full_scale_saturates(void)
{
    static const q15_t v[] = { -32768, -32767, -16384, 0, 16384, 32767 };
    const size_t n = sizeof v / sizeof v[0];
    err_t e = { 0 };
    for (size_t i = 0; i < n; i++) {
        for (size_t j = 0; j < n; j++) {
            const foc_ab_t c2 = foc_clarke2_q15(v[i], v[j]);
            track(&e, c2.beta, sat((v[i] + 2.0 * v[j]) / SQRT3));
            const foc_ab_t in = { v[i], v[j] };
            const foc_abc_t abc = foc_iclarke_q15(in);
            track(&e, abc.b, sat(-v[i] / 2.0 + SQRT3 / 2.0 * v[j]));
            track(&e, abc.c, sat(-v[i] / 2.0 - SQRT3 / 2.0 * v[j]));
            for (size_t k = 0; k < n; k++) {
                const foc_abc_t p = { v[i], v[j], v[k] };
                const foc_ab_t c3 = foc_clarke3_q15(p);
                track(&e, c3.alpha, sat((2.0 * v[i] - v[j] - v[k]) / 3.0));
                for (size_t l = 0; l < n; l++) {
                    const foc_sincos_t sc = { v[k], v[l] };
                    const double s = v[k] / 32768.0;
                    const double c = v[l] / 32768.0;
                    const foc_dq_t dq = foc_park_q15(in, sc);
                    track(&e, dq.d, sat(v[i] * c + v[j] * s));
                    track(&e, dq.q, sat(v[j] * c - v[i] * s));
                    const foc_dq_t dq_in = { v[i], v[j] };
                    const foc_ab_t ab = foc_ipark_q15(dq_in, sc);
                    track(&e, ab.alpha, sat(v[i] * c - v[j] * s));
                    track(&e, ab.beta, sat(v[i] * s + v[j] * c));
                }
            }
        }
    }
    report("full-scale corners", &e, ARITH_LSB);
    const foc_sincos_t worst = { -32768, -32768 };
    const foc_ab_t neg = { -32768, -32768 };
    TK_CHECK(foc_park_q15(neg, worst).d == 32767, "d saturates");
}

TK_CASES(TK_CASE(case_clarke2), TK_CASE(case_clarke3), TK_CASE(case_park),
         TK_CASE(case_ipark), TK_CASE(case_iclarke),
         TK_CASE(case_full_scale_saturates))
