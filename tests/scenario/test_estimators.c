/*
 * Sensorless estimators running the loop on their own angle (after a
 * sensored start), on the motor of the build's userparms.h with the
 * controller's parameters equal to the plant unless a case says otherwise.
 * Limits from the estimator issue: angle error RMS <= 3 deg and peak
 * <= 6 deg (PLL, Luenberger; flux RMS <= 5 deg), speed estimate error
 * <= 1 %; detuned motor RMS <= 10 deg; lowest speed with RMS <= 10 deg
 * at most 5 % of the maximum speed.
 */
#include <stdio.h>

#include "estimator_metrics.h"
#include "foc/config.h"
#include "testkit.h"

typedef struct {
    foc_est_kind_t kind;
    double rms_max_deg;
    double peak_max_deg;
} limits_t;

static const limits_t pll_limits = { FOC_EST_PLL, 3.0, 6.0 };
/* Flux: the issue gives only RMS <= 5 deg; 10 deg peak is our choice. */
static const limits_t flux_limits = { FOC_EST_FLUX, 5.0, 10.0 };
static const limits_t luen_limits = { FOC_EST_LUENBERGER, 3.0, 6.0 };

static void check_case(const limits_t *lim, const char *label, const est_case_t *c,
                       double rms_max, double peak_max)
{
    est_result_t r;
    est_measure(lim->kind, c, &r);
    TK_CHECK(est_check(label, &r, rms_max, peak_max, 1.0, c->speed_rpm), "%s", label);
}

static void speeds_and_loads(const limits_t *lim)
{
    const double speeds[] = { 500.0, 1000.0, 2000.0, 3000.0 };
    const double loads[] = { 0.0, 0.05 };
    for (size_t i = 0; i < 4; i++) {
        for (size_t j = 0; j < 2; j++) {
            const est_case_t c = { speeds[i], loads[j], 30.0 + 47.0 * (double)i, NULL, 0, 0 };
            char label[64];
            snprintf(label, sizeof label, "%s %5.0f rpm %.2f Nm", foc_est_name(lim->kind),
                     speeds[i], loads[j]);
            check_case(lim, label, &c, lim->rms_max_deg, lim->peak_max_deg);
        }
    }
}

static void reverse(const limits_t *lim)
{
    const double loads[] = { 0.0, 0.05 };
    for (size_t j = 0; j < 2; j++) {
        const est_case_t c = { -1000.0, loads[j], 250.0, NULL, 0, 0 };
        char label[64];
        snprintf(label, sizeof label, "%s -1000 rpm %.2f Nm", foc_est_name(lim->kind), loads[j]);
        check_case(lim, label, &c, lim->rms_max_deg, lim->peak_max_deg);
    }
}

/* The real motor: Rs +30 %, Ls -20 %, flux -10 % from userparms.h.
 * Limits from what the three estimators measure (Hurst075): no load RMS
 * 0.107-0.118 deg, peak 0.242-0.372 deg -> 0.5 and 1.2 deg; 0.05 Nm RMS
 * 2.87-2.90 deg, peak 2.97-3.03 deg (the bias dL iq / psi) -> 10 and
 * 10 deg.  (The peak was limited at 180 deg, which the error, wrapped by
 * remainder(.., 360), can never exceed.) */
static void detuned(const limits_t *lim)
{
    char plant[256];
    est_detuned_plant(plant, sizeof plant);
    const double loads[] = { 0.0, 0.05 };
    const double rms_max[] = { 0.5, 10.0 };
    const double peak_max[] = { 1.2, 10.0 };
    for (size_t j = 0; j < 2; j++) {
        const est_case_t c = { 1000.0, loads[j], 160.0, plant, 0, 0 };
        char label[64];
        snprintf(label, sizeof label, "%s detuned 1000 rpm %.2f Nm", foc_est_name(lim->kind),
                 loads[j]);
        check_case(lim, label, &c, rms_max[j], peak_max[j]);
    }
}

