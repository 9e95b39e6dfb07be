/*
 * PI controller with back-calculation anti-windup (foc/pi.h).
 *
 * The reference is the same discrete law in double precision, in LSB:
 *   u = I + Kp e;  y = clamp(u);  I += Ki e + Kc (y - u);  I clamped.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "foc/pi.h"
#include "testkit.h"

/* Output of the fixed-point PI against the double reference in a closed
 * loop: the integrator's Q15 part is truncated (< 1 LSB) and the
 * proportional term rounded (0.5 LSB); the loop keeps the difference from
 * growing. */
#define TRACK_LSB 3.0

typedef struct {
    double kp, ki, kc; /* gains, real */
    double lo, hi;     /* limits, LSB */
    double integ;      /* integrator, LSB */
    int anti_windup;   /* 0: plain PI, unlimited integrator */
} ref_pi_t;

static ref_pi_t ref_from(const foc_pi_q15_t *pi, const foc_pi_gains_t *g, int anti_windup)
{
    const ref_pi_t r = { g->kp * ldexp(1.0, 15 - g->kp_rshift) / 32768.0,
                         g->ki * ldexp(1.0, g->ki_shift) / 32768.0,
                         anti_windup ? g->kc / 32768.0 : 0.0,
                         pi->out_min,
                         pi->out_max,
                         pi->integ / 32768.0,
                         anti_windup };
    return r;
}

static double ref_step(ref_pi_t *r, double e)
{
    const double u = r->integ + r->kp * e;
    const double y = fmin(fmax(u, r->lo), r->hi);
    r->integ += r->ki * e + r->kc * (y - u);
    if (r->anti_windup) {
        r->integ = fmin(fmax(r->integ, r->lo), r->hi);
    }
    return y;
}

/* First-order plant x += a (y - x), in LSB. */
static double plant(double x, double y)
{
    return x + 0.02 * (y - x);
}

static q15_t to_q15(double x)
{
    return (q15_t)lround(fmin(fmax(x, -32768.0), 32767.0));
}

/* Step responses in closed loop with a first-order plant: the fixed-point
 * PI (fed the rounded plant output) against the double reference, for a
 * step inside the limits, one that saturates, a step down, and a gain
 * above 1. */
static void case_step_response(void)
{
    static const struct {
        q15_t kp;
        uint8_t shift;
        q15_t ki;
        uint8_t ki_shift;
        q15_t kc, lo, hi, ref;
    } runs[] = {
        { Q15(0.5), 0, Q15(0.02), 0, Q15(0.5), Q15(-0.9), Q15(0.9), Q15(0.5) },
        { Q15(0.5), 0, Q15(0.02), 0, Q15(0.5), Q15(-0.9), Q15(0.6), Q15(0.8) },
        { Q15(0.5), 0, Q15(0.02), 0, Q15(0.5), Q15(-0.9), Q15(0.9), Q15(-0.7) },
        { Q15(0.75), 2, Q15(0.05), 0, Q15(0.2), Q15(-1.0), Q15(1.0), Q15(0.3) },
        { Q15(0.5), 0, Q15(0.015), 2, Q15(0.5), Q15(-0.9), Q15(0.9), Q15(0.5) },
    };
    double worst = 0.0;
    for (size_t i = 0; i < sizeof runs / sizeof runs[0]; i++) {
        foc_pi_q15_t pi;
        const foc_pi_gains_t g = FOC_PI_GAINS(runs[i].kp, runs[i].shift, runs[i].ki, runs[i].ki_shift, runs[i].kc);
        foc_pi_init(&pi, runs[i].lo, runs[i].hi);
        ref_pi_t ref = ref_from(&pi, &g, 1);
        double x_fix = 0.0;
        double x_ref = 0.0;
        double run_worst = 0.0;
        for (int n = 0; n < 3000; n++) {
            const q15_t e = foc_sub_q15(runs[i].ref, to_q15(x_fix));
            const double y_fix = foc_pi_step(&pi, &g, e);
            const double y_ref = ref_step(&ref, runs[i].ref - x_ref);
            run_worst = fmax(run_worst, fabs(y_fix - y_ref));
            x_fix = plant(x_fix, y_fix);
            x_ref = plant(x_ref, y_ref);
        }
        TK_CHECK(run_worst <= TRACK_LSB, "run %zu: %.2f LSB", i, run_worst);
        TK_CHECK(fabs(x_fix - fmin(runs[i].ref, runs[i].hi)) <= 2.0,
                 "run %zu: settles at %.1f", i, x_fix);
        worst = fmax(worst, run_worst);
    }
    printf("pi step response: max %.2f LSB from the double reference "
           "(limit %.1f)\n", worst, TRACK_LSB);
}

