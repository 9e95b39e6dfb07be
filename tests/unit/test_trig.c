/*
 * sin/cos (exhaustive) and atan2 (dense grids) against double precision.
 */
#include <math.h>
#include <stdint.h>

#include "foc/trig.h"
#include "testkit.h"

#define PI 3.14159265358979323846
#define COUNTS_PER_RAD (32768.0 / PI)
#define COUNTS_PER_DEG (65536.0 / 360.0)

/* Limits: sin/cos 2 LSB (header contract); atan2 0.05 deg = 9.1 counts. */
#define SINCOS_LSB 2.0
#define ATAN_DEG 0.05

/* x * 32768 clamped to the Q15 range: the exact Q15 value of x. */
static double q15_ref(double x)
{
    const double v = x * 32768.0;
    return (v > 32767.0) ? 32767.0 : v;
}

static double angle_rad(uint16_t a)
{
    return a / COUNTS_PER_RAD;
}

/* |a - b| in counts, modulo one turn. */
static double angle_diff(double a, double b)
{
    double d = fmod(a - b, 65536.0);
    if (d > 32768.0) {
        d -= 65536.0;
    } else if (d < -32768.0) {
        d += 65536.0;
    }
    return fabs(d);
}

/* Reference angle of (x, y) in counts, [0, 65536). */
static double ref_atan2(double y, double x)
{
    const double a = atan2(y, x) * COUNTS_PER_RAD;
    return (a < 0.0) ? a + 65536.0 : a;
}

static void case_sin_exhaustive(void)
{
    double worst = 0.0;
    for (uint32_t a = 0; a < 65536u; a++) {
        const double want = q15_ref(sin(angle_rad((uint16_t)a)));
        worst = fmax(worst, fabs(foc_sin_q15((uint16_t)a) - want));
    }
    printf("sin: max error %.3f LSB\n", worst);
    TK_CHECK(worst <= SINCOS_LSB, "max error %.3f LSB", worst);
    TK_CHECK(foc_sin_q15(16384) == 32767 && foc_sin_q15(0) == 0
                 && foc_sin_q15(32768) == 0 && foc_sin_q15(49152) == -32767,
             "axes");
}

static void case_cos_exhaustive(void)
{
    double worst = 0.0;
    for (uint32_t a = 0; a < 65536u; a++) {
        const double want = q15_ref(cos(angle_rad((uint16_t)a)));
        worst = fmax(worst, fabs(foc_cos_q15((uint16_t)a) - want));
    }
    printf("cos: max error %.3f LSB\n", worst);
    TK_CHECK(worst <= SINCOS_LSB, "max error %.3f LSB", worst);
    TK_CHECK(foc_cos_q15(0) == 32767 && foc_cos_q15(32768) == -32767,
             "axes");
}

/* foc_sincos_q15 equals foc_sin_q15 / foc_cos_q15 at every angle; sin is
 * exactly odd and cos(a) == sin(a + 90 deg). */
static void case_sincos_consistent(void)
{
    int errors = 0;
    for (uint32_t a = 0; a < 65536u; a++) {
        const uint16_t t = (uint16_t)a;
        const foc_sincos_t sc = foc_sincos_q15(t);
        if (sc.sin != foc_sin_q15(t) || sc.cos != foc_cos_q15(t)
            || foc_sin_q15((uint16_t)(0u - a)) != -sc.sin
            || foc_sin_q15((uint16_t)(a + 16384u)) != sc.cos) {
            if (errors++ < 5) {
                TK_CHECK(0, "angle %lu", (unsigned long)a);
            }
        }
    }
    TK_CHECK(errors == 0, "%d mismatches", errors);
}

/* Worst atan2 error (degrees) against the angle of the integer input. */
static double atan2_error_deg(q15_t y, q15_t x)
{
    return angle_diff(foc_atan2_q15(y, x), ref_atan2(y, x)) / COUNTS_PER_DEG;
}

/* Vectors of several magnitudes at 65536 / 7 angles (all octants), and a
 * square grid over the whole Q15 range including -32768. */
static void case_atan2_dense(void)
{
    static const double mags[] = { 32767.0, 30000.0, 16384.0, 5000.0, 1000.0 };
    double worst = 0.0;
    for (size_t m = 0; m < sizeof mags / sizeof mags[0]; m++) {
        for (uint32_t a = 0; a < 65536u; a += 7u) {
            const double th = angle_rad((uint16_t)a);
            const q15_t x = (q15_t)lround(mags[m] * cos(th));
            const q15_t y = (q15_t)lround(mags[m] * sin(th));
            worst = fmax(worst, atan2_error_deg(y, x));
        }
    }
    for (int32_t x = -32768; x <= 32767; x += 97) {
        for (int32_t y = -32768; y <= 32767; y += 89) {
            worst = fmax(worst, atan2_error_deg((q15_t)y, (q15_t)x));
        }
    }
    printf("atan2: max error %.4f deg (%.2f counts)\n", worst,
           worst * COUNTS_PER_DEG);
    TK_CHECK(worst <= ATAN_DEG, "max error %.4f deg", worst);
}

/*
 * Small vectors.  Against the angle of the integer input the limit stays
 * 0.05 deg (the ratio keeps its full Q15 resolution at any magnitude).
 * Against the angle of the exact vector before rounding to integers, the
 * rounding moves the tip by up to sqrt(2)/2 LSB, which alone turns it by up
 * to asin(0.7071 / |v|): 0.203 deg at |v| = 200, 0.81 deg at |v| = 50.  The
 * limit there is that bound plus 0.05 deg.
 */
