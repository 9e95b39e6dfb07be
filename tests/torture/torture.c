/*
 * The torture campaign of issue 10: random scenarios on one motor parameter
 * set (this file is compiled once per set, like the core), judged every PWM
 * period by an oracle that reads the plant's TRUE state (phase currents,
 * rotor speed, bus voltage, what the scenario did to the rotor) and knows
 * nothing of the estimator's internals.  docs/safety.md states every rule
 * with its figures; the oracle below is the reference.
 *
 *   torture_<motor> --seed N [--plant averaged|realistic] [--dump FILE.scn] [--trace]
 *        one random run (the seed decides everything but the motor); prints
 *        one result line "key=value ..." (tools/torture.py collects them);
 *        the plant is the realistic one of issue 13 (switched bridge, the
 *        board's sampling instant, sensor gains and drift, EMF harmonics,
 *        q saturation: docs/safety.md) unless --plant averaged (the
 *        averaged bridge, the same run otherwise)
 *   torture_<motor> --scenario FILE.scn [--estimator E] [--trace]
 *        (--trace: a CSV row every millisecond; --trace-every N: every N
 *        PWM periods)
 *        a written scenario (tests/torture/regress; with `commission`, the
 *        identified values as focsim's id_* keys); `#!` lines in it set the
 *        run's options and expectations:
 *          #! estimator pll|luenberger|flux   (several: one run each)
 *          #! stop_mode ramp|coast|short      #! coulomb <Nm>
 *          #! min_speed_rpm <rpm>             the controller's lowest
 *                                             sensorless command (default
 *                                             SENSORLESS_MIN_SPEED_RPM)
 *          #! mtpa off                        id = 0 below base speed on a
 *                                             salient rotor (MTPA's baseline)
 *          #! expect fault                    a named fault must be latched
 *          #! expect state RUN                the final state
 *          #! expect speed <rpm> <tol %>      mean true speed over the last
 *                                             0.3 s within tol of rpm
 *          #! expect bus_below_ov             true bus never above OVERVOLTAGE_V
 *          #! expect running_or_fault         ends in RUN or with a named fault
 *          #! measure_from <s>                the angle error's RMS counts the
 *                                             periods in RUN from then on
 *                                             (default 0: all of RUN)
 *          #! expect angle_rms <deg>          that RMS (estimated - the
 *                                             plant's true electrical angle)
 *                                             at most <deg>
 *        the result line's angle_err_rms_deg is that RMS (nan: no period
 *        in RUN after measure_from);
 *        exit status 0 when no invariant is violated, no trip is false and
 *        every expectation holds, 1 otherwise
 *   torture_<motor> --params
 *        the motor's figures that scripts need (key=value: max speed, rated
 *        torque, ramp rate, ...), from the userparms.h it is built with
 *        (ld_h, lq_h, flux_wb: the plant's own, which is built from it)
 *   torture_<motor> --selftest
 *        the oracle's own test (ctest): a benign run is clean, each injected
 *        violation is caught by its kind, a seed reproduces its run
 *
 * The simulation loop is tools/focsim/sim.c's (sim_init / sim_step), the
 * scenario language focsim's: a dumped run replays in focsim.
 */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "foc/config.h"
#include "host_port.h"
#include "scenario.h"
#include "sim.h"

#ifndef TORTURE_MOTOR
#define TORTURE_MOTOR "unknown"
#endif

/* ------------------------------------------------------------ figures -- */

#define PI_D 3.14159265358979323846
#define RAD_S_PER_RPM (2.0 * PI_D / 60.0)
#define SLOW_TS_S ((double)CONTROL_SLOW_DIVIDER / PWM_FREQUENCY_HZ)

/* Margins of the invariants (docs/safety.md). */
#define I_MARGIN 1.05              /* peak phase current / CURRENT_LIMIT_A */
#define ORACLE_OVERSPEED 1.10      /* |speed| / MOTOR_MAX_SPEED_RPM */
#define STILL_FRACTION 0.02        /* standstill: |speed| < 2 % of max */
#define SLIP_DEG 90.0              /* "not following": the estimated angle */
#define SLIP_WINDOW_S 0.05         /* slipped this far in this time */
#define EST_WRONG_REL 0.30         /* a trip's cause: |true-est| > 30 % */
#define EST_ANGLE_WRONG_DEG 30.0   /* or the estimated angle this far off */
#define EST_ANGLE_WRONG_S 0.1      /* (electrical) for this long in RUN */
#define NF_GAP_S 0.05              /* gaps shorter than this join stretches */
#define DET_FAST_S 0.200           /* detection bound above 10 % of max */
#define DET_SLOW_S 0.500           /* and below */
#define OV_MARGIN 1.02             /* bus above OVERVOLTAGE_V x this ... */
#define OV_DETECT_S 0.005          /* ... for this long without the fault */
#define CAUSE_WINDOW_S 1.0         /* how far back a fault's cause may lie */
#define GAIN_RING_N 512            /* ms of true speed kept (>= 2 x 200 ms) */
#define HEAVY_FRACTION 0.9          /* a load beyond: of Kt x the q limit */
#define NO_GAIN_IQ_FRACTION 0.75    /* "at the current limit": mean true iq */
#define BEHIND_FRACTION 0.875       /* behind: below this of the command */
#define IQ_REF_MAX_A (CURRENT_LIMIT_A * (1.0 - CURRENT_REF_MARGIN))
#define HUNT_FRACTION 0.5          /* hunting: the true iq swings beyond */
#define HUNT_SWINGS 8              /* +-this x CURRENT_LIMIT_A this often */
#define HUNT_WINDOW_S 0.1          /* within this time, in RUN */

static double kt_nm_per_a(double flux_wb)
{
    return 1.5 * MOTOR_POLE_PAIRS * flux_wb;
}

/* Envelope of the campaign: J up to 20 x the data sheet's. */
#define J_ENVELOPE 20.0

/* Time to brake the rotor from `rpm` to rest at the current limit with the
 * envelope's largest inertia (plant flux at its lowest, x0.8). */
static double t_mech_s(double rpm)
{
    const double tmax = kt_nm_per_a(FOC_FLUX_WB * 0.8) * CURRENT_LIMIT_A;
    return J_ENVELOPE * MOTOR_INERTIA_KGM2 * fabs(rpm) * RAD_S_PER_RPM / tmax;
}

static double bound_calib_s(void) { return CALIB_TIME_S + 10.0 * SLOW_TS_S; }
static double bound_start_s(void) { return STARTUP_TIMEOUT_S + 10.0 * SLOW_TS_S; }
/* CATCH: its window (CATCH_TIME_S, at least 64 slow ticks), twice for an
 * estimate not yet steady, and the inductance probe's settling */
static double bound_catch_s(void)
{
    return 3.0 * fmax(CATCH_TIME_S, 64.0 * SLOW_TS_S) + 10.0 * SLOW_TS_S;
}
static double bound_stop_s(double rpm)
{
    return fabs(rpm) / SPEED_RAMP_RPM_PER_S + t_mech_s(rpm) + 0.5;
}
static double bound_reversal_s(double rpm_from, double rpm_to)
{
    return bound_stop_s(rpm_from) + bound_start_s() + fabs(rpm_to) / SPEED_RAMP_RPM_PER_S +
           t_mech_s(rpm_to) + 0.5;
}
/* Energised standstill (thermal budget): the longest legitimate one is a
 * start-up into a rotor that cannot turn, which must end by the start-up
 * time-out. */
static double bound_still_s(void) { return STARTUP_TIMEOUT_S + 0.5; }

/* --------------------------------------------------------------- rng -- */

static uint64_t rng_state;