/* Steps until the output leaves out_max after the error reverses. */
static long leave_steps_fixed(foc_pi_q15_t *pi, const foc_pi_gains_t *g, q15_t e_back, long limit)
{
    for (long n = 1; n <= limit; n++) {
        if (foc_pi_step(pi, g, e_back) < pi->out_max) {
            return n;
        }
    }
    return -1;
}

static long leave_steps_ref(ref_pi_t *r, double e_back, long limit)
{
    for (long n = 1; n <= limit; n++) {
        if (ref_step(r, e_back) < r->hi) {
            return n;
        }
    }
    return -1;
}

/*
 * Windup recovery: a large positive error holds the output at its limit
 * for 5000 steps, then the error reverses to a small negative value.  With
 * back-calculation the output leaves the limit within WINDUP_STEPS; a
 * plain PI (same gains, unlimited integrator) takes over 100 times longer.
 * While saturated, the integrator settles where back-calculation puts it:
 * I = out_max - Kp e + (Ki / Kc) e.
 */
#define WINDUP_STEPS 2L

static void case_windup_recovery(void)
{
    const q15_t e_hold = Q15(0.5);
    const q15_t e_back = Q15(-0.05);
    foc_pi_q15_t pi;
    const foc_pi_gains_t g = FOC_PI_GAINS(Q15(0.2), 0, Q15(0.01), 0, Q15(0.1));
    foc_pi_init(&pi, Q15(-0.5), Q15(0.5));
    ref_pi_t plain = ref_from(&pi, &g, 0);
    int saturated = 0;
    for (int n = 0; n < 5000; n++) {
        saturated += foc_pi_step(&pi, &g, e_hold) == pi.out_max;
        ref_step(&plain, e_hold);
    }
    TK_CHECK(saturated >= 4900, "saturated only %d steps", saturated);
    const double settled = pi.out_max - 0.2 * e_hold + (0.01 / 0.1) * e_hold;
    TK_CHECK(fabs(pi.integ / 32768.0 - settled) <= 2.0,
             "integrator %.1f, want %.1f", pi.integ / 32768.0, settled);

    const long fixed = leave_steps_fixed(&pi, &g, e_back, 1000000L);
    const long ref = leave_steps_ref(&plain, e_back, 1000000L);
    printf("pi windup: leaves the limit after %ld step(s); without "
           "anti-windup after %ld\n", fixed, ref);
    TK_CHECK(fixed >= 1 && fixed <= WINDUP_STEPS, "%ld steps", fixed);
    TK_CHECK(ref > 100L * fixed, "reference %ld steps", ref);
}

/* Back-calculation with the integrator away from its clamp: after a long
 * saturation the error ramps down slowly through zero.  The output leaves
 * the limit within a step of the double reference of the same law, and
 * long before a plain PI would. */