/* One plant parameter at `scale` x its nominal value, all else equal,
 * 0.05 Nm at `speed`, the nominal motor's limits. */
static void check_scaled(const limits_t *lim, const char *param, double nominal, double scale,
                         double speed, double angle, int aligned_start)
{
    char plant[64];
    snprintf(plant, sizeof plant, "0 plant %s %g", param, scale * nominal);
    const est_case_t c = { speed, 0.05, angle, plant, 0, aligned_start };
    char label[64];
    snprintf(label, sizeof label, "%s %s x%.2f %5.0f rpm", foc_est_name(lim->kind), param, scale,
             speed);
    check_case(lim, label, &c, lim->rms_max_deg, lim->peak_max_deg);
}

/* The magnet's flux off MOTOR_KE (tolerance, temperature), in both
 * directions (the PLL's eq. 2 alone was 25.8 deg off at x0.75, 12.0 deg at
 * x1.3 and 102 deg at x1.3 in reverse). */
static void flux_mismatch(const limits_t *lim)
{
    const double scales[] = { 0.75, 1.3 };
    const double speeds[] = { 1000.0, -1000.0 };
    for (size_t i = 0; i < 2; i++) {
        for (size_t j = 0; j < 2; j++) {
            check_scaled(lim, "flux", FOC_FLUX_WB, scales[i], speeds[j], 70.0 + 90.0 * (double)j, 0);
        }
    }
}

/* The winding's resistance off MOTOR_RS_OHM (x0.7, x1.6: temperature,
 * cables, the data sheet) after the sensorless start: the alignment
 * measures Rs for the PLL and the flux estimator (controller.c
 * identify_rs; without it, neither starts at x0.7 and the flux estimator
 * is 10.7 deg off at x1.6). */
static void rs_mismatch(const limits_t *lim)
{
    const double scales[] = { 0.7, 1.6 };
    for (size_t i = 0; i < 2; i++) {
        check_scaled(lim, "rs", MOTOR_RS_OHM, scales[i], 500.0, 200.0, 1);
    }
}

/* The winding's inductance off MOTOR_LD_H / MOTOR_LQ_H (x0.6, x1.5)
 * after the sensorless start, with the load of 0.05 Nm: the alignment
 * measures it for the PLL and the flux estimator (controller.c
 * identify_ls; without it both are 4.8 deg RMS off at x0.6 and 5.9 deg
 * at x1.5, the angle error dL iq / psi; with it 0.03-0.28 deg). */
static void ls_mismatch(const limits_t *lim)
{
    const double scales[] = { 0.6, 1.5 };
    for (size_t i = 0; i < 2; i++) {
        char plant[128];
        snprintf(plant, sizeof plant, "0 plant ld %g\n0 plant lq %g", scales[i] * MOTOR_LD_H,
                 scales[i] * MOTOR_LQ_H);
        const est_case_t c = { 1000.0, 0.05, 120.0, plant, 0, 1 };
        char label[64];
        snprintf(label, sizeof label, "%s ls x%.2f 1000 rpm", foc_est_name(lim->kind), scales[i]);
        check_case(lim, label, &c, lim->rms_max_deg, lim->peak_max_deg);
    }
}

/* The same inductance errors after a start into a rotor turning at
 * 1000 rpm (spun, let go once CALIB is over): CATCH probes the inductance
 * once its estimate has locked (controller.c catch_tick; without the
 * probe the PLL is 4.7 and 6.0 deg RMS off, the flux estimator 4.7 deg
 * at x0.6). */
static void ls_mismatch_caught(const limits_t *lim)
{
    const double scales[] = { 0.6, 1.5 };
    for (size_t i = 0; i < 2; i++) {
        char plant[160];
        snprintf(plant, sizeof plant, "0 plant ld %g\n0 plant lq %g\n0 spin 1000\n%g unlock",
                 scales[i] * MOTOR_LD_H, scales[i] * MOTOR_LQ_H, CALIB_TIME_S + 0.005);
        const est_case_t c = { 1000.0, 0.05, 120.0, plant, 0, 1 };
        char label[64];
        snprintf(label, sizeof label, "%s ls x%.2f caught at 1000 rpm", foc_est_name(lim->kind),
                 scales[i]);
        check_case(lim, label, &c, lim->rms_max_deg, lim->peak_max_deg);
    }
}