static uint64_t rng_next(void)
{
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static double urand(double lo, double hi)
{
    return lo + (hi - lo) * ((double)(rng_next() >> 11) / 9007199254740992.0);
}

static double logrand(double lo, double hi)
{
    return exp(urand(log(lo), log(hi)));
}

static int irand(int n) /* 0 .. n-1 */
{
    return (int)(rng_next() % (uint64_t)n);
}

/* ----------------------------------------------------------- run spec -- */

typedef struct {
    char text[16384]; /* the scenario, focsim's language */
    size_t len;
    foc_est_kind_t est;
    int stop_mode;
    double coulomb_nm;
    int min_speed_rpm; /* -1: SENSORLESS_MIN_SPEED_RPM */
    int mtpa;          /* -1: on for a salient rotor; 0: id = 0 (#! mtpa off) */
    int expect_fault;
    char expect_state[16];
    double expect_speed_rpm, expect_speed_tol;
    int has_expect_speed;
    int expect_bus_below_ov;   /* the true bus never above OVERVOLTAGE_V */
    int expect_running_or_fault;
    double measure_from_s;     /* the angle error's RMS from this time, s */
    double expect_angle_rms_deg;
    int has_expect_angle_rms;
} spec_t;

static void spec_add(spec_t *sp, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(sp->text + sp->len, sizeof sp->text - sp->len, fmt, ap);
    va_end(ap);
    if (n > 0 && sp->len + (size_t)n < sizeof sp->text) {
        sp->len += (size_t)n;
    }
}

static const char *const est_names[] = { "pll", "luenberger", "flux" };
static const foc_est_kind_t est_kinds[] = { FOC_EST_PLL, FOC_EST_LUENBERGER, FOC_EST_FLUX };
static const char *const stop_names[] = { "ramp", "coast", "short" };

/* 1: the realistic plant of issue 13 (the default); 0: the averaged bridge
 * model (--plant averaged), for comparison */
static int plant_realistic = 1;

/* A random scenario.  Everything is drawn from the seed, in a fixed order,
 * so one seed is one run. */
static void generate(uint32_t seed, spec_t *sp)
{
    memset(sp, 0, sizeof *sp);
    sp->min_speed_rpm = -1;
    sp->mtpa = -1;
    rng_state = 0x5EED0000ull ^ ((uint64_t)seed * 0x100000001B3ull);
    const double wmax = MOTOR_MAX_SPEED_RPM;
    const double t_rated = kt_nm_per_a(FOC_FLUX_WB) * MOTOR_RATED_CURRENT_A;
    const double vnom = BOARD_VDC_NOMINAL_V;
    const int e = irand(3);
    sp->est = est_kinds[e];
    sp->stop_mode = irand(3);
    spec_add(sp, "# torture seed %u, motor %s, estimator %s, stop mode %s\n", seed,
             TORTURE_MOTOR, est_names[e], stop_names[sp->stop_mode]);
    spec_add(sp, "#! motor %s\n#! estimator %s\n#! stop_mode %s\n", TORTURE_MOTOR, est_names[e],
             stop_names[sp->stop_mode]);
    /* plant mismatch */
    const double kl = urand(0.5, 1.5);
    spec_add(sp, "0 plant rs %.6g\n", MOTOR_RS_OHM * urand(0.6, 2.0));
    spec_add(sp, "0 plant ld %.6g\n", MOTOR_LD_H * kl);
    spec_add(sp, "0 plant lq %.6g\n", MOTOR_LQ_H * kl);
    spec_add(sp, "0 plant flux %.6g\n", FOC_FLUX_WB * urand(0.8, 1.2));
    spec_add(sp, "0 plant j %.6g\n", MOTOR_INERTIA_KGM2 * logrand(0.2, 20.0));
    spec_add(sp, "0 plant b %.6g\n",
             MOTOR_VISCOUS_NM_PER_KRPM / (1000.0 * RAD_S_PER_RPM) * urand(0.0, 3.0));
    {
        /* the value as printed, so that the dumped scenario replays exactly */
        char num[32];
        snprintf(num, sizeof num, "%.6g", MOTOR_COULOMB_NM * urand(0.0, 3.0));
        sp->coulomb_nm = atof(num);
        spec_add(sp, "#! coulomb %s\n", num);
    }
    spec_add(sp, "0 plant noise %.3g\n", urand(0.0, 3.0));
    spec_add(sp, "0 plant deadtime %.6g\n", PWM_DEADTIME_S * urand(0.5, 1.5));
    if (irand(2) == 0) {
        spec_add(sp, "0 plant buscap %.6g\n", logrand(100e-6, 2000e-6) * (24.0 / vnom));
    }
    if (plant_realistic) {
        /* issue 13: the switched bridge, the board's sampling instant, and
         * the sensor's and the magnet's imperfections, drawn from a stream
         * of their own: the rest of the run is the averaged plant's for the
         * same seed (--plant averaged) */
        const uint64_t main_stream = rng_state;
        rng_state = 0x9EA100ull ^ ((uint64_t)seed * 0x100000001B3ull);
        spec_add(sp, "0 plant switched 1\n0 plant midsample %d\n",
                 SAMPLE_DELAY_PERIODS < 1.25 ? 1 : 0);
        spec_add(sp, "0 plant gaina %.4f\n", urand(-0.03, 0.03));
        spec_add(sp, "0 plant gainb %.4f\n", urand(-0.03, 0.03));
        spec_add(sp, "0 plant gainc %.4f\n", urand(-0.03, 0.03));
        spec_add(sp, "0 plant emf5 %.4f\n", urand(0.0, 0.04));
        spec_add(sp, "0 plant emf7 %.4f\n", urand(0.0, 0.015));
        spec_add(sp, "0 plant drifta %.3f\n", urand(-0.2, 0.2));
        spec_add(sp, "0 plant driftb %.3f\n", urand(-0.2, 0.2));
        spec_add(sp, "0 plant driftc %.3f\n", urand(-0.2, 0.2));
        spec_add(sp, "0 plant lqsat %.4g\n", CURRENT_LIMIT_A * urand(2.0, 5.0));
        rng_state = main_stream;
    }
    spec_add(sp, "0 angle %.1f\n", urand(0.0, 360.0));

    /* commands */
    const double t_start = CALIB_TIME_S + STARTUP_ALIGN_TIME_S + STARTUP_RAMP_TIME_S;
    double t = urand(0.0, 0.05);
    int running = 0, locked = 0, spun = 0;
    double load = 0.0;
    const double t_peak = kt_nm_per_a(FOC_FLUX_WB) * CURRENT_LIMIT_A;
    const int n = 4 + irand(8);
    for (int k = 0; k < n; k++) {
        const int a = irand(100);
        if (!running || a < 12) {
            /* start, sometimes into a turning rotor: one the bridge does
             * not drive, so a stop first and its bound (a spin of a
             * driven rotor would change its back-EMF in no time, which no
             * shaft does) */
            if (irand(5) == 0 && !locked) {
                spec_add(sp, "%.4f stop\n", t);
                t += bound_stop_s(wmax);
                spec_add(sp, "%.4f spin %.0f\n", t, (irand(2) ? 1 : -1) * urand(0.05, 1.0) * wmax);
                spun = 1;
                t += urand(0.05, 0.3);
            }
            double ref = (irand(2) ? 1 : -1) * urand(0.1, 1.0) * wmax;
            spec_add(sp, "%.4f speed %.0f\n", t, ref);
            spec_add(sp, "%.4f start\n", t);
            if (spun) {
                const double tu = t + urand(0.0, 0.3);
                spec_add(sp, "%.4f unlock\n", tu);
                spun = 0;
            }
            running = 1;
            t += t_start * urand(0.8, 1.5) + urand(0.1, 0.6);
            continue;
        }
        if (a < 40) { /* speed step, reversal, small or above max */
            const int kind = irand(10);
            double ref;
            if (kind == 0) {
                ref = (irand(2) ? 1 : -1) * urand(1.0, 1.4) * wmax;
            } else if (kind == 1) {
                ref = (irand(2) ? 1 : -1) * urand(0.01, 0.1) * wmax;
            } else {
                ref = (irand(2) ? 1 : -1) * urand(0.1, 1.0) * wmax;
            }
            spec_add(sp, "%.4f speed %.0f\n", t, ref);
            t += urand(0.2, 1.0) + t_mech_s(wmax) / J_ENVELOPE * urand(0.5, 5.0);
        } else if (a < 52) { /* load up to 1.5 x rated torque */
            load = (load > 0.0) ? 0.0 : t_rated * urand(0.1, 1.5);
            spec_add(sp, "%.4f load %.6g\n", t, load);
            t += urand(0.2, 0.8);
        } else if (a < 60) { /* jam, then let go: a dry-friction brake of 2 to
                              * 4 x the motor's peak torque stops the rotor
                              * within milliseconds and holds it (no shaft
                              * stops in no time: an instant lock at speed
                              * moves the back-EMF faster than any current
                              * loop; the regression files keep `lock`) */
            spec_add(sp, "%.4f load %.6g\n", t, t_peak * urand(2.0, 4.0));
            locked = 1;
            t += urand(0.1, 1.2);
            spec_add(sp, "%.4f load %.6g\n", t, load);
            locked = 0;
            t += urand(0.1, 0.4);
        } else if (a < 68) { /* bus sag or surge, then back */
            const double v = irand(2) ? vnom * urand(0.5, 0.95) : vnom * urand(1.02, 1.3);
            spec_add(sp, "%.4f vdc %.4g\n", t, v);
            t += urand(0.05, 0.6);
            spec_add(sp, "%.4f vdc %.4g\n", t, vnom);
            t += urand(0.1, 0.3);
        } else if (a < 73) { /* temperature */
            spec_add(sp, "%.4f temp %.1f\n", t, urand(20.0, 130.0));
            t += urand(0.1, 0.5);
            spec_add(sp, "%.4f temp 25\n", t);
            t += urand(0.05, 0.2);
        } else if (a < 85) { /* stop (the run's stop mode) */
            spec_add(sp, "%.4f stop\n", t);
            running = 0;
            t += bound_stop_s(wmax) * urand(0.3, 1.2);
        } else if (a < 92) { /* acknowledge */
            spec_add(sp, "%.4f ack\n", t);
            running = 0; /* a fault may have ended the run */
            t += urand(0.05, 0.3);
        } else { /* spammed commands within 10 ms */
            const int m = 5 + irand(16);
            for (int i = 0; i < m; i++) {
                const double ti = t + urand(0.0, 0.01);
                switch (irand(4)) {
                case 0: spec_add(sp, "%.4f start\n", ti); break;
                case 1: spec_add(sp, "%.4f stop\n", ti); break;
                case 2: spec_add(sp, "%.4f ack\n", ti); break;
                default:
                    spec_add(sp, "%.4f speed %.0f\n", ti,
                             (irand(2) ? 1 : -1) * urand(0.0, 1.2) * wmax);
                    break;
                }
            }
            running = irand(2);
            t += urand(0.2, 0.8);
        }
    }
    spec_add(sp, "%.4f end\n", t + urand(0.5, 1.5));
}

/* ------------------------------------------------------------- oracle -- */

enum {
    V_CURRENT, V_TRANSIT, V_NOFOLLOW, V_THERMAL, V_OVERSPEED, V_BUS_OV, V_FALSE_TRIP,
    V_EXPECT, V_KINDS
};
static const char *const v_names[V_KINDS] = {
    "current", "transit", "nofollow", "thermal", "overspeed", "bus_ov", "false_trip",
    "expect",
};

/* What the self-test perturbs in the oracle's view of the plant. */
typedef enum {
    INJ_NONE, INJ_CURRENT, INJ_STALL, INJ_SLIP, INJ_BUS, INJ_SPEED, INJ_FAULT, INJ_TRANSIT,
    INJ_THERMAL
} inject_t;

typedef struct {
    /* results */
    int count[V_KINDS];
    double first_t[V_KINDS];
    char what[V_KINDS][160];
    double peak_ratio;        /* worst peak phase current / CURRENT_LIMIT_A */
    double peak_t;
    double det_worst_s;       /* worst detection time of a not-following rotor */
    int detections;
    /* state */
    foc_state_t prev_state;
    double state_since;
    double stop_from_rpm;
    int reversal_on;
    double reversal_t, reversal_from, reversal_to;
    int nf_on;
    double nf_start, nf_last, nf_cmd;
    int still_on;
    double still_start, still_last;
    double ov_since;
    uint16_t prev_first;
    pmsm_bridge_t bridge_k, bridge_km1; /* of this row's period and the one before */
    /* recent history for fault causes */
    double last_lock_t, last_spin_t, last_heavy_t, last_nf_t, last_ov_t, last_uv_t;
    double last_est_wrong_t, last_ol_slip_t, last_start_turning_t, last_oc_t, last_hunt_t;
    double angle_wrong_since; /* in RUN, the angle EST_ANGLE_WRONG_DEG off */
    /* the speed loop hunting: times of the last HUNT_SWINGS swings of the
     * true iq from one side of +-HUNT_FRACTION x the limit to the other */
    double hunt_t[HUNT_SWINGS];
    int hunt_i, hunt_side;
    const char *last_cause; /* of the last fault latched */
    double vdc_max;
    /* unwrapped electrical angle error (estimate - true), deg, sampled
     * every millisecond over SLIP_WINDOW_S */
    double slip_u, slip_prev_d;
    double slip_ring[64];
    int slip_n, slip_i;
    long slip_k;
    int slip_flag;
    long uncontrollable_periods; /* current not judged: back-EMF beyond reach */
    /* true speed, rpm, every millisecond (two of the follow check's slow
     * windows) */
    double gain_ring[GAIN_RING_N];
    double gain_iq_ring[GAIN_RING_N]; /* true iq toward the command, A */
    int gain_n, gain_i;
    long gain_k;
    double run_since;
    double last_no_gain_t;
    /* speed window for `expect speed` */
    double tail_sum;
    long tail_n;
} oracle_t;

static void violate(oracle_t *o, int kind, double t, const char *fmt, ...)
{
    if (o->count[kind]++ == 0) {
        o->first_t[kind] = t;
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(o->what[kind], sizeof o->what[kind], fmt, ap);
        va_end(ap);
    }
}

static void oracle_init(oracle_t *o)
{
    memset(o, 0, sizeof *o);
    o->prev_state = FOC_STATE_IDLE;
    o->ov_since = -1.0;
    o->last_lock_t = o->last_spin_t = o->last_heavy_t = o->last_nf_t = -1e9;
    o->last_ov_t = o->last_uv_t = o->last_ol_slip_t = o->last_start_turning_t = -1e9;
    o->last_oc_t = o->last_est_wrong_t = o->last_no_gain_t = o->last_hunt_t = -1e9;
    o->angle_wrong_since = -1.0;
    for (int k = 0; k < HUNT_SWINGS; k++) o->hunt_t[k] = -1e9;
}

static int energised(int bridge) { return bridge == PMSM_BRIDGE_PWM; }

/* The physical cause of a newly latched fault found in the plant's recent
 * history, or NULL (a false trip). */
static const char *fault_cause(const oracle_t *o, uint16_t fault, double t)
{
    const double w = CAUSE_WINDOW_S;
    switch (fault) {
    case FOC_FAULT_OVERVOLTAGE: return t - o->last_ov_t <= 0.05 ? "bus high" : NULL;
    case FOC_FAULT_UNDERVOLTAGE: return t - o->last_uv_t <= 0.05 ? "bus low" : NULL;
    case FOC_FAULT_OVERTEMP:
        return host_port()->temp_degc >= OVERTEMP_DEGC - 2.0 ? "hot" : NULL;
    case FOC_FAULT_OVERCURRENT: return t - o->last_oc_t <= 0.002 ? "current" : NULL;
    case FOC_FAULT_STARTUP_FAILED:
    case FOC_FAULT_SPEED_FEEDBACK:
        if (t - o->last_lock_t <= w) return "rotor locked";
        if (t - o->last_spin_t <= w) return "rotor driven";
        if (t - o->last_heavy_t <= w) return "load beyond the current";
        if (t - o->last_no_gain_t <= w) return "rotor not gaining on the command";
        if (t - o->last_nf_t <= w) return "rotor not following";
        if (t - o->last_est_wrong_t <= w) return "estimate wrong";
        if (t - o->last_hunt_t <= w) return "speed loop hunting";
        if (t - o->last_ol_slip_t <= 0.5) return "rotor not following the start-up";
        if (t - o->last_start_turning_t <= w + STARTUP_TIMEOUT_S) return "start into a turning rotor";
        if (t - o->last_uv_t <= w) return "bus low";
        return NULL;
    default: return "other";
    }
}

/* One PWM period.  `r` is sim.c's row (true currents, speed, bus), `s` the
 * simulation (the model's rotor mode and load: what the scenario did). */
static void oracle_step(oracle_t *o, const sim_t *s, const sim_row_t *r0, inject_t inj,
                        double t_end)
{
    sim_row_t row = *r0;
    sim_row_t *r = &row;
    const double t = r->t_s;
    const foc_ctrl_t *c = &s->ctrl;
    foc_state_t st = c->state;
    uint16_t first = c->faults.first;
    /* injected violations (self-test): the oracle's view is perturbed */
    if (inj == INJ_CURRENT && t >= 1.0 && t < 1.0005) {
        r->ia_a = 1.5 * CURRENT_LIMIT_A;
    }
    if (inj == INJ_STALL && t >= 1.0) {
        r->speed_rpm = 0.0;
    }
    if (inj == INJ_SLIP && t >= 1.0) {
        /* the rotor lags the commutation by 10 electrical turns a second */
        r->theta_e_deg = fmod(r->theta_e_deg - 3600.0 * (t - 1.0) + 3600000.0, 360.0);
    }
    if (inj == INJ_BUS && t >= 1.0 && t < 1.02) {
        r->vdc_v = 1.1 * OVERVOLTAGE_V;
    }
    if (inj == INJ_SPEED && t >= 1.0 && t < 1.01) {
        r->speed_rpm = 1.5 * MOTOR_MAX_SPEED_RPM;
    }
    if (inj == INJ_FAULT &&
        t >= CALIB_TIME_S + STARTUP_ALIGN_TIME_S + STARTUP_RAMP_TIME_S + 0.95) {
        st = FOC_STATE_FAULT;
        first = FOC_FAULT_SPEED_FEEDBACK;
    }
    if (inj == INJ_TRANSIT && t >= 1.0) {
        st = FOC_STATE_STOP; /* a STOP that never ends */
    }
    if (inj == INJ_THERMAL && t >= 0.5) {
        /* held at standstill with the rated current, the bridge on */
        r->speed_rpm = 0.0;
        r->id_a = 0.0;
        r->iq_a = MOTOR_RATED_CURRENT_A;
        r->bridge = PMSM_BRIDGE_PWM;
    }
    const double wmax = MOTOR_MAX_SPEED_RPM;
    const double w = r->speed_rpm;
    const double west = r->speed_est_rpm;
    const double wref = sim_rpm_from_q15(c->speed_ctrl.ramped);
    const double wcmd = sim_rpm_from_q15(c->req.speed);
    const double ipk = fmax(fabs(r->ia_a), fmax(fabs(r->ib_a), fabs(r->ic_a)));
    const double imag = sqrt(r->id_a * r->id_a + r->iq_a * r->iq_a);
    const int en = energised(r->bridge) || energised(s->model.bridge);
    const pmsm_model_t *m = &s->model;
    /* Rule 1's bridge, period by period: this row's sample was taken at
     * the start of period k, and the oracle runs after the model has
     * stepped through it, so m->bridge is period k+1's; the rows before
     * kept k's and k-1's.  The sample is judged when the bridge switched
     * next to it (period k-1 or k; k+1 too, as before), the true extremes
     * since the previous sample (the switched bridge's ripple; the sample
     * sees its middle) when it switched in the period they span, k-1 (and
     * k's first half when sampled mid-period).  (The sample was judged by
     * period k+1's bridge only: the end of a PWM period before the bridge
     * turns off, such as CATCH's probe, a period of zero vector, was never
     * judged: seed 109.) */
    const pmsm_sample_t *smp = &host_port()->last_sample;
    double ipk_span = 0.0;
    for (int ph = 0; ph < 3; ph++) {
        ipk_span = fmax(ipk_span, fmax(fabs(smp->i_min_a[ph]), fabs(smp->i_max_a[ph])));
    }
    const int en_sample = en || energised(o->bridge_k) || energised(o->bridge_km1);
    const int en_span = energised(o->bridge_km1) || (m->p.sample_mid_period && energised(o->bridge_k));
    o->bridge_km1 = o->bridge_k;
    o->bridge_k = m->bridge;
    /* the largest gain error of the plant's current sensors: the firmware
     * sees the current that much larger or smaller (seed 67) */
    const double gain_max =
        fmax(fabs(m->p.gain_error[0]), fmax(fabs(m->p.gain_error[1]), fabs(m->p.gain_error[2])));

    /* history for the causes of faults */
    if (m->rotor == PMSM_ROTOR_LOCKED) o->last_lock_t = t;
    if (m->rotor == PMSM_ROTOR_SPIN) o->last_spin_t = t;
    /* the torque against the rotor: the load and the friction, dry and
     * viscous (a load just below the limit's torque with friction on top
     * is beyond it), against HEAVY_FRACTION of the torque the current
     * references' limit gives (the follow check's policy: a rotor gaining
     * less than a tenth of what the heaviest one would at the limit
     * carries that much; seed 783, the servo knocked from 340 to 130 rpm
     * by a load of 99.6 % of that torque, tripped by the statistic) */
    const double against_nm =
        m->load_nm + m->p.coulomb_nm + m->p.b_nm_per_rad_s * fabs(w) * RAD_S_PER_RPM;
    if (against_nm > HEAVY_FRACTION * kt_nm_per_a(m->p.flux_wb) * IQ_REF_MAX_A ||
        ((st == FOC_STATE_ALIGN || st == FOC_STATE_OPENLOOP) &&
         m->load_nm + m->p.coulomb_nm > HEAVY_FRACTION * kt_nm_per_a(m->p.flux_wb) * STARTUP_CURRENT_FINAL_A)) {
        o->last_heavy_t = t;
    }
    /* in RUN, at the current limit toward the command, behind it and not
     * gaining on it by the follow check's own progress per window
     * (docs/safety.md: its false-trip margin), judged on the true speed
     * and current: a load that takes most of the limit's torque */
    if (st == FOC_STATE_RUN && o->prev_state != FOC_STATE_RUN) o->run_since = t;
    const long per_ms = (long)(PWM_FREQUENCY_HZ / 1000.0);
    if (o->gain_k++ % per_ms == 0) {
        o->gain_ring[o->gain_i] = w;
        o->gain_iq_ring[o->gain_i] = (wcmd < 0.0) ? -r->iq_a : r->iq_a;
        o->gain_i = (o->gain_i + 1) % GAIN_RING_N;
        if (o->gain_n < GAIN_RING_N) o->gain_n++;
        const double win_s = fabs(wcmd) >= 0.1 * wmax ? FOC_FOLLOW_FAST_S : FOC_FOLLOW_SLOW_S;
        const int n = (int)(win_s * 1000.0 + 0.5);
        /* both windows in RUN, where the check runs */
        const int judged = st == FOC_STATE_RUN && t - o->run_since >= 2.0 * win_s;
        const int behind = wcmd != 0.0 && (fabs(w) < BEHIND_FRACTION * fabs(wcmd) || (w < 0.0) != (wcmd < 0.0));
        if (judged && behind && o->gain_n >= 2 * n) {
            double last = 0.0, prev = 0.0, iq = 0.0;
            for (int k = 1; k <= n; k++) {
                const int i1 = (o->gain_i - k + GAIN_RING_N) % GAIN_RING_N;
                const int i2 = (o->gain_i - n - k + GAIN_RING_N) % GAIN_RING_N;
                last += o->gain_ring[i1];
                prev += o->gain_ring[i2];
                iq += o->gain_iq_ring[i1] + o->gain_iq_ring[i2];
            }
            const double gain = (wcmd < 0.0 ? prev - last : last - prev) / n;
            const int limited = iq / (2 * n) >= NO_GAIN_IQ_FRACTION * IQ_REF_MAX_A;
            if (limited && gain < FOC_FOLLOW_PROGRESS_RPM(win_s)) o->last_no_gain_t = t;
        }
    }
    /* the speed loop hunting: full torque one way, then the other, again
     * and again (a rotor much lighter than MOTOR_INERTIA_KGM2 makes the
     * loop's gain too high for its delays: Shinano at J x 0.25, seed 295)
     * -- a reason to stop, the drive train takes torque reversals at the
     * current limit */
    if (st == FOC_STATE_RUN) {
        const int side = r->iq_a >= HUNT_FRACTION * CURRENT_LIMIT_A    ? 1
                         : r->iq_a <= -HUNT_FRACTION * CURRENT_LIMIT_A ? -1
                                                                       : 0;
        if (side != 0 && side == -o->hunt_side) {
            o->hunt_t[o->hunt_i] = t;
            o->hunt_i = (o->hunt_i + 1) % HUNT_SWINGS;
            /* the oldest of the last HUNT_SWINGS swings */
            if (t - o->hunt_t[o->hunt_i] <= HUNT_WINDOW_S) o->last_hunt_t = t;
        }
        if (side != 0) o->hunt_side = side;
    } else {
        o->hunt_side = 0;
    }
    if (r->vdc_v >= 0.97 * OVERVOLTAGE_V) o->last_ov_t = t;
    if (r->vdc_v <= 1.03 * UNDERVOLTAGE_V) o->last_uv_t = t;
    /* an over-current's cause: the hardware trip's level, or the current
     * vector beyond CURRENT_LIMIT_A as sensors with the plant's gain errors
     * and 3 sigma of its noise can read it (the firmware's own trip, at the
     * limit: a current the loop no longer holds) */
    const double noise_a =
        m->p.noise_codes * BOARD_CURRENT_FULL_SCALE_A / (double)(1L << (m->p.adc_bits - 1));
    if (fmax(ipk, ipk_span) >= 0.97 * BOARD_CURRENT_FULL_SCALE_A ||
        imag * (1.0 + gain_max) + 3.0 * noise_a >= CURRENT_LIMIT_A) {
        o->last_oc_t = t;
    }
    /* the estimate far from the truth: a reason to trip, not yet a
     * violation when the controller does not (rule 3 judges the angle) */
    if ((st == FOC_STATE_RUN || st == FOC_STATE_OPENLOOP) &&
        fabs(w - west) > fmax(EST_WRONG_REL * fabs(west), STILL_FRACTION * wmax)) {
        o->last_est_wrong_t = t;
    }
    /* or its angle, held off: the current goes to the wrong axis and the
     * rotor does not get the torque asked for (seed 6864: the PLL 38 deg
     * behind a rotor with 1.97 x its resistance, the current on d) */
    const double angle_err = fmod(r->theta_est_deg - r->theta_e_deg + 540.0, 360.0) - 180.0;
    if (st == FOC_STATE_RUN && en && fabs(angle_err) > EST_ANGLE_WRONG_DEG) {
        if (o->angle_wrong_since < 0.0) o->angle_wrong_since = t;
        if (t - o->angle_wrong_since >= EST_ANGLE_WRONG_S) o->last_est_wrong_t = t;
    } else {
        o->angle_wrong_since = -1.0;
    }
    if (st == FOC_STATE_OPENLOOP && fabs(r->speed_ref_rpm) >= 0.5 * STARTUP_FINAL_SPEED_RPM &&
        fabs(w - r->speed_ref_rpm) > 0.5 * fabs(r->speed_ref_rpm)) {
        o->last_ol_slip_t = t;
    }
    if (st == FOC_STATE_CALIB && fabs(w) >= STILL_FRACTION * wmax) {
        o->last_start_turning_t = t;
    }

    /* 1. current: every state, while the bridge switches, except where no
     * controller can hold it: the d current needed to keep the back-EMF
     * inside the bus's reach ((psi - Vdc/sqrt3 / we) / Ld) above the limit */
    const double we = fabs(w) * RAD_S_PER_RPM * MOTOR_POLE_PAIRS;
    const int uncontrollable =
        we * m->p.flux_wb > r->vdc_v / sqrt(3.0) + m->p.ld_h * we * CURRENT_LIMIT_A;
    if (uncontrollable) o->uncontrollable_periods++;
    if ((en_sample || en_span) && !uncontrollable) {
        const double ratio = fmax(en_sample ? ipk : 0.0, en_span ? ipk_span : 0.0) / CURRENT_LIMIT_A;
        if (ratio > o->peak_ratio) {
            o->peak_ratio = ratio;
            o->peak_t = t;
        }
        if (ratio > I_MARGIN) {
            violate(o, V_CURRENT, t, "%.3f A = %.2f x CURRENT_LIMIT_A in %s", ratio * CURRENT_LIMIT_A, ratio,
                    foc_state_name(st));
        }
    }

    /* 2. transitional states end within their bound or in a fault */
    if (st != o->prev_state &&
        !(st == FOC_STATE_OPENLOOP && o->prev_state == FOC_STATE_ALIGN)) {
        /* ALIGN and OPENLOOP are one start-up: one bound */
        o->state_since = t;
        if (st == FOC_STATE_STOP || st == FOC_STATE_BRAKE) {
            o->stop_from_rpm = fmax(fabs(w), fabs(west));
        }
    }
    {
        const double in = t - o->state_since;
        double bound = -1.0;
        switch (st) {
        case FOC_STATE_CALIB: bound = bound_calib_s(); break;
        case FOC_STATE_ALIGN:
        case FOC_STATE_OPENLOOP: bound = bound_start_s(); break;
        case FOC_STATE_CATCH: bound = bound_catch_s(); break;
        case FOC_STATE_STOP:
        case FOC_STATE_BRAKE: bound = bound_stop_s(o->stop_from_rpm); break;
        default: break;
        }
        if (bound > 0.0 && in > bound) {
            violate(o, V_TRANSIT, t, "%s for %.2f s (bound %.2f s)", foc_state_name(st), in,
                    bound);
        }
    }
    /* the reversal: a command of the other sign than the rotation, in RUN */
    if (!o->reversal_on && st == FOC_STATE_RUN && fabs(w) > 0.1 * wmax && wcmd * w < 0.0) {
        o->reversal_on = 1;
        o->reversal_t = t;
        o->reversal_from = w;
        o->reversal_to = wcmd;
    }
    if (o->reversal_on) {
        if (st == FOC_STATE_FAULT || st == FOC_STATE_IDLE || st == FOC_STATE_STOP ||
            st == FOC_STATE_BRAKE || wcmd * o->reversal_to <= 0.0 ||
            (st == FOC_STATE_RUN && w * o->reversal_to > 0.0 &&
             fabs(w) > STILL_FRACTION * wmax)) {
            o->reversal_on = 0;
        } else if (t - o->reversal_t > bound_reversal_s(o->reversal_from, o->reversal_to)) {
            violate(o, V_TRANSIT, t, "reversal %.0f -> %.0f rpm not done after %.2f s",
                    o->reversal_from, o->reversal_to, t - o->reversal_t);
            o->reversal_on = 0;
        }
    }

    /* 3. a rotor that does not follow: judged in RUN with the bridge on */
    int slipping = 0;
    if (st == FOC_STATE_RUN && en) {
        const double d = angle_err;
        if (o->slip_n == 0 && o->slip_k == 0) {
            o->slip_prev_d = d;
            o->slip_u = d;
        }
        o->slip_u += fmod(d - o->slip_prev_d + 540.0, 360.0) - 180.0;
        o->slip_prev_d = d;
        const int len = (int)(SLIP_WINDOW_S * 1000.0);
        if (o->slip_k++ % per_ms == 0) {
            /* against the sample SLIP_WINDOW_S ago (the oldest one in the
             * first milliseconds of RUN) */
            const int back = o->slip_n < len ? o->slip_n : len;
            o->slip_flag = back > 0 &&
                fabs(o->slip_u - o->slip_ring[(o->slip_i + 64 - back) % 64]) > SLIP_DEG;
            o->slip_ring[o->slip_i] = o->slip_u;
            o->slip_i = (o->slip_i + 1) % 64;
            if (o->slip_n < len) o->slip_n++;
        }
        slipping = o->slip_flag;
    } else {
        o->slip_n = 0;
        o->slip_k = 0;
        o->slip_flag = 0;
    }
    if (st == FOC_STATE_RUN && en) {
        const int disagree = slipping;
        const int stalled = fabs(wref) >= STILL_FRACTION * wmax && fabs(w) < STILL_FRACTION * wmax;
        if (disagree || stalled) {
            o->last_nf_t = t;
            if (!o->nf_on || t - o->nf_last > NF_GAP_S) {
                o->nf_on = 1;
                o->nf_start = t;
                o->nf_cmd = 0.0;
            }
            o->nf_last = t;
            o->nf_cmd = fmax(o->nf_cmd, fabs(wcmd));
            const double bound = o->nf_cmd > 0.1 * wmax ? DET_FAST_S : DET_SLOW_S;
            if (t - o->nf_start > bound) {
                violate(o, V_NOFOLLOW, t,
                        "RUN, no fault %.2f s after the rotor stopped following "
                        "(true %.0f rpm, estimate %.0f, command %.0f)",
                        t - o->nf_start, w, west, wcmd);
                o->nf_on = 0;
            }
        }
    } else if (o->nf_on) {
        if (st == FOC_STATE_FAULT && t - o->nf_last <= NF_GAP_S) {
            const double d = t - o->nf_start;
            o->detections++;
            if (d > o->det_worst_s) o->det_worst_s = d;
        }
        o->nf_on = 0;
    }

    /* 4. energised standstill (thermal budget) */
    if (en && fabs(w) < STILL_FRACTION * wmax && imag >= 0.5 * MOTOR_RATED_CURRENT_A) {
        if (!o->still_on || t - o->still_last > NF_GAP_S) {
            o->still_on = 1;
            o->still_start = t;
        }
        o->still_last = t;
        if (t - o->still_start > bound_still_s()) {
            violate(o, V_THERMAL, t, "energised standstill %.2f s at %.2f A in %s",
                    t - o->still_start, imag, foc_state_name(st));
            o->still_on = 0;
        }
    }

    /* 5. overspeed (the rotor not driven by the scenario) */
    if (m->rotor != PMSM_ROTOR_SPIN && fabs(w) > ORACLE_OVERSPEED * wmax) {
        violate(o, V_OVERSPEED, t, "%.0f rpm = %.2f x MOTOR_MAX_SPEED_RPM in %s", w,
                fabs(w) / wmax, foc_state_name(st));
    }

    /* 6. bus over-voltage noticed */
    if (r->vdc_v > OV_MARGIN * OVERVOLTAGE_V &&
        (c->faults.active & FOC_FAULT_OVERVOLTAGE) == 0u && inj != INJ_FAULT) {
        if (o->ov_since < 0.0) o->ov_since = t;
        if (t - o->ov_since > OV_DETECT_S) {
            violate(o, V_BUS_OV, t, "bus %.1f V (OVERVOLTAGE_V %.1f) unnoticed for %.1f ms",
                    r->vdc_v, OVERVOLTAGE_V, 1e3 * (t - o->ov_since));
        }
    } else {
        o->ov_since = -1.0;
    }

    /* 7. false trips: a newly latched fault with no physical cause */
    if (first != 0u && o->prev_first == 0u) {
        o->last_cause = fault_cause(o, first, t);
    }
    if (first != 0u && o->prev_first == 0u && o->last_cause == NULL) {
        violate(o, V_FALSE_TRIP, t, "%s in %s with no physical cause (true %.0f rpm, est %.0f)",
                foc_fault_name(first), foc_state_name(o->prev_state), w, west);
    }
    o->prev_first = first;
    o->prev_state = st;

    o->vdc_max = fmax(o->vdc_max, r->vdc_v);
    if (t >= t_end - 0.3) {
        o->tail_sum += w;
        o->tail_n++;
    }
}

/* --------------------------------------------------------------- runs -- */

typedef struct {
    oracle_t o;
    foc_state_t final_state;
    uint16_t fault;
    double t_end;
    double angle_err_rms_deg; /* sim_angle_err_rms_deg: in RUN from measure_from_s */
    double sample_peak_a;     /* the largest sampled phase current, A */
} result_t;

static int run_spec(const spec_t *sp, inject_t inj, int trace, result_t *res)
{
    scn_t scn;
    char err[256];
    if (scn_parse_text(sp->text, "torture", &scn, err, sizeof err) != 0) {
        fprintf(stderr, "torture: scenario error: %s\n", err);
        return -1;
    }
    static sim_t sim;
    sim_options_t opt;
    sim_default_options(&opt);
    opt.estimator = sp->est;
    opt.stop_mode = sp->stop_mode;
    opt.min_speed_rpm = sp->min_speed_rpm;
    opt.mtpa = sp->mtpa;
    opt.measure_from_s = sp->measure_from_s;
    if (sim_init(&sim, &opt, &scn, err, sizeof err) != 0) {
        fprintf(stderr, "torture: sim error: %s\n", err);
        scn_free(&scn);
        return -1;
    }
    sim.model.p.coulomb_nm = sp->coulomb_nm;
    host_port()->temp_degc = 25.0;
    oracle_init(&res->o);
    sim_row_t row;
    long k = 0;
    while (sim_step(&sim, &row)) {
        oracle_step(&res->o, &sim, &row, inj, scn.end_s);
        if (trace > 0 && k % trace == 0) {
            char buf[512];
            sim_csv_row(&row, buf, sizeof buf);
            printf("%s\n", buf);
        }
        k++;
    }
    if (sim.model_failed) {
        fprintf(stderr, "torture: the motor model's state is no longer finite at %.6f s\n",
                sim.t_s);
        scn_free(&scn);
        return -1;
    }
    sim_commission_print(&sim, stdout); /* (a scenario with `commission`) */
    res->final_state = sim.ctrl.state;
    res->fault = sim.ctrl.faults.first;
    res->t_end = scn.end_s;
    res->angle_err_rms_deg = sim_angle_err_rms_deg(&sim);
    res->sample_peak_a = sim.peak_current_a;
    scn_free(&scn);
    return 0;
}

static int total_violations(const result_t *r)
{
    int n = 0;
    for (int k = 0; k < V_KINDS; k++) n += r->o.count[k] != 0;
    return n;
}

static void print_result(const char *label, const spec_t *sp, const result_t *r)
{
    printf("%s motor=%s est=%s stop=%s violations=", label, TORTURE_MOTOR,
           foc_est_name(sp->est), stop_names[sp->stop_mode]);
    int any = 0;
    for (int k = 0; k < V_KINDS; k++) {
        if (r->o.count[k]) {
            printf("%s%s", any ? "," : "", v_names[k]);
            any = 1;
        }
    }
    if (!any) printf("none");
    printf(" peak_ratio=%.3f det_worst_s=%.3f detections=%d end_state=%s fault=%s cause=%s"
           " t_end=%.2f unjudged_current_s=%.4f angle_err_rms_deg=%.3f\n",
           r->o.peak_ratio, r->o.det_worst_s, r->o.detections, foc_state_name(r->final_state),
           foc_fault_name(r->fault), r->o.last_cause ? r->o.last_cause : "-", r->t_end,
           (double)r->o.uncontrollable_periods / PWM_FREQUENCY_HZ, r->angle_err_rms_deg);
    for (int k = 0; k < V_KINDS; k++) {
        if (r->o.count[k]) {
            printf("  %s at %.4f s: %s\n", v_names[k], r->o.first_t[k], r->o.what[k]);
        }
    }
}

/* Parses the `#!` lines of a written scenario. */
static int parse_directives(const char *text, spec_t *sp, int *ests, int *nests)
{
    const char *p = text;
    *nests = 0;
    while (*p) {
        const char *eol = strchr(p, '\n');
        size_t len = eol ? (size_t)(eol - p) : strlen(p);
        char line[256];
        if (len >= sizeof line) len = sizeof line - 1;
        memcpy(line, p, len);
        line[len] = '\0';
        if (strncmp(line, "#!", 2) == 0) {
            char key[32] = "", a[32] = "", b[32] = "";
            sscanf(line + 2, "%31s %31s %31s", key, a, b);
            if (strcmp(key, "estimator") == 0) {
                char *tok = strtok(line + 2 + strlen(" estimator"), " \t");
                while (tok && *nests < 3) {
                    for (int i = 0; i < 3; i++) {
                        if (strcmp(tok, est_names[i]) == 0) ests[(*nests)++] = i;
                    }
                    tok = strtok(NULL, " \t");
                }
            } else if (strcmp(key, "stop_mode") == 0) {
                for (int i = 0; i < 3; i++) {
                    if (strcmp(a, stop_names[i]) == 0) sp->stop_mode = i;
                }
            } else if (strcmp(key, "coulomb") == 0) {
                sp->coulomb_nm = atof(a);
            } else if (strcmp(key, "min_speed_rpm") == 0) {
                sp->min_speed_rpm = atoi(a);
            } else if (strcmp(key, "mtpa") == 0) {
                sp->mtpa = (strcmp(a, "off") == 0) ? 0 : 1;
            } else if (strcmp(key, "measure_from") == 0) {
                sp->measure_from_s = atof(a);
            } else if (strcmp(key, "expect") == 0) {
                if (strcmp(a, "fault") == 0) {
                    sp->expect_fault = 1;
                } else if (strcmp(a, "bus_below_ov") == 0) {
                    sp->expect_bus_below_ov = 1;
                } else if (strcmp(a, "running_or_fault") == 0) {
                    sp->expect_running_or_fault = 1;
                } else if (strcmp(a, "state") == 0) {
                    snprintf(sp->expect_state, sizeof sp->expect_state, "%s", b);
                } else if (strcmp(a, "angle_rms") == 0) {
                    sp->has_expect_angle_rms = 1;
                    sp->expect_angle_rms_deg = atof(b);
                } else if (strcmp(a, "speed") == 0) {
                    sp->has_expect_speed = 1;
                    sp->expect_speed_rpm = atof(b);
                    const char *tol = strstr(line, b) + strlen(b);
                    sp->expect_speed_tol = atof(tol) / 100.0;
                }
            } else if (strcmp(key, "motor") != 0) {
                fprintf(stderr, "torture: unknown directive: %s\n", line);
                return -1;
            }
        }
        p = eol ? eol + 1 : p + len;
    }
    return 0;
}

static char *read_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)n + 1);
    if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
    }
    if (buf) buf[n] = '\0';
    fclose(f);
    return buf;
}