static void case_windup_slow_ramp(void)
{
    foc_pi_q15_t pi;
    const foc_pi_gains_t g = FOC_PI_GAINS(Q15(0.1), 0, Q15(0.002), 0, Q15(0.05));
    foc_pi_init(&pi, Q15(-0.25), Q15(0.25));
    ref_pi_t ref = ref_from(&pi, &g, 1);
    ref_pi_t plain = ref_from(&pi, &g, 0);
    for (int n = 0; n < 3000; n++) {
        foc_pi_step(&pi, &g, Q15(0.5));
        ref_step(&ref, Q15(0.5));
        ref_step(&plain, Q15(0.5));
    }
    TK_CHECK(foc_pi_step(&pi, &g, Q15(0.5)) == pi.out_max, "not saturated");
    ref_step(&ref, Q15(0.5));
    ref_step(&plain, Q15(0.5));

    long leave_fix = -1;
    long leave_ref = -1;
    long leave_plain = -1;
    for (long n = 0; n < 100000 && leave_plain < 0; n++) {
        const double e = fmax(16384.0 - 8.0 * n, -32768.0); /* 0 at 2048 */
        if (foc_pi_step(&pi, &g, to_q15(e)) < pi.out_max && leave_fix < 0) {
            leave_fix = n;
        }
        if (ref_step(&ref, e) < ref.hi && leave_ref < 0) {
            leave_ref = n;
        }
        if (ref_step(&plain, e) < plain.hi && leave_plain < 0) {
            leave_plain = n;
        }
    }
    printf("pi slow ramp: leaves the limit at ramp step %ld, reference %ld, "
           "plain PI %ld (error crosses zero at 2048)\n", leave_fix,
           leave_ref, leave_plain);
    TK_CHECK(leave_fix >= 0 && labs(leave_fix - leave_ref) <= 1,
             "left at %ld, reference %ld", leave_fix, leave_ref);
    TK_CHECK(leave_plain > leave_fix + 1000, "plain PI left at %ld",
             leave_plain);
}

/* After a preset to y0 the first output with zero error is y0 (clamped to
 * the limits), whatever the integrator held. */
static void case_bumpless_preset(void)
{
    foc_pi_q15_t pi;
    const foc_pi_gains_t g = FOC_PI_GAINS(Q15(0.3), 1, Q15(0.05), 0, Q15(0.1));
    foc_pi_init(&pi, Q15(-0.8), Q15(0.7));
    for (int32_t y0 = -32768; y0 <= 32767; y0 += 97) {
        foc_pi_step(&pi, &g, (q15_t)(y0 / 2)); /* disturb the integrator */
        foc_pi_preset(&pi, (q15_t)y0);
        const int32_t want = (y0 < pi.out_min) ? pi.out_min
                           : (y0 > pi.out_max) ? pi.out_max : y0;
        const q15_t y = foc_pi_step(&pi, &g, 0);
        TK_CHECK(abs(y - want) <= 1, "preset %ld: %d", (long)y0, y);
        TK_CHECK(foc_pi_step(&pi, &g, 0) == y, "preset %ld: drifts", (long)y0);
    }
}

/* Random errors and limit changes: the integrator's Q15 part and the
 * output always stay within the current limits. */
static void case_integrator_in_range(void)
{
    foc_pi_q15_t pi;
    uint32_t s = 1u;
    int errors = 0;
    const foc_pi_gains_t g = FOC_PI_GAINS(Q15(0.9), 3, Q15(0.9), 0, Q15(0.9));
    foc_pi_init(&pi, Q15(-0.5), Q15(0.5));
    for (int n = 0; n < 200000; n++) {
        s = s * 1664525u + 1013904223u;
        if ((n % 1000) == 0) {
            const q15_t a = (q15_t)(s >> 16);
            const q15_t b = (q15_t)(s & 0xFFFFu);
            foc_pi_set_limits(&pi, a < b ? a : b, a < b ? b : a);
        }
        const q15_t y = foc_pi_step(&pi, &g, (q15_t)(s >> 16));
        const int32_t i15 = pi.integ >> 15;
        if ((y < pi.out_min || y > pi.out_max || i15 < pi.out_min
             || i15 > pi.out_max) && errors++ < 5) {
            TK_CHECK(0, "step %d: y=%d I=%ld limits [%d, %d]", n, y,
                     (long)i15, pi.out_min, pi.out_max);
        }
    }
    TK_CHECK(errors == 0, "%d violations", errors);
    /* Limits that exclude zero hold the integrator from init on. */
    const foc_pi_gains_t g_above = FOC_PI_GAINS(Q15(0.5), 0, Q15(0.1), 0, Q15(0.1));
    foc_pi_init(&pi, Q15(0.2), Q15(0.4));
    TK_CHECK(foc_pi_step(&pi, &g_above, 0) == Q15(0.2), "init: %d", foc_pi_step(&pi, &g_above, 0));
}

