/*
 * Self-commissioning against the plant's true values (issue 12): one
 * executable per motor parameter set (like tests/torture), the real core
 * and the motor model of tools/focsim/sim.c.
 *
 *   commission_<motor> [--rs X] [--ld X] [--lq X] [--flux X] [--j X]
 *                      [--b X] [--tc X] [--dt X] [--seed N] [--table]
 *                      [--lock --expect-fail STEP]
 *
 * The plant is the motor of the userparms.h the core was built with, each
 * --<param> X scaling its value (the +-50 % mismatch of issue 12; --b the
 * viscous friction, --tc the dry, --dt the bridge's dead time
 * PWM_DEADTIME_S, which the build compensates), with 2 codes of ADC noise.
 * A `commission` runs from IDLE; the identified Rs, Ld, Lq, flux, inertia
 * and viscous friction (focsim's id_* keys) are compared with the model's
 * own parameters: the oracle never reads what the firmware says about the
 * plant, only what it identified.  Tolerances (issue 12): Rs and flux
 * +-3 %, Ld, Lq, J and B +-5 % (the dry friction is printed, not judged);
 * the dead time TOL_DT (not printed with --table).
 * MECH (J, B) must have run when the plant's flux, Ld and Lq are within
 * 10 % of the parameters (the firmware's gate is 15 % of its measures)
 * and must not have run when one is 20 % or more off.
 * Prints one line per quantity (or, --table, one Markdown row); exit 0
 * when commissioning ended in IDLE with every value in its tolerance.
 * --lock holds the rotor (the flux's spin cannot turn it); --expect-fail
 * STEP: exit 0 only if commissioning ended in FAULT COMMISSION_FAILED
 * naming that step, with no result marked valid.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "foc/config.h"
#include "scenario.h"
#include "sim.h"

#ifndef COMMISSION_MOTOR
#define COMMISSION_MOTOR "unknown"
#endif

#define TOL_RS 0.03
#define TOL_L 0.05
#define TOL_FLUX 0.03
#define TOL_MECH 0.05
#define TOL_DT 0.02 /* 3 x the Hurst075's worst at half, seeds 1..20: 0.61 % */
#define RUN_LIMIT_S 60.0 /* the fan's slow spin-up fits */

typedef struct {
    double rs, ld, lq, flux, j, b, tc, dt;
    unsigned long seed;
    int table, lock;
    const char *expect_fail; /* a step name, or NULL */
} scales_t;

static int parse_args(int argc, char **argv, scales_t *k)
{
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--table") == 0 || strcmp(argv[i], "--lock") == 0) {
            *(argv[i][2] == 't' ? &k->table : &k->lock) = 1;
            continue;
        }
        if (i + 1 >= argc) {
            return -1;
        }
        const double v = atof(argv[i + 1]);
        const char *o = argv[i++];
        if (strcmp(o, "--seed") == 0) {
            k->seed = strtoul(argv[i], NULL, 10);
            continue;
        }
        if (strcmp(o, "--expect-fail") == 0) {
            k->expect_fail = argv[i];
            continue;
        }
        if (!(v > 0.0)) {
            return -1;
        }
        if (strcmp(o, "--rs") == 0) {
            k->rs = v;
        } else if (strcmp(o, "--ld") == 0) {
            k->ld = v;
        } else if (strcmp(o, "--lq") == 0) {
            k->lq = v;
        } else if (strcmp(o, "--flux") == 0) {
            k->flux = v;
        } else if (strcmp(o, "--j") == 0) {
            k->j = v;
        } else if (strcmp(o, "--b") == 0) {
            k->b = v;
        } else if (strcmp(o, "--tc") == 0) {
            k->tc = v;
        } else if (strcmp(o, "--dt") == 0) {
            k->dt = v;
        } else {
            return -1;
        }
    }
    return 0;
}

static int check(const char *what, double id, double truth, double tol, int table)
{
    const double err = id / truth - 1.0;
    const int ok = fabs(err) <= tol;
    if (table) {
        printf(" %.4g | %.4g (%+.2f %%) |", truth, id, 100.0 * err);
    } else {
        printf("%s true=%.6g identified=%.6g error=%+.2f%% tolerance=%.0f%% %s\n", what, truth, id,
               100.0 * err, 100.0 * tol, ok ? "ok" : "FAIL");
    }
    return ok;
}

