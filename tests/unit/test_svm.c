/*
 * Space-vector modulation (min-max injection) against double precision.
 *
 * Per-unit: 1.0 (32768) = Vdc / sqrt(3) for the vector; duties are Q15
 * fractions of the period.  A line-to-line duty difference is the line
 * voltage over Vdc: d_a - d_b = (v_a - v_b) / sqrt(3), with v_a, v_b, v_c the
 * inverse-Clarke phase values of the input.
 *
 * Limits:
 *   LINE_LSB    2.0   line-to-line duty difference against the reference:
 *                     two duties each rounded (0.5 LSB) plus the 1/sqrt(3)
 *                     constant (0.42 LSB off, up to 0.7 LSB at |v| = 1);
 *   CENTRE_LSB  1.0   (max duty + min duty) / 2 against 16384;
 *   ANGLE_DEG   0.05  overmodulated vector angle against the input angle
 *                     (duty rounding moves the tip by ~1 LSB out of 32768:
 *                     0.002 deg; 0.05 deg is the atan2 accuracy);
 *   MAG_LSB     4.0   overmodulated vector magnitude against the hexagon
 *                     radius in its direction: duty rounding (up to 1.5 LSB
 *                     on the rebuilt vector), the clamp of the top duty from
 *                     32768 to 32767 (1.2 LSB) and the truncated gain (1 LSB).
 */
#include <math.h>
#include <stdint.h>

#include "foc/svm.h"
#include "testkit.h"

#define PI 3.14159265358979323846
#define SQRT3 1.73205080756887729
#define LINE_LSB 2.0
#define CENTRE_LSB 1.0
#define ANGLE_DEG 0.05
#define MAG_LSB 4.0

static double angle_rad(uint32_t a)
{
    return a * (PI / 32768.0);
}

static q15_t q(double x)
{
    return (q15_t)lround(fmin(fmax(x, -32768.0), 32767.0));
}

static foc_ab_t vec(double mag, double th)
{
    const foc_ab_t v = { q(mag * cos(th)), q(mag * sin(th)) };
    return v;
}

static int in_range(const foc_duty_t *d)
{
    return d->a >= 0 && d->b >= 0 && d->c >= 0;  /* q15_t <= 32767 always */
}

static double dmax(const foc_duty_t *d)
{
    return fmax(d->a, fmax(d->b, d->c));
}

static double dmin(const foc_duty_t *d)
{
    return fmin(d->a, fmin(d->b, d->c));
}

/* Vector the duties produce, in Q15 per-unit: the duty offsets are the
 * phase values over sqrt(3), so alpha = (2 d_a - d_b - d_c) / sqrt(3) and
 * beta = d_b - d_c. */
static void reconstruct(const foc_duty_t *d, double *alpha, double *beta)
{
    *alpha = (2.0 * d->a - d->b - d->c) / SQRT3;
    *beta = (double)d->b - d->c;
}

/* Worst line-voltage error of one vector, LSB. */
static double line_error(foc_ab_t v, const foc_duty_t *d)
{
    const double va = v.alpha;
    const double vb = -v.alpha / 2.0 + SQRT3 / 2.0 * v.beta;
    const double vc = -v.alpha / 2.0 - SQRT3 / 2.0 * v.beta;
    const double eab = fabs((d->a - d->b) - (va - vb) / SQRT3);
    const double ebc = fabs((d->b - d->c) - (vb - vc) / SQRT3);
    const double eca = fabs((d->c - d->a) - (vc - va) / SQRT3);
    return fmax(eab, fmax(ebc, eca));
}

