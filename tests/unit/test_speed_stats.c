/*
 * Speed FIFO statistics (foc/speed_stats.h) against a double-precision
 * reference over the same 64-sample window.
 */
#include <math.h>
#include <stdint.h>

#include "foc/speed_stats.h"
#include "testkit.h"

#define N FOC_SPEED_STATS_N

/* Limits, in LSB: mean (Q15) rounded, mu^2 (Q30) and variance (Q30) as
 * documented in speed_stats.h. */
#define MEAN_LSB 0.5
#define MU2_LSB 0.5
#define VAR_LSB 33.0

static uint32_t rng = 12345u;
static int32_t rand_q15(void)
{
    rng = rng * 1664525u + 1013904223u;
    return (int32_t)(rng >> 16) - 32768;
}

typedef struct {
    double mean, mu2, var; /* Q15, Q30, Q30 */
} ref_t;

/* The last min(count, 64) samples of `hist` (missing ones = 0). */
static ref_t reference(const q15_t *hist, long count)
{
    double sum = 0.0, sum_sq = 0.0;
    for (long k = count - N; k < count; k++) {
        const double x = (k >= 0) ? hist[k] : 0.0;
        sum += x;
        sum_sq += x * x;
    }
    ref_t r;
    r.mean = sum / N;
    r.mu2 = r.mean * r.mean;
    r.var = sum_sq / N - r.mu2;
    return r;
}

typedef struct {
    double mean, mu2, var;
    long decisions, disagreements;
} worst_t;

/* Pushes `n` samples from `gen` and compares every step. */
static void run_sequence(const char *name, int32_t (*gen)(long), long n, worst_t *w)
{
    static q15_t hist[4096];
    foc_speed_stats_t s;
    foc_speed_stats_reset(&s);
    const q15_t thresholds[] = { 0, 1, 2048, 8192, 32767 }; /* 0.0625 = 2048 */
    for (long k = 0; k < n && k < 4096; k++) {
        hist[k] = (q15_t)gen(k);
        foc_speed_stats_push(&s, hist[k]);
        const ref_t r = reference(hist, k + 1);
        const double e_mean = fabs(foc_speed_stats_mean(&s) - r.mean);
        const double e_mu2 = fabs(foc_speed_stats_mean_sq(&s) - r.mu2);
        const double e_var = fabs(foc_speed_stats_variance(&s) - r.var);
        w->mean = fmax(w->mean, e_mean);
        w->mu2 = fmax(w->mu2, e_mu2);
        w->var = fmax(w->var, e_var);
        TK_CHECK(e_mean <= MEAN_LSB, "%s k=%ld: mean %d want %.3f", name, k,
                 foc_speed_stats_mean(&s), r.mean);
        TK_CHECK(e_mu2 <= MU2_LSB, "%s k=%ld: mu2 %ld want %.1f", name, k,
                 (long)foc_speed_stats_mean_sq(&s), r.mu2);
        TK_CHECK(e_var <= VAR_LSB, "%s k=%ld: var %ld want %.1f", name, k,
                 (long)foc_speed_stats_variance(&s), r.var);
        for (size_t t = 0; t < sizeof thresholds / sizeof thresholds[0]; t++) {
            const double limit = r.mu2 * thresholds[t] / 32768.0;
            const int want = (k + 1 >= N) && (r.var <= limit);
            const int got = foc_speed_stats_reliable(&s, thresholds[t]);
            /* Within the documented error of the boundary either answer
             * is right. */
            if (fabs(r.var - limit) > VAR_LSB + MU2_LSB + 1.0) {
                w->decisions++;
                w->disagreements += (got != want);
                TK_CHECK(got == want, "%s k=%ld thr=%d: reliable %d want %d "
                         "(var %.0f limit %.0f)", name, k, thresholds[t], got,
                         want, r.var, limit);
            }
        }
    }
}

static int32_t gen_uniform(long k) { (void)k; return rand_q15(); }
static int32_t gen_noisy_speed(long k)
{
    /* 1000 rpm-ish with noise of a few percent, then a sign change */
    const int32_t base = (k < 300) ? 5461 : -5461;
    return base + rand_q15() / 128;
}
static int32_t gen_alternating_full(long k) { return (k & 1) ? 32767 : -32768; }
static int32_t gen_max(long k) { (void)k; return 32767; }
static int32_t gen_min(long k) { (void)k; return -32768; }
static int32_t gen_ramp(long k) { return (int32_t)((k * 131) % 65536) - 32768; }
static int32_t gen_small(long k) { return (int32_t)(k % 7) - 3; }
static int32_t gen_spike(long k) { return (k % 97 == 50) ? -32768 : 1000; }
static int32_t gen_slow_sine(long k) { return (int32_t)lround(20000.0 * sin(0.01 * (double)k)); }

