/*
 * Current-sensor gain balance (foc/gain_balance.h) in a loop simulated
 * here in double precision: the build's motor (Rs, L, flux) turning at a
 * constant speed, its true phase currents seen through sensors of given
 * gains (two shunts A, B with C from them, or three), a current PI in
 * the rotor frame (bandwidth 1 kHz, double) regulating what the block
 * corrects, the block's tick every CONTROL_SLOW_DIVIDER periods.
 *
 * The expected Gh is the sensors' negative-sequence coefficient, from
 * their measurement matrix M (alpha, beta measured per unit alpha, beta
 * true): i_m = P i + Q conj(i) with P = ((Mxx + Myy) + j (Myx - Mxy)) / 2,
 * Q = ((Mxx - Myy) + j (Myx + Mxy)) / 2, and the correction leaves no
 * negative sequence where Gh = Q / conj(P).  The oracle of the effect is
 * the true current's component at -2 theta in the rotor frame.
 */
#include <complex.h>
#include <math.h>
#include <stdio.h>

#include "foc/config.h"
#include "foc/gain_balance.h"
#include "foc/trig.h"
#include "ideal_pmsm.h"
#include "testkit.h"

#define SECONDS 4.0
#define TOL_EXACT 0.05 /* measured 0.4-2.7 % */
#define CUT_EXACT 0.06 /* 0.00-0.03 */
#define TOL_NOISY 0.4 /* 2.8-13.6 % */
#define CUT_NOISY 0.5 /* 0.05-0.17 */

typedef struct {
    double gain[3]; /* per phase: measured = (1 + gain) x true */
    int three;      /* 1: three sensors (Clarke of three), 0: A and B */
    double noise_a; /* RMS per phase, A */
} sensors_t;

typedef struct {
    double complex g_learned; /* Gh at the end */
    double complex g_expected;
    double neg_a;             /* true current at -2 theta, A (last 0.5 s) */
} result_t;

/* x in Q15 of `base` (the unit tests' shared rounding, ideal_pmsm.h). */
static q15_t q15_of(double x, double base) { return ideal_q15(x / base); }

static uint32_t lcg = 12345u;
static double gauss(void)
{
    double s = 0.0;
    for (int k = 0; k < 12; k++) {
        lcg = lcg * 1664525u + 1013904223u;
        s += (double)(lcg >> 8) / 16777216.0;
    }
    return s - 6.0;
}

/* The sensors' alpha/beta from true alpha/beta (no noise). */
static double complex measure(const sensors_t *s, double complex i)
{
    const double ia = creal(i);
    const double ib = -0.5 * creal(i) + 0.5 * sqrt(3.0) * cimag(i);
    const double ic = -ia - ib;
    const double ma = (1.0 + s->gain[0]) * ia;
    const double mb = (1.0 + s->gain[1]) * ib;
    const double mc = (1.0 + s->gain[2]) * ic;
    if (s->three) {
        return (2.0 * ma - mb - mc) / 3.0 + I * (mb - mc) / sqrt(3.0);
    }
    return ma + I * (ma + 2.0 * mb) / sqrt(3.0);
}

static double complex expected_g(const sensors_t *s)
{
    const double complex mx = measure(s, 1.0);
    const double complex my = measure(s, I);
    const double complex p = ((creal(mx) + cimag(my)) + I * (cimag(mx) - creal(my))) / 2.0;
    const double complex q = ((creal(mx) - cimag(my)) + I * (cimag(mx) + creal(my))) / 2.0;
    return q / conj(p);
}

/* Runs SECONDS at `rpm` with the q current `iq_a`; learn: the block's
 * tick runs (else Gh stays zero). */