static int check_expectations(const spec_t *sp, result_t *r)
{
    if (sp->expect_fault && r->fault == 0u) {
        violate(&r->o, V_EXPECT, r->t_end, "expected a named fault, none latched (end in %s)",
                foc_state_name(r->final_state));
    }
    if (sp->expect_state[0] && strcmp(sp->expect_state, foc_state_name(r->final_state)) != 0) {
        violate(&r->o, V_EXPECT, r->t_end, "expected final state %s, got %s (fault %s)",
                sp->expect_state, foc_state_name(r->final_state), foc_fault_name(r->fault));
    }
    if (sp->expect_bus_below_ov && r->o.vdc_max > OVERVOLTAGE_V) {
        violate(&r->o, V_EXPECT, r->t_end, "bus reached %.1f V, above OVERVOLTAGE_V %.1f V",
                r->o.vdc_max, OVERVOLTAGE_V);
    }
    if (sp->expect_running_or_fault && r->final_state != FOC_STATE_RUN && r->fault == 0u) {
        violate(&r->o, V_EXPECT, r->t_end, "expected RUN or a named fault, ended in %s",
                foc_state_name(r->final_state));
    }
    /* NaN (no period measured) fails too */
    if (sp->has_expect_angle_rms && !(r->angle_err_rms_deg <= sp->expect_angle_rms_deg)) {
        violate(&r->o, V_EXPECT, r->t_end,
                "expected the angle error within %.2f deg RMS in RUN from %.3f s, got %.3f deg",
                sp->expect_angle_rms_deg, sp->measure_from_s, r->angle_err_rms_deg);
    }
    if (sp->has_expect_speed) {
        const double mean = r->o.tail_n ? r->o.tail_sum / (double)r->o.tail_n : 0.0;
        if (fabs(mean - sp->expect_speed_rpm) >
            sp->expect_speed_tol * fabs(sp->expect_speed_rpm)) {
            violate(&r->o, V_EXPECT, r->t_end,
                    "expected %.0f rpm +-%.0f %% over the last 0.3 s, got %.0f rpm",
                    sp->expect_speed_rpm, 100.0 * sp->expect_speed_tol, mean);
        }
    }
    return total_violations(r);
}