int main(int argc, char **argv)
{
    scales_t k = { 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1, 0, 0, NULL };
    if (parse_args(argc, argv, &k) != 0) {
        fprintf(stderr,
                "usage: %s [--rs X] [--ld X] [--lq X] [--flux X] [--j X] [--b X] [--tc X] [--dt X]\n"
                "          [--seed N] [--table]\n"
                "          [--lock --expect-fail STEP]\n",
                argv[0]);
        return 2;
    }
    const int table = k.table;
    char text[1024];
    snprintf(text, sizeof text,
             "0 plant noise 2\n0 plant deadtime %.9g\n0 plant rs %.9g\n0 plant ld %.9g\n"
             "0 plant lq %.9g\n0 plant flux %.9g\n0 plant j %.9g\n0 plant b %.9g\n0 plant coulomb %.9g\n"
             "%s0.01 commission\n%.1f end\n",
             PWM_DEADTIME_S * k.dt, MOTOR_RS_OHM * k.rs, MOTOR_LD_H * k.ld, MOTOR_LQ_H * k.lq,
             FOC_FLUX_WB * k.flux, MOTOR_INERTIA_KGM2 * k.j,
             MOTOR_VISCOUS_NM_PER_KRPM * 60.0 / (1000.0 * 2.0 * FOC_PI_D) * k.b, MOTOR_COULOMB_NM * k.tc,
             k.lock ? "0 lock\n" : "", RUN_LIMIT_S);
    scn_t scn;
    char err[256];
    if (scn_parse_text(text, "commission", &scn, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        return 2;
    }
    static sim_t sim;
    sim_options_t o;
    sim_default_options(&o);
    o.seed = (uint32_t)k.seed;
    if (sim_init(&sim, &o, &scn, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        return 2;
    }
    /* until the commissioning has ended (IDLE or FAULT after it began) */
    int began = 0;
    while (sim_step(&sim, NULL)) {
        const foc_state_t st = sim.ctrl.state;
        began |= st == FOC_STATE_COMMISSION;
        if (began && (st == FOC_STATE_IDLE || st == FOC_STATE_FAULT)) {
            break;
        }
    }
    const pmsm_params_t *p = &sim.model.p; /* the plant's truth */
    sim_commission_t r;
    sim_commission_results(&sim, &r);
    if (table) {
        printf("| %s | rs %.2f ld %.2f lq %.2f flux %.2f j %.2f b %.2f tc %.2f |", COMMISSION_MOTOR, k.rs,
               k.ld, k.lq, k.flux, k.j, k.b, k.tc);
    } else {
        printf("motor=%s end_state=%s fault=%s step=%s time_s=%.3f peak_a=%.3f limit_a=%.3f\n",
               COMMISSION_MOTOR, foc_state_name(sim.ctrl.state), foc_fault_name(sim.ctrl.faults.first),
               r.failed_step, sim.t_s, sim.peak_current_a, (double)CURRENT_LIMIT_A);
    }
    if (k.expect_fail != NULL) {
        const int failed = sim.ctrl.state == FOC_STATE_FAULT && !r.valid &&
                           sim.ctrl.faults.first == (uint16_t)FOC_FAULT_COMMISSION_FAILED &&
                           strcmp(r.failed_step, k.expect_fail) == 0;
        printf("expected COMMISSION_FAILED at %s: %s\n", k.expect_fail, failed ? "PASS" : "FAIL");
        scn_free(&scn);
        return failed ? 0 : 1;
    }
    int ok = r.valid && sim.ctrl.state == FOC_STATE_IDLE;
    ok &= check("rs_ohm", r.rs_ohm, p->rs_ohm, TOL_RS, table);
    ok &= check("ld_h", r.ld_h, p->ld_h, TOL_L, table);
    ok &= check("lq_h", r.lq_h, p->lq_h, TOL_L, table);
    ok &= check("flux_wb", r.flux_wb, p->flux_wb, TOL_FLUX, table);
    if (p->deadtime_s > 0.0) {
        ok &= table ? fabs(r.deadtime_s / p->deadtime_s - 1.0) <= TOL_DT
                    : check("deadtime_s", r.deadtime_s, p->deadtime_s, TOL_DT, 0);
    }
    const double off = fmax(fabs(k.flux - 1.0), fmax(fabs(k.ld - 1.0), fabs(k.lq - 1.0)));
    if (off <= 0.10) {
        ok &= r.mech;
        ok &= check("j_kgm2", r.j_kgm2, p->j_kgm2, TOL_MECH, table);
        ok &= check("b_nms", r.b_nms, p->b_nm_per_rad_s, TOL_MECH, table);
        check("coulomb_nm", r.coulomb_nm, p->coulomb_nm, TOL_MECH, table);
    } else if (off >= 0.20) {
        ok &= !r.mech;
        if (table) {
            printf(" not run | | |");
        } else {
            printf("mech not run (the flux or an inductance %.0f %% off the build's): %s\n", 100.0 * off,
                   r.mech ? "FAIL" : "ok");
        }
    }
    /* within the current limit plus the oracle's 5 % (docs/safety.md) */
    ok &= sim.peak_current_a <= 1.05 * CURRENT_LIMIT_A;
    if (table) {
        printf(" %s |\n", ok ? "pass" : "FAIL");
    } else {
        printf("%s\n", ok ? "PASS" : "FAIL");
    }
    scn_free(&scn);
    return ok ? 0 : 1;
}