static void run(const sensors_t *s, double rpm, double iq_a, int learn, result_t *out)
{
    const double ts = 1.0 / PWM_FREQUENCY_HZ;
    const double we = rpm * MOTOR_POLE_PAIRS * 2.0 * FOC_PI_D / 60.0;
    const double l = 0.5 * (MOTOR_LD_H + MOTOR_LQ_H);
    const double wc = 2.0 * FOC_PI_D * 1000.0;
    const double kp = l * wc;
    const double ki = MOTOR_RS_OHM * wc;
    const double complex i_ref = I * iq_a;
    const double complex emf = I * we * FOC_FLUX_WB;
    foc_gain_balance_t gb;
    foc_gb_init(&gb);
    double complex i_dq = 0.0;                       /* true, rotor frame */
    double complex integ = MOTOR_RS_OHM * i_ref + emf + I * we * l * i_ref; /* steady state */
    double complex v = integ;
    double complex neg_sum = 0.0;
    double neg_n = 0.0;
    const long periods = lround(SECONDS / ts);
    lcg = 12345u;
    for (long k = 0; k < periods; k++) {
        const double theta = fmod(we * (double)k * ts, 2.0 * FOC_PI_D);
        const double complex rot = cexp(I * theta);
        /* measured, Q15, corrected by the block, back to the rotor frame */
        double complex m = measure(s, i_dq * rot);
        m += s->noise_a * (gauss() + I * gauss());
        const foc_ab_t m_q = { q15_of(creal(m), FOC_I_BASE_A), q15_of(cimag(m), FOC_I_BASE_A) };
        const foc_ab_t c_q = foc_gb_correct(&gb, m_q);
        const double complex i_meas =
            ((double)c_q.alpha + I * (double)c_q.beta) * FOC_I_BASE_A / 32768.0 * conj(rot);
        const double complex err = i_ref - i_meas;
        integ += ki * ts * err;
        v = integ + kp * err;
        if (learn && k % CONTROL_SLOW_DIVIDER == 0) {
            const uint16_t th16 = (uint16_t)lround(theta / (2.0 * FOC_PI_D) * 65536.0);
            const foc_dq_t v_q = { q15_of(creal(v), FOC_V_BASE_V), q15_of(cimag(v), FOC_V_BASE_V) };
            const foc_dq_t i_q = { q15_of(creal(i_meas), FOC_I_BASE_A),
                                   q15_of(cimag(i_meas), FOC_I_BASE_A) };
            if (k == 0) {
                foc_gb_follow(&gb, v_q, i_q);
            } else {
                foc_gb_tick(&gb, th16, v_q, i_q, q15_of(rpm, SPEED_BASE_RPM));
            }
        }
        /* the machine over the period, 20 Euler substeps */
        for (int j = 0; j < 20; j++) {
            const double complex di = (v - MOTOR_RS_OHM * i_dq - I * we * l * i_dq - emf) / l;
            i_dq += di * ts / 20.0;
        }
        if ((double)k * ts >= SECONDS - 0.5) {
            neg_sum += (i_dq - i_ref) * cexp(I * 2.0 * theta);
            neg_n += 1.0;
        }
    }
    out->g_learned = (gb.g_re + I * gb.g_im) / 32768.0;
    out->g_expected = expected_g(s);
    out->neg_a = cabs(neg_sum / neg_n);
}

/* Learns within `tol` of the expected Gh, and the true negative sequence
 * falls to `cut` of what it is unbalanced. */
static void check_learns(const sensors_t *s, double rpm, double iq_a, double tol, double cut,
                         const char *what)
{
    result_t off;
    result_t on;
    run(s, rpm, iq_a, 0, &off);
    run(s, rpm, iq_a, 1, &on);
    const double err = cabs(on.g_learned - on.g_expected) / cabs(on.g_expected);
    printf("%s, %.0f rpm, iq %.2f A: Gh %.5f%+.5fj, expected %.5f%+.5fj (off by %.1f %%, limit "
           "%.0f %%); true negative sequence %.2f mA, %.2f mA unbalanced (%.2f x, limit %.2f)\n",
           what, rpm, iq_a, creal(on.g_learned), cimag(on.g_learned), creal(on.g_expected),
           cimag(on.g_expected), 100.0 * err, 100.0 * tol, on.neg_a * 1e3, off.neg_a * 1e3,
           on.neg_a / off.neg_a, cut);
    TK_CHECK(err <= tol, "%s: Gh off by %.1f %%", what, 100.0 * err);
    TK_CHECK(on.neg_a <= cut * off.neg_a, "%s: negative sequence %.2f of unbalanced", what,
             on.neg_a / off.neg_a);
}