static void case_matches_double_reference(void)
{
    struct {
        const char *name;
        int32_t (*gen)(long);
    } seqs[] = {
        { "uniform", gen_uniform },       { "noisy speed, reversal", gen_noisy_speed },
        { "alternating full scale", gen_alternating_full },
        { "all +max", gen_max },          { "all -32768", gen_min },
        { "ramp wrapping", gen_ramp },    { "tiny values", gen_small },
        { "spikes", gen_spike },          { "slow sine", gen_slow_sine },
    };
    worst_t w = { 0, 0, 0, 0, 0 };
    for (size_t i = 0; i < sizeof seqs / sizeof seqs[0]; i++) {
        run_sequence(seqs[i].name, seqs[i].gen, 1000, &w);
    }
    printf("speed_stats: worst mean %.3f LSB, mu2 %.1f LSB, variance %.1f LSB (Q30); "
           "%ld reliability decisions, %ld disagreements\n",
           w.mean, w.mu2, w.var, w.decisions, w.disagreements);
}

/* Full-scale windows: exact figures, no overflow. */
static void case_full_scale_edges(void)
{
    foc_speed_stats_t s;
    foc_speed_stats_reset(&s);
    for (unsigned k = 0; k < N; k++) {
        foc_speed_stats_push(&s, -32768);
    }
    TK_CHECK(foc_speed_stats_mean(&s) == -32768, "mean %d", foc_speed_stats_mean(&s));
    TK_CHECK(foc_speed_stats_mean_sq(&s) == 1073741824L, "mu2 %ld",
             (long)foc_speed_stats_mean_sq(&s));
    TK_CHECK(foc_speed_stats_variance(&s) == 0, "var %ld", (long)foc_speed_stats_variance(&s));
    TK_CHECK(foc_speed_stats_reliable(&s, 2048) == 1, "constant full scale is reliable");

    for (unsigned k = 0; k < N; k++) {
        foc_speed_stats_push(&s, 32767);
    }
    TK_CHECK(foc_speed_stats_mean(&s) == 32767, "mean %d", foc_speed_stats_mean(&s));
    TK_CHECK(foc_speed_stats_mean_sq(&s) == 32767L * 32767L, "mu2 %ld",
             (long)foc_speed_stats_mean_sq(&s));
    TK_CHECK(foc_speed_stats_variance(&s) <= 32, "var %ld", (long)foc_speed_stats_variance(&s));

    /* +-full scale alternating: mean -1/2, variance 32767.5^2 (~2^30) */
    for (unsigned k = 0; k < N; k++) {
        foc_speed_stats_push(&s, (k & 1u) ? 32767 : -32768);
    }
    const double var = foc_speed_stats_variance(&s);
    TK_CHECK(fabs(var - 32767.5 * 32767.5) <= VAR_LSB, "variance %.1f", var);
    TK_CHECK(foc_speed_stats_reliable(&s, 32767) == 0, "alternating is unreliable");
}

/* Not reliable before 64 samples; reset empties; a zero window counts as
 * reliable (documented: callers check the mean). */
static void case_window_and_reset(void)
{
    foc_speed_stats_t s;
    foc_speed_stats_reset(&s);
    for (unsigned k = 0; k < N - 1u; k++) {
        foc_speed_stats_push(&s, 10000);
        TK_CHECK(foc_speed_stats_reliable(&s, 2048) == 0, "reliable after %u samples", k + 1u);
    }
    foc_speed_stats_push(&s, 10000);
    TK_CHECK(foc_speed_stats_reliable(&s, 2048) == 1, "constant window not reliable");
    TK_CHECK(foc_speed_stats_reliable(&s, -1) == 0, "negative threshold");
    foc_speed_stats_reset(&s);
    TK_CHECK(foc_speed_stats_mean(&s) == 0 && foc_speed_stats_variance(&s) == 0 &&
                 foc_speed_stats_reliable(&s, 2048) == 0, "reset");
    for (unsigned k = 0; k < N; k++) {
        foc_speed_stats_push(&s, 0);
    }
    TK_CHECK(foc_speed_stats_reliable(&s, 2048) == 1, "zero window");
}

/* The running sums never drift: after a million pushes they equal the sums
 * recomputed from the FIFO. */
static void case_no_drift(void)
{
    foc_speed_stats_t s;
    foc_speed_stats_reset(&s);
    for (long k = 0; k < 1000000L; k++) {
        foc_speed_stats_push(&s, (q15_t)rand_q15());
    }
    int32_t sum = 0, sum_sq = 0;
    for (unsigned k = 0; k < N; k++) {
        const int32_t x = s.fifo[k];
        sum += x;
        sum_sq += (x * x + 32) >> 6;
    }
    TK_CHECK(sum == s.sum && sum_sq == s.sum_sq, "sum %ld/%ld sum_sq %ld/%ld", (long)s.sum,
             (long)sum, (long)s.sum_sq, (long)sum_sq);
}

TK_CASES(TK_CASE(case_matches_double_reference), TK_CASE(case_full_scale_edges),
         TK_CASE(case_window_and_reset), TK_CASE(case_no_drift))