static void case_atan2_small_magnitude(void)
{
    static const double mags[] = { 200.0, 50.0 };
    for (size_t m = 0; m < sizeof mags / sizeof mags[0]; m++) {
        const double quant_deg = asin(sqrt(0.5) / mags[m]) * 180.0 / PI;
        double worst_int = 0.0;
        double worst_true = 0.0;
        for (uint32_t a = 0; a < 65536u; a++) {
            const double th = angle_rad((uint16_t)a);
            const q15_t x = (q15_t)lround(mags[m] * cos(th));
            const q15_t y = (q15_t)lround(mags[m] * sin(th));
            const uint16_t got = foc_atan2_q15(y, x);
            worst_int = fmax(worst_int, atan2_error_deg(y, x));
            worst_true = fmax(worst_true, angle_diff(got, a) / COUNTS_PER_DEG);
        }
        printf("atan2 |v|=%.0f: %.4f deg vs integer input, %.4f deg vs exact "
               "angle (limit %.4f)\n", mags[m], worst_int, worst_true,
               quant_deg + ATAN_DEG);
        TK_CHECK(worst_int <= ATAN_DEG, "|v|=%.0f: %.4f deg", mags[m],
                 worst_int);
        TK_CHECK(worst_true <= quant_deg + ATAN_DEG, "|v|=%.0f: %.4f deg",
                 mags[m], worst_true);
    }
}

/* Axes exactly; (0, 0) -> 0; diagonals and -32768 corners within 0.05 deg;
 * a vector one LSB off an axis just beside it. */
static void case_atan2_axes_and_edges(void)
{
    static const q15_t mags[] = { 1, 2, 100, 32767, -32768 };
    TK_CHECK(foc_atan2_q15(0, 0) == 0, "(0,0) -> %u", foc_atan2_q15(0, 0));
    for (size_t i = 0; i < sizeof mags / sizeof mags[0]; i++) {
        const q15_t m = mags[i];
        const int neg = m < 0;
        /* (x, 0), (0, y) with m of either sign */
        TK_CHECK(foc_atan2_q15(0, m) == (neg ? 32768u : 0u), "x=%d", m);
        TK_CHECK(foc_atan2_q15(m, 0) == (neg ? 49152u : 16384u), "y=%d", m);
        if (m != Q15_MIN) {
            TK_CHECK(foc_atan2_q15(0, (q15_t)-m) == (neg ? 0u : 32768u),
                     "x=%d", -m);
            TK_CHECK(foc_atan2_q15((q15_t)-m, 0) == (neg ? 16384u : 49152u),
                     "y=%d", -m);
        }
    }
    static const q15_t corners[] = { -32768, -32767, -1, 1, 32767 };
    const size_t n = sizeof corners / sizeof corners[0];
    for (size_t i = 0; i < n; i++) {
        for (size_t j = 0; j < n; j++) {
            const double err = atan2_error_deg(corners[i], corners[j]);
            TK_CHECK(err <= ATAN_DEG, "(%d, %d): %.4f deg", corners[j],
                     corners[i], err);
        }
    }
    TK_CHECK(foc_atan2_q15(-32768, -32768) == 40960u, "225 deg: %u",
             foc_atan2_q15(-32768, -32768));
    TK_CHECK(foc_atan2_q15(32767, 32767) == 8192u, "45 deg: %u",
             foc_atan2_q15(32767, 32767));
}

/* atan2(sin a, cos a) returns a at every angle, within the atan2 limit
 * (the sin/cos error adds at most 2 / 32767 rad = 0.004 deg). */
static void case_atan2_inverts_sincos(void)
{
    double worst = 0.0;
    for (uint32_t a = 0; a < 65536u; a++) {
        const foc_sincos_t sc = foc_sincos_q15((uint16_t)a);
        worst = fmax(worst, angle_diff(foc_atan2_q15(sc.sin, sc.cos), a));
    }
    worst /= COUNTS_PER_DEG;
    printf("atan2(sincos(a)) - a: max %.4f deg\n", worst);
    TK_CHECK(worst <= ATAN_DEG, "max error %.4f deg", worst);
}

/* Signed angle difference: the shorter way round, both wraps. */
static void case_angle_diff(void)
{
    for (int32_t d = -32768; d <= 32767; d += 7) {
        for (uint32_t b = 0; b < 65536u; b += 4099u) {
            const uint16_t a = (uint16_t)((int32_t)b + d);
            TK_CHECK(foc_angle_diff(a, (uint16_t)b) == d, "a=%u b=%lu: %d != %ld", a,
                     (unsigned long)b, foc_angle_diff(a, (uint16_t)b), (long)d);
        }
    }
    TK_CHECK(foc_angle_diff(0, 32768) == -32768, "half turn: %d", foc_angle_diff(0, 32768));
}

TK_CASES(TK_CASE(case_sin_exhaustive), TK_CASE(case_cos_exhaustive),
         TK_CASE(case_sincos_consistent), TK_CASE(case_atan2_dense),
         TK_CASE(case_atan2_small_magnitude),
         TK_CASE(case_atan2_axes_and_edges),
         TK_CASE(case_atan2_inverts_sincos), TK_CASE(case_angle_diff))