/* (a) Inside the linear circle, line voltages exact and duties centred. */
static void case_linear_line_voltages(void)
{
    static const double mags[] = { 0.0, 1.0, 100.0, 5000.0, 16384.0,
                                   30000.0, 32767.0 };
    double worst_line = 0.0;
    double worst_centre = 0.0;
    int out_of_range = 0;
    for (size_t m = 0; m < sizeof mags / sizeof mags[0]; m++) {
        for (uint32_t t = 0; t < 65536u; t += 3u) {
            const foc_ab_t v = vec(mags[m], angle_rad(t));
            const foc_duty_t d = foc_svm_q15(v);
            out_of_range += !in_range(&d);
            worst_line = fmax(worst_line, line_error(v, &d));
            worst_centre =
                fmax(worst_centre, fabs((dmax(&d) + dmin(&d)) / 2.0 - 16384.0));
        }
    }
    printf("svm linear: line voltage error %.3f LSB (limit %.1f), centre "
           "%.2f LSB (limit %.1f)\n", worst_line, LINE_LSB, worst_centre,
           CENTRE_LSB);
    TK_CHECK(out_of_range == 0, "%d duties out of range", out_of_range);
    TK_CHECK(worst_line <= LINE_LSB, "line error %.3f LSB", worst_line);
    TK_CHECK(worst_centre <= CENTRE_LSB, "centre %.2f LSB", worst_centre);
    const foc_ab_t zero = { 0, 0 };
    const foc_duty_t d0 = foc_svm_q15(zero);
    TK_CHECK(d0.a == 16384 && d0.b == 16384 && d0.c == 16384,
             "zero vector: %d %d %d", d0.a, d0.b, d0.c);
}

/* (b) |v| = 1.0 at every angle fits the period, and at the angles where
 * the circle touches the hexagon (30 deg + k 60 deg) takes all of it. */
static void case_full_linear_range(void)
{
    double widest = 0.0;
    double worst_line = 0.0;
    int out_of_range = 0;
    for (uint32_t t = 0; t < 65536u; t++) {
        const foc_ab_t v = vec(32767.0, angle_rad(t));
        const foc_duty_t d = foc_svm_q15(v);
        out_of_range += !in_range(&d);
        widest = fmax(widest, dmax(&d) - dmin(&d));
        worst_line = fmax(worst_line, line_error(v, &d));
    }
    for (uint32_t k = 0; k < 6u; k++) {
        const foc_ab_t v = vec(32767.0, PI / 6.0 + k * PI / 3.0);
        const foc_duty_t d = foc_svm_q15(v);
        TK_CHECK(dmax(&d) - dmin(&d) >= 32765.0, "span %.0f at %lu deg",
                 dmax(&d) - dmin(&d), (unsigned long)(30u + 60u * k));
    }
    printf("svm |v|=1: widest span %.0f, line error %.3f LSB\n", widest,
           worst_line);
    TK_CHECK(out_of_range == 0, "%d duties out of range", out_of_range);
    TK_CHECK(worst_line <= LINE_LSB, "line error %.3f LSB", worst_line);
}

/* Radius of the hexagon (duty span = period) in the direction th: the
 * unit circle touches it at 30 deg + k 60 deg, its corners are at k 60 deg. */
static double hexagon_radius(double th)
{
    const double deg = fmod(th * 180.0 / PI + 330.0, 60.0); /* from a flat */
    return 32768.0 / cos((fmin(deg, 60.0 - deg)) * PI / 180.0);
}

/* (c) Overmodulation up to the edges of the Q15 square: duties in range,
 * span = period outside the hexagon, angle kept, magnitude cut to the
 * hexagon. */