/* Proportional-only with Kp = kp 2^shift / 32768 for every shift: output
 * is round(Kp e) clamped, exactly; gains above 1 included. */
static void case_kp_shift(void)
{
    static const q15_t kps[] = { Q15(0.75), Q15(0.5), 32767, -20000 };
    int errors = 0;
    for (size_t k = 0; k < sizeof kps / sizeof kps[0]; k++) {
        for (uint8_t shift = 0; shift <= 15; shift++) {
            foc_pi_q15_t pi;
            const foc_pi_gains_t g = FOC_PI_GAINS(kps[k], shift, 0, 0, 0);
            foc_pi_init(&pi, Q15_MIN, Q15_MAX);
            for (int32_t e = -32768; e <= 32767; e += 7) {
                const double p = floor(kps[k] * ldexp(1.0, shift) * e
                                       / 32768.0 + 0.5);
                const double want = fmin(fmax(p, -32768.0), 32767.0);
                const q15_t y = foc_pi_step(&pi, &g, (q15_t)e);
                if (y != want && errors++ < 5) {
                    TK_CHECK(0, "kp=%d shift=%u e=%ld: %d, want %.0f", kps[k],
                             shift, (long)e, y, want);
                }
            }
        }
    }
    TK_CHECK(errors == 0, "%d mismatches", errors);
    foc_pi_q15_t pi;
    const foc_pi_gains_t g = FOC_PI_GAINS(Q15(0.75), 2, 0, 0, 0);
    foc_pi_init(&pi, Q15_MIN, Q15_MAX); /* Kp = 3 */
    TK_CHECK(foc_pi_step(&pi, &g, 1000) == 3000, "3 x 1000");
}

/* Narrowing the limits clamps the integrator at once; widening them again
 * does not restore what was cut. */
static void case_set_limits(void)
{
    foc_pi_q15_t pi;
    const foc_pi_gains_t g = FOC_PI_GAINS(Q15(0.5), 0, Q15(0.01), 0, Q15(0.1));
    foc_pi_init(&pi, Q15(-0.9), Q15(0.9));
    foc_pi_preset(&pi, Q15(0.8));
    foc_pi_set_limits(&pi, Q15(-0.5), Q15(0.5));
    TK_CHECK((pi.integ >> 15) == Q15(0.5), "I=%ld", (long)(pi.integ >> 15));
    TK_CHECK(foc_pi_step(&pi, &g, 0) == Q15(0.5), "clamped output");
    foc_pi_set_limits(&pi, Q15(-0.9), Q15(0.9));
    TK_CHECK(foc_pi_step(&pi, &g, 0) == Q15(0.5), "widened: %d",
             foc_pi_step(&pi, &g, 0));
    foc_pi_set_limits(&pi, Q15(-0.9), Q15(-0.6));
    TK_CHECK(foc_pi_step(&pi, &g, 0) == Q15(-0.6), "below: %d",
             foc_pi_step(&pi, &g, 0));
}

TK_CASES(TK_CASE(case_step_response), TK_CASE(case_windup_recovery),
         TK_CASE(case_windup_slow_ramp), TK_CASE(case_bumpless_preset),
         TK_CASE(case_integrator_in_range), TK_CASE(case_kp_shift),
         TK_CASE(case_set_limits))