static int run_scenario_file(const char *path, int est_override, int trace)
{
    char *text = read_file(path);
    if (!text) {
        fprintf(stderr, "torture: cannot read %s\n", path);
        return 2;
    }
    static spec_t sp;
    memset(&sp, 0, sizeof sp);
    sp.stop_mode = STOP_MODE;
    sp.coulomb_nm = MOTOR_COULOMB_NM;
    sp.min_speed_rpm = -1;
    sp.mtpa = -1;
    int ests[3], nests;
    if (parse_directives(text, &sp, ests, &nests) != 0) {
        free(text);
        return 2;
    }
    snprintf(sp.text, sizeof sp.text, "%s", text);
    free(text);
    if (est_override >= 0) {
        ests[0] = est_override;
        nests = 1;
    }
    if (nests == 0) {
        ests[nests++] = 0;
    }
    int bad = 0;
    for (int i = 0; i < nests; i++) {
        sp.est = est_kinds[ests[i]];
        static result_t r;
        if (run_spec(&sp, INJ_NONE, trace, &r) != 0) return 2;
        const int v = check_expectations(&sp, &r);
        char label[300];
        snprintf(label, sizeof label, "%s %s", v ? "FAIL" : "PASS", path);
        print_result(label, &sp, &r);
        bad |= v != 0;
    }
    return bad;
}

