/*
 * First-order low-pass filter (foc/lpf.h).
 */
#include <math.h>
#include <stdint.h>

#include "foc/lpf.h"
#include "testkit.h"

/* Steps to reach 1 - 1/e of a step, linearly interpolated between
 * samples. */
static double measured_tau(q15_t k, q15_t y0, q15_t x)
{
    foc_lpf_q15_t f;
    const double target = y0 + (1.0 - exp(-1.0)) * (x - y0);
    double prev = y0;
    foc_lpf_init(&f, y0);
    for (int n = 1; n < 1000000; n++) {
        const double y = foc_lpf_step(&f, x, k);
        if ((x > y0) ? (y >= target) : (y <= target)) {
            return n - 1 + (target - prev) / (y - prev);
        }
        prev = y;
    }
    return -1.0;
}

/* Time constant within 1 % of the one the Q15 K implies,
 * tau = -1 / ln(1 - K) samples, for slow and fast filters and both step
 * directions; every sample within STEP_LSB of the double-precision
 * response. */
#define STEP_LSB 2.0

static void case_lpf_step_response(void)
{
    static const q15_t ks[] = { Q15(0.001), Q15(0.01), Q15(0.05), Q15(0.2) };
    static const q15_t steps[][2] = { { 0, 20000 }, { 30000, -30000 },
                                      { -32768, 32767 } };
    double worst_tau = 0.0;
    double worst_lsb = 0.0;
    for (size_t i = 0; i < sizeof ks / sizeof ks[0]; i++) {
        const double kd = ks[i] / 32768.0;
        const double tau = -1.0 / log(1.0 - kd);
        for (size_t s = 0; s < sizeof steps / sizeof steps[0]; s++) {
            const q15_t y0 = steps[s][0];
            const q15_t x = steps[s][1];
            const double t = measured_tau(ks[i], y0, x);
            worst_tau = fmax(worst_tau, fabs(t / tau - 1.0));
            TK_CHECK(fabs(t / tau - 1.0) <= 0.01, "K=%d step %d->%d: tau=%.2f "
                     "want %.2f", ks[i], y0, x, t, tau);

            foc_lpf_q15_t f;
            double worst = 0.0;
            foc_lpf_init(&f, y0);
            for (int n = 1; n <= (int)(8.0 * tau); n++) {
                const double want = x + (y0 - x) * pow(1.0 - kd, n);
                const double err = fabs(foc_lpf_step(&f, x, ks[i]) - want);
                worst = (err > worst) ? err : worst;
            }
            worst_lsb = fmax(worst_lsb, worst);
            TK_CHECK(worst <= STEP_LSB, "K=%d step %d->%d: err %.2f LSB",
                     ks[i], y0, x, worst);
        }
    }
    printf("lpf: tau error %.3f %%, response error %.2f LSB\n",
           100.0 * worst_tau, worst_lsb);
}

/* A small K still reaches the input exactly (no dead band from
 * truncation), from above and below, and then stays there. */
static void case_lpf_small_k_reaches_input(void)
{
    static const q15_t ks[] = { Q15(0.001), 1 };
    static const q15_t steps[][2] = { { 0, 1000 },  { 0, -1000 },
                                      { 0, 1 },     { 0, -1 },
                                      { 500, 499 }, { 32767, -32768 },
                                      { -32768, 32767 } };
    for (size_t i = 0; i < sizeof ks / sizeof ks[0]; i++) {
        /* Within ~ 40 tau plus, for the last LSB, 32768 / K steps. */
        const long n = 40L * 32768L / ks[i] + 32768L / ks[i] + 10;
        for (size_t s = 0; s < sizeof steps / sizeof steps[0]; s++) {
            foc_lpf_q15_t f;
            foc_lpf_init(&f, steps[s][0]);
            TK_CHECK(foc_lpf_out(&f) == steps[s][0], "init");
            long reached = -1;
            for (long k = 0; k < n && reached < 0; k++) {
                if (foc_lpf_step(&f, steps[s][1], ks[i]) == steps[s][1]) {
                    reached = k;
                }
            }
            TK_CHECK(reached >= 0, "K=%d step %d->%d: stuck at %d", ks[i],
                     steps[s][0], steps[s][1], foc_lpf_out(&f));
            for (int k = 0; k < 1000; k++) {
                foc_lpf_step(&f, steps[s][1], ks[i]);
            }
            TK_CHECK(foc_lpf_out(&f) == steps[s][1], "K=%d: left %d for %d",
                     ks[i], steps[s][1], foc_lpf_out(&f));
        }
    }
}

TK_CASES(TK_CASE(case_lpf_step_response),
         TK_CASE(case_lpf_small_k_reaches_input))
