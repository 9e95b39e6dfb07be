/*
 * Online Rs adaptation (foc/rs_adapt.h) on the machine's steady state,
 * computed here in double precision from the build's motor (SI units,
 * then the Q15 bases):
 *   vd = Rs id - we Lq iq,   vq = Rs iq + we (Ld id + psi).
 * From the alignment's ratio the adaptation must reach the winding's
 * Rs / MOTOR_RS_OHM within 1 %, motoring and braking, in both
 * directions; stop at its range's ends (-1/8, +1/2 of where it began);
 * and hold the ratio where its gate is shut.
 */
#include <math.h>
#include <stdio.h>

#include "foc/config.h"
#include "foc/rs_adapt.h"
#include "ideal_pmsm.h"
#include "testkit.h"

#define TICKS 4000 /* 2 s of slow ticks at the Hurst075's 2 kHz */

/* Runs TICKS ticks of the steady state (rs_true in ohms, speed in rpm,
 * currents in A) from `start` x MOTOR_RS_OHM; returns the final ratio. */
static double run(double rs_true, double rpm, double id, double iq, double start)
{
    const double we = rpm * MOTOR_POLE_PAIRS * 2.0 * FOC_PI_D / 60.0;
    const double vd = rs_true * id - we * MOTOR_LQ_H * iq;
    const double vq = rs_true * iq + we * (MOTOR_LD_H * id + FOC_FLUX_WB);
    const foc_dq_t v = { ideal_q15(vd / FOC_V_BASE_V), ideal_q15(vq / FOC_V_BASE_V) };
    const foc_dq_t i = { ideal_q15(id / FOC_I_BASE_A), ideal_q15(iq / FOC_I_BASE_A) };
    const q15_t w = ideal_q15(rpm / SPEED_BASE_RPM);
    foc_rs_adapt_t a;
    q15_t ratio = (q15_t)lround(start * 16384.0);
    foc_rs_adapt_reset(&a, v, i, w, ratio);
    for (int k = 0; k < TICKS; k++) {
        ratio = foc_rs_adapt_tick(&a, v, i, w, ratio, FOC_RATIO_ONE_Q14);
    }
    return ratio / 16384.0;
}

static void check_converges(double scale, double rpm_frac, double id_frac, double iq_frac,
                            double start, const char *what)
{
    const double rpm = rpm_frac * MOTOR_MAX_SPEED_RPM;
    const double id = id_frac * MOTOR_RATED_CURRENT_A;
    const double iq = iq_frac * MOTOR_RATED_CURRENT_A;
    const double got = run(scale * MOTOR_RS_OHM, rpm, id, iq, start);
    printf("  %s: Rs x%.2f from x%.2f at %.0f rpm, id %.2f A, iq %.2f A: x%.4f\n", what, scale,
           start, rpm, id, iq, got);
    TK_CHECK(fabs(got / scale - 1.0) <= 0.01, "%s: x%.4f for x%.2f", what, got, scale);
}

static void case_converges_motoring(void)
{
    check_converges(1.3, 0.5, -0.5, 0.8, 1.0, "warm winding");
    check_converges(0.9, 0.5, -0.5, 0.8, 1.0, "a cooler winding");
    check_converges(1.4, 0.3, -0.6, 0.6, 1.0, "lower speed");
}

static void case_converges_braking_and_reverse(void)
{
    check_converges(1.3, 0.5, -0.5, -0.8, 1.0, "braking");
    check_converges(1.3, -0.5, -0.5, -0.8, 1.0, "reverse");
    check_converges(1.3, -0.5, -0.5, 0.8, 1.0, "reverse, braking");
}

/* The range: from the alignment's x1.0, a winding at x2.0 is followed to
 * x1.5 only, one at x0.5 to x0.875. */
static void case_range(void)
{
    const double ir = MOTOR_RATED_CURRENT_A;
    const double rpm = 0.5 * MOTOR_MAX_SPEED_RPM;
    const double up = run(2.0 * MOTOR_RS_OHM, rpm, -0.5 * ir, 0.8 * ir, 1.0);
    const double down = run(0.5 * MOTOR_RS_OHM, rpm, -0.5 * ir, 0.8 * ir, 1.0);
    printf("  x2.0 -> x%.4f, x0.5 -> x%.4f\n", up, down);
    TK_CHECK(up == 1.5 && down == 0.875, "x%.4f x%.4f", up, down);
}

/* The gate: no d current worth a quarter of the q current, no ohmic drop
 * worth an eighth of the EMF, or no speed: the ratio stays put. */
static void case_gate_holds(void)
{
    const double rs = 1.3 * MOTOR_RS_OHM;
    const double rpm = 0.5 * MOTOR_MAX_SPEED_RPM;
    const double ir = MOTOR_RATED_CURRENT_A;
    const double held[][3] = {
        { rpm, 0.0, 0.8 * ir },       /* no d current */
        { rpm, -0.1 * ir, 0.8 * ir }, /* d current below a quarter of q */
        { rpm, -0.5 * ir, 0.0 },      /* no q current: no drop */
        { rpm, -0.5 * ir, 0.15 * ir }, /* a drop below a quarter of the EMF */
        { 0.0, -0.5 * ir, 0.8 * ir }, /* standstill */
    };
    for (size_t k = 0; k < sizeof held / sizeof held[0]; k++) {
        const double got = run(rs, held[k][0], held[k][1], held[k][2], 1.0);
        TK_CHECK(got == 1.0, "gate %zu: x%.4f", k, got);
    }
}

TK_CASES(TK_CASE(case_converges_motoring), TK_CASE(case_converges_braking_and_reverse),
         TK_CASE(case_range), TK_CASE(case_gate_holds))