/* ---------------------------------------------------------- self-test -- */

/* A benign start and speed step on the nominal plant. */
static void benign_spec(spec_t *sp)
{
    memset(sp, 0, sizeof *sp);
    sp->mtpa = -1;
    sp->est = FOC_EST_PLL;
    sp->stop_mode = STOP_MODE_RAMP;
    sp->coulomb_nm = MOTOR_COULOMB_NM;
    const double t_start = CALIB_TIME_S + STARTUP_ALIGN_TIME_S + STARTUP_RAMP_TIME_S;
    spec_add(sp, "0 speed %.0f\n0 start\n", 0.5 * MOTOR_NOMINAL_SPEED_RPM);
    spec_add(sp, "%.3f speed %.0f\n", t_start + 0.5, 0.8 * MOTOR_NOMINAL_SPEED_RPM);
    spec_add(sp, "%.3f stop\n", t_start + 1.0);
    spec_add(sp, "%.3f end\n", t_start + 1.0 + bound_stop_s(MOTOR_NOMINAL_SPEED_RPM) + 0.2);
}

static int selftest(void)
{
    static spec_t sp;
    static result_t r;
    int fail = 0;
    benign_spec(&sp);
    if (run_spec(&sp, INJ_NONE, 0, &r) != 0) return 2;
    print_result("selftest benign", &sp, &r);
    if (total_violations(&r) != 0 || r.o.peak_ratio <= 0.1) {
        printf("selftest: FAIL: the benign run is not clean\n");
        fail = 1;
    }
    static const struct { inject_t inj; int kind; const char *name; } cases[] = {
        { INJ_CURRENT, V_CURRENT, "current spike" },
        { INJ_STALL, V_NOFOLLOW, "rotor stalled (true speed 0)" },
        { INJ_SLIP, V_NOFOLLOW, "rotor slipping (true angle lags)" },
        { INJ_BUS, V_BUS_OV, "bus above the over-voltage threshold" },
        { INJ_SPEED, V_OVERSPEED, "overspeed" },
        { INJ_FAULT, V_FALSE_TRIP, "fault without cause" },
        { INJ_TRANSIT, V_TRANSIT, "STOP that never ends" },
        { INJ_THERMAL, V_THERMAL, "energised standstill" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        if (run_spec(&sp, cases[i].inj, 0, &r) != 0) return 2;
        const int hit = r.o.count[cases[i].kind] != 0;
        printf("selftest inject %-40s -> %s%s%s%s\n", cases[i].name, v_names[cases[i].kind],
               hit ? " caught" : " MISSED", r.o.last_cause ? ", cause " : "",
               r.o.last_cause ? r.o.last_cause : "");
        fail |= !hit;
    }
    /* the ripple: on the switched bridge the benign run's judged peak is
     * above every sampled current (the oracle reads the extremes; the
     * Hurst075's ripple is 1 % of that peak) */
    {
        static spec_t sw;
        benign_spec(&sw);
        spec_add(&sw, "0 plant switched 1\n");
        if (run_spec(&sw, INJ_NONE, 0, &r) != 0) return 2;
        const double peak_a = r.o.peak_ratio * CURRENT_LIMIT_A;
        const int seen = total_violations(&r) == 0 && peak_a > 1.002 * r.sample_peak_a;
        printf("selftest switched bridge: peak %.4f A, sampled %.4f A -> %s\n", peak_a,
               r.sample_peak_a, seen ? "ripple seen" : "MISSED");
        fail |= !seen;
    }
    /* the stall must also show up as a thermal violation when it lasts */
    /* determinism: one seed, one run */
    static spec_t a, b;
    static result_t ra, rb;
    generate(12345u, &a);
    generate(12345u, &b);
    if (strcmp(a.text, b.text) != 0) {
        printf("selftest: FAIL: seed 12345 generated two different scenarios\n");
        fail = 1;
    }
    if (run_spec(&a, INJ_NONE, 0, &ra) != 0 || run_spec(&b, INJ_NONE, 0, &rb) != 0) return 2;
    if (memcmp(ra.o.count, rb.o.count, sizeof ra.o.count) != 0 ||
        ra.o.peak_ratio != rb.o.peak_ratio || ra.final_state != rb.final_state) {
        printf("selftest: FAIL: seed 12345 ran twice with different outcomes\n");
        fail = 1;
    } else {
        printf("selftest: seed 12345 reproduces (peak ratio %.4f both times)\n", ra.o.peak_ratio);
    }
    printf("selftest: %s\n", fail ? "FAILED" : "passed");
    return fail;
}

/* --------------------------------------------------------------- main -- */

int main(int argc, char **argv)
{
    long seed = -1;
    const char *dump = NULL, *scenario = NULL;
    int trace = 0, est = -1;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc) {
            seed = strtol(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--dump") == 0 && i + 1 < argc) {
            dump = argv[++i];
        } else if (strcmp(argv[i], "--scenario") == 0 && i + 1 < argc) {
            scenario = argv[++i];
        } else if (strcmp(argv[i], "--estimator") == 0 && i + 1 < argc) {
            ++i;
            for (int k = 0; k < 3; k++) {
                if (strcmp(argv[i], est_names[k]) == 0) est = k;
            }
        } else if (strcmp(argv[i], "--plant") == 0 && i + 1 < argc) {
            ++i;
            if (strcmp(argv[i], "averaged") == 0) {
                plant_realistic = 0;
            } else if (strcmp(argv[i], "realistic") != 0) {
                fprintf(stderr, "torture: --plant averaged|realistic\n");
                return 2;
            }
        } else if (strcmp(argv[i], "--trace") == 0) {
            trace = (int)(PWM_FREQUENCY_HZ / 1000.0);
        } else if (strcmp(argv[i], "--trace-every") == 0 && i + 1 < argc) {
            trace = (int)strtol(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--selftest") == 0) {
            return selftest();
        } else if (strcmp(argv[i], "--params") == 0) {
            printf("motor=%s max_speed_rpm=%g min_speed_rpm=%g ramp_rpm_per_s=%g "
                   "current_limit_a=%g rated_current_a=%g rated_torque_nm=%g inertia_kgm2=%g "
                   "pwm_hz=%g calib_time_s=%g startup_timeout_s=%g nominal_speed_rpm=%g "
                   "pole_pairs=%d ld_h=%g lq_h=%g flux_wb=%g fw_id_max_a=%g\n",
                   TORTURE_MOTOR, MOTOR_MAX_SPEED_RPM, STARTUP_MIN_SPEED_RPM, SPEED_RAMP_RPM_PER_S,
                   CURRENT_LIMIT_A, MOTOR_RATED_CURRENT_A,
                   kt_nm_per_a(FOC_FLUX_WB) * MOTOR_RATED_CURRENT_A, MOTOR_INERTIA_KGM2,
                   PWM_FREQUENCY_HZ, CALIB_TIME_S, STARTUP_TIMEOUT_S, MOTOR_NOMINAL_SPEED_RPM,
                   (int)MOTOR_POLE_PAIRS, MOTOR_LD_H, MOTOR_LQ_H, FOC_FLUX_WB, FW_ID_MAX_A);
            return 0;
        } else {
            fprintf(stderr,
                    "usage: %s --seed N [--plant averaged|realistic] [--dump FILE.scn] [--trace] | --scenario FILE "
                    "[--estimator pll|luenberger|flux] [--trace | --trace-every N] | --params | --selftest\n",
                    argv[0]);
            return 2;
        }
    }
    if (scenario) {
        return run_scenario_file(scenario, est, trace);
    }
    if (seed < 0) {
        fprintf(stderr, "%s: --seed N, --scenario FILE or --selftest\n", argv[0]);
        return 2;
    }
    static spec_t sp;
    static result_t r;
    generate((uint32_t)seed, &sp);
    if (dump) {
        FILE *f = fopen(dump, "w");
        if (f) {
            fputs(sp.text, f);
            fclose(f);
        }
    }
    if (run_spec(&sp, INJ_NONE, trace, &r) != 0) return 2;
    char label[64];
    snprintf(label, sizeof label, "seed=%ld", seed);
    print_result(label, &sp, &r);
    return 0;
}