static void case_overmodulation(void)
{
    double worst_angle = 0.0;
    double worst_mag = 0.0;
    double narrowest = 32768.0;
    int out_of_range = 0;
    for (uint32_t t = 0; t < 65536u; t += 3u) {
        const double th = angle_rad(t);
        const double edge = 32767.0 / fmax(fabs(cos(th)), fabs(sin(th)));
        const double mags[] = { 38000.0, 40000.0, 44000.0, edge };
        for (size_t m = 0; m < sizeof mags / sizeof mags[0]; m++) {
            const foc_ab_t v = vec(fmin(mags[m], edge), th);
            const foc_duty_t d = foc_svm_q15(v);
            double alpha;
            double beta;
            reconstruct(&d, &alpha, &beta);
            /* the square's edge is inside the hexagon near its corners */
            const double hex = hexagon_radius(atan2(v.beta, v.alpha));
            const double in_mag = hypot(v.alpha, v.beta);
            const double want_mag = fmin(in_mag, hex);
            const double da = remainder(atan2(beta, alpha)
                                        - atan2(v.beta, v.alpha), 2.0 * PI);
            out_of_range += !in_range(&d);
            worst_angle = fmax(worst_angle, fabs(da) * 180.0 / PI);
            worst_mag = fmax(worst_mag, fabs(hypot(alpha, beta) - want_mag));
            if (in_mag > hex + 1.0) {
                narrowest = fmin(narrowest, dmax(&d) - dmin(&d));
            }
        }
    }
    printf("svm overmodulation: angle error %.4f deg (limit %.2f), magnitude "
           "vs hexagon %.2f LSB (limit %.1f), narrowest span %.0f\n",
           worst_angle, ANGLE_DEG, worst_mag, MAG_LSB, narrowest);
    TK_CHECK(out_of_range == 0, "%d duties out of range", out_of_range);
    TK_CHECK(worst_angle <= ANGLE_DEG, "angle error %.4f deg", worst_angle);
    TK_CHECK(worst_mag <= MAG_LSB, "magnitude error %.2f LSB", worst_mag);
    TK_CHECK(narrowest >= 32766.0, "span %.0f below the period", narrowest);
    const foc_ab_t corners[] = { { 32767, 32767 }, { -32768, -32768 },
                                 { 32767, -32768 }, { -32768, 32767 } };
    for (size_t i = 0; i < 4; i++) {
        const foc_duty_t d = foc_svm_q15(corners[i]);
        TK_CHECK(in_range(&d) && dmax(&d) - dmin(&d) >= 32766.0,
                 "corner %zu: %d %d %d", i, d.a, d.b, d.c);
    }
}

/* (d) Sector = 1 + floor(angle / 60 deg) all around the circle.  Within
 * 0.001 deg of a sector edge either neighbour is accepted (the edge is
 * found with the rounded 1/sqrt(3)); on the alpha axis the edge is exact:
 * sector 1 at 0 deg and 4 at 180 deg. */
static void case_sectors(void)
{
    int errors = 0;
    for (uint32_t t = 0; t < 65536u; t++) {
        const foc_ab_t v = vec(30000.0, angle_rad(t));
        const double deg =
            fmod(atan2(v.beta, v.alpha) * 180.0 / PI + 360.0, 360.0);
        const int want = 1 + (int)(deg / 60.0);
        const int below = 1 + (int)fmod((deg - 0.001) + 360.0, 360.0) / 60;
        const int above = 1 + (int)fmod(deg + 0.001, 360.0) / 60;
        const int got = foc_svm_q15(v).sector;
        if (got != want && got != below && got != above && errors++ < 5) {
            TK_CHECK(0, "%.4f deg: sector %d, want %d", deg, got, want);
        }
    }
    TK_CHECK(errors == 0, "%d wrong sectors", errors);
    static const struct {
        foc_ab_t v;
        uint8_t sector;
    } axes[] = { { { 1000, 0 }, 1 },     { { 0, 1000 }, 2 },
                 { { -1000, 0 }, 4 },    { { 0, -1000 }, 5 },
                 { { 32767, 0 }, 1 },    { { -32768, 0 }, 4 },
                 { { 1, 0 }, 1 },        { { -1, 0 }, 4 },
                 /* 0.01 deg either side of the edges at 60 .. 300 deg */
                 { { 1000, 1731 }, 1 },  { { 1000, 1733 }, 2 },
                 { { -1000, 1733 }, 2 }, { { -1000, 1731 }, 3 },
                 { { -1000, -1731 }, 4 }, { { -1000, -1733 }, 5 },
                 { { 1000, -1733 }, 5 }, { { 1000, -1731 }, 6 } };
    for (size_t i = 0; i < sizeof axes / sizeof axes[0]; i++) {
        const uint8_t got = foc_svm_q15(axes[i].v).sector;
        TK_CHECK(got == axes[i].sector, "(%d, %d): sector %u, want %u",
                 axes[i].v.alpha, axes[i].v.beta, got, axes[i].sector);
    }
}

TK_CASES(TK_CASE(case_linear_line_voltages), TK_CASE(case_full_linear_range),
         TK_CASE(case_overmodulation), TK_CASE(case_sectors))