static void lowest_speed(const limits_t *lim)
{
    const double speeds[] = { 400, 300, 250, 200, 175, 150, 125, 100, 75, 50, 35, 25 };
    const double lowest = est_lowest_speed(lim->kind, speeds, 12, 10.0);
    const double target = 0.05 * MOTOR_MAX_SPEED_RPM;
    printf("%s: lowest steady speed with angle rms <= 10 deg: %.0f rpm (target <= %.0f)\n",
           foc_est_name(lim->kind), lowest, target);
    TK_CHECK(lowest > 0.0 && lowest <= target, "lowest speed %.0f rpm", lowest);
}

static void case_pll_speeds_and_loads(void) { speeds_and_loads(&pll_limits); }
static void case_pll_reverse(void) { reverse(&pll_limits); }
static void case_pll_detuned_motor(void) { detuned(&pll_limits); }
static void case_pll_lowest_speed(void) { lowest_speed(&pll_limits); }
static void case_pll_flux_mismatch(void) { flux_mismatch(&pll_limits); }
static void case_pll_rs_mismatch(void) { rs_mismatch(&pll_limits); }
static void case_pll_ls_mismatch(void) { ls_mismatch(&pll_limits); }
static void case_pll_ls_mismatch_caught(void) { ls_mismatch_caught(&pll_limits); }
static void case_flux_speeds_and_loads(void) { speeds_and_loads(&flux_limits); }
static void case_flux_reverse(void) { reverse(&flux_limits); }
static void case_flux_detuned_motor(void) { detuned(&flux_limits); }
static void case_flux_lowest_speed(void) { lowest_speed(&flux_limits); }
static void case_flux_flux_mismatch(void) { flux_mismatch(&flux_limits); }
static void case_flux_rs_mismatch(void) { rs_mismatch(&flux_limits); }
static void case_flux_ls_mismatch(void) { ls_mismatch(&flux_limits); }
static void case_flux_ls_mismatch_caught(void) { ls_mismatch_caught(&flux_limits); }
static void case_luenberger_speeds_and_loads(void) { speeds_and_loads(&luen_limits); }
static void case_luenberger_reverse(void) { reverse(&luen_limits); }
static void case_luenberger_detuned_motor(void) { detuned(&luen_limits); }
static void case_luenberger_lowest_speed(void) { lowest_speed(&luen_limits); }
static void case_luenberger_flux_mismatch(void) { flux_mismatch(&luen_limits); }

TK_CASES(TK_CASE(case_pll_speeds_and_loads), TK_CASE(case_pll_reverse),
         TK_CASE(case_pll_detuned_motor), TK_CASE(case_pll_lowest_speed),
         TK_CASE(case_pll_flux_mismatch), TK_CASE(case_pll_rs_mismatch),
         TK_CASE(case_pll_ls_mismatch), TK_CASE(case_flux_ls_mismatch),
         TK_CASE(case_pll_ls_mismatch_caught), TK_CASE(case_flux_ls_mismatch_caught),
         TK_CASE(case_flux_speeds_and_loads), TK_CASE(case_flux_reverse),
         TK_CASE(case_flux_detuned_motor), TK_CASE(case_flux_lowest_speed),
         TK_CASE(case_flux_flux_mismatch), TK_CASE(case_flux_rs_mismatch),
         TK_CASE(case_luenberger_speeds_and_loads), TK_CASE(case_luenberger_reverse),
         TK_CASE(case_luenberger_detuned_motor), TK_CASE(case_luenberger_lowest_speed),
         TK_CASE(case_luenberger_flux_mismatch))