/* The realistic plant's sensors (+2 / -2 %, two shunts), 2 codes of noise. */
static void case_learns_two_shunts(void)
{
    const sensors_t s = { { 0.02, -0.02, 0.0 }, 0, 2.0 * FOC_I_BASE_A / 512.0 };
    check_learns(&s, 2000.0, 0.86, TOL_NOISY, CUT_NOISY, "A +2 %, B -2 %");
    check_learns(&s, -2000.0, 0.86, TOL_NOISY, CUT_NOISY, "A +2 %, B -2 %, reverse");
    check_learns(&s, 1000.0, -0.86, TOL_NOISY, CUT_NOISY, "A +2 %, B -2 %, braking");
}

/* Other gains, and three sensors. */
static void case_learns_other_gains(void)
{
    const sensors_t s1 = { { 0.03, -0.01, 0.0 }, 0, 2.0 * FOC_I_BASE_A / 512.0 };
    check_learns(&s1, 1500.0, 0.6, TOL_NOISY, CUT_NOISY, "A +3 %, B -1 %");
    const sensors_t s2 = { { -0.01, 0.025, 0.0 }, 0, 2.0 * FOC_I_BASE_A / 512.0 };
    check_learns(&s2, 3000.0, 0.6, TOL_NOISY, CUT_NOISY, "A -1 %, B +2.5 %");
    const sensors_t s3 = { { 0.02, -0.02, 0.01 }, 1, 2.0 * FOC_I_BASE_A / 512.0 };
    check_learns(&s3, 2000.0, 0.86, TOL_NOISY, CUT_NOISY, "three: +2, -2, +1 %");
}

/* Without noise the learned Gh is the closed form's. */
static void case_exact_without_noise(void)
{
    const sensors_t s1 = { { 0.02, -0.02, 0.0 }, 0, 0.0 };
    check_learns(&s1, 2000.0, 0.86, TOL_EXACT, CUT_EXACT, "A +2 %, B -2 %, no noise");
    check_learns(&s1, -1000.0, -0.86, TOL_EXACT, CUT_EXACT, "A +2 %, B -2 %, no noise, reverse, braking");
    const sensors_t s2 = { { -0.01, 0.025, 0.0 }, 0, 0.0 };
    check_learns(&s2, 3000.0, 0.6, TOL_EXACT, CUT_EXACT, "A -1 %, B +2.5 %, no noise");
    const sensors_t s3 = { { 0.02, -0.02, 0.01 }, 1, 0.0 };
    check_learns(&s3, 2000.0, 0.86, TOL_EXACT, CUT_EXACT, "three: +2, -2, +1 %, no noise");
}

/* Matched sensors: Gh stays near zero (the noise alone). */
static void case_matched_stays_zero(void)
{
    const sensors_t s = { { 0.0, 0.0, 0.0 }, 0, 2.0 * FOC_I_BASE_A / 512.0 };
    result_t r;
    run(&s, 2000.0, 0.86, 1, &r);
    printf("matched: |Gh| %.5f (limit 0.005; measured 0.0016)\n", cabs(r.g_learned));
    TK_CHECK(cabs(r.g_learned) <= 0.005, "|Gh| %.5f", cabs(r.g_learned));
}

/* Where it cannot see the mismatch it holds: too slow (twice the
 * electrical frequency turning less than once in 50 ms) and too little
 * current (|W| below its floor). */
static void case_gates_hold(void)
{
    const sensors_t s = { { 0.02, -0.02, 0.0 }, 0, 2.0 * FOC_I_BASE_A / 512.0 };
    result_t r;
    const double slow_rpm = 0.8 * FOC_GB_MIN_WE_RAD_S * 60.0 / (2.0 * FOC_PI_D * MOTOR_POLE_PAIRS);
    run(&s, slow_rpm, 0.86, 1, &r);
    printf("%.0f rpm: |Gh| %.5f\n", slow_rpm, cabs(r.g_learned));
    TK_CHECK(r.g_learned == 0.0, "slow: Gh moved");
    run(&s, 2000.0, 0.05, 1, &r);
    printf("2000 rpm, 0.05 A: |Gh| %.5f\n", cabs(r.g_learned));
    TK_CHECK(r.g_learned == 0.0, "low current: Gh moved");
}

TK_CASES(TK_CASE(case_exact_without_noise), TK_CASE(case_learns_two_shunts), TK_CASE(case_learns_other_gains),
         TK_CASE(case_matched_stays_zero), TK_CASE(case_gates_hold))
