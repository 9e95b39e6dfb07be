/*
 * One simulation: the real controller (core + host port) against the motor
 * model, driven by a scenario.  focsim is a command-line wrapper around it;
 * the scenario tests call it in-process.
 *
 * Each sim_step() is one PWM period k at time t_k = k / f_pwm:
 *   1. scenario events with time <= t_k are applied;
 *   2. the model runs to its ADC's sampling instant (t_k, or mid-period
 *      with `plant midsample 1`) and the fast step runs (samples then,
 *      duties for period k+1);
 *   3. every CONTROL_SLOW_DIVIDER periods the slow step runs after it (a
 *      lower-priority interrupt);
 *   4. the row for t_k is filled;
 *   5. the model integrates period k.
 *
 * The plant starts with the motor and inverter of userparms.h (the
 * controller's belief, including the dead time PWM_DEADTIME_S, which the
 * controller compensates); `plant` commands make it differ.
 */
#ifndef FOCSIM_SIM_H
#define FOCSIM_SIM_H

#include <stdint.h>
#include <stdio.h>

#include "foc/controller.h"
#include "pmsm_model.h"
#include "scenario.h"

typedef struct {
    foc_est_kind_t estimator;
    uint32_t seed;
    int fw_mode;            /* foc_fw_mode_t, or -1 for userparms.h's */
    int stop_mode;          /* foc_stop_mode_t, or -1 for userparms.h's */
    int brake_resistor;     /* 0/1, or -1 for userparms.h's */
    int sensored_start;     /* 1: run on the model's angle until the */
                            /* hand-over speed (a test aid) */
    int ideal_inverter;     /* 1: plant without dead time and the */
                            /* controller without compensation */
    int fault_brake;        /* 0/1, or -1 for userparms.h's FAULT_BRAKE */
    int open_loop_only;     /* 0/1, or -1: OPEN_LOOP_FUNCTIONING */
    int tuning;             /* 0/1, or -1: TUNING */
    int rs_adapt;           /* 0/1, or -1: RS_ADAPTATION */
    int min_speed_rpm;      /* lowest sensorless command, rpm (0: none), */
                            /* or -1: SENSORLESS_MIN_SPEED_RPM */
    int mtpa;               /* 0/1, or -1: MTPA on salient rotors (FOC_SALIENT) */
    int substeps;           /* RK4 substeps per PWM period of the model, */
                            /* 0 for its default (4) */
    double measure_from_s;  /* the angle error's RMS counts the periods in */
                            /* RUN from this time on, s (0: all of RUN) */
} sim_options_t;

/* userparms.h's choices, seed 1, no sensored start. */
void sim_default_options(sim_options_t *o);

/* One CSV row; names and units as in the CSV header (sim_csv_header). */
typedef struct {
    double t_s;
    const char *state;
    const char *fault;
    double speed_ref_rpm, speed_rpm, speed_est_rpm;
    double theta_e_deg, theta_est_deg;
    double id_a, iq_a, id_ref_a, iq_ref_a;
    double vd_v, vq_v, vdc_v, torque_nm;
    double ia_a, ib_a, ic_a;
    int bridge;      /* pmsm_bridge_t the port has set for the next period */
                     /* (not a CSV column) */
} sim_row_t;

typedef struct {
    pmsm_model_t model;
    foc_ctrl_t ctrl;
    const scn_t *scn;
    size_t next_event;
    uint64_t period;
    double t_s;
    double closed_loop_time_s;  /* first entry into RUN, -1 if never */
    double peak_current_a;      /* largest true |phase current| seen */
    int slow_elsewhere;         /* 1: sim_step leaves foc_slow_step to the */
                                /* caller (a test running it preempted) */
    double measure_from_s;      /* sim_options_t's */
    double angle_err_sq_sum;    /* sum of (estimated - true electrical */
    uint64_t angle_err_n;       /* angle, deg)^2 over the periods in RUN */
                                /* from measure_from_s on, and their count */
    int model_failed;           /* 1: the model's state became non-finite */
                                /* (sim_step then ends the run) */
} sim_t;

/* Sets up model, port and controller; 0, or -1 with a message. */
int sim_init(sim_t *s, const sim_options_t *o, const scn_t *scn, char *err,
             size_t errlen);

/* One PWM period; returns 1 while the scenario has not ended, 0 after the
 * last period (row not filled then) or once the model's state is no longer
 * finite (model_failed: a plant value beyond what the model can integrate).  row may be NULL when the caller
 * needs no row for this period (the run is the same; faster). */
int sim_step(sim_t *s, sim_row_t *row);

/* RMS of the estimated minus the plant's true electrical angle, deg, at
 * the sample of every PWM period in RUN from measure_from_s on (the angle
 * the fast step ran on against the rotor's at that instant); NAN when no
 * such period has been simulated. */
double sim_angle_err_rms_deg(const sim_t *s);

/* 1 if the next sim_step is the scenario's last period. */
int sim_last_period(const sim_t *s);

/* The CSV header line (no newline) and one row in the same column order. */
const char *sim_csv_header(void);
void sim_csv_row(const sim_row_t *r, char *buf, size_t len);

/* Parses "sensored|pll|luenberger|flux"; -1 if unknown. */
int sim_estimator_from_name(const char *name, foc_est_kind_t *kind);

/* Parse "off|table|voltage" and "ramp|coast|short"; -1 if unknown. */
int sim_fw_mode_from_name(const char *name, int *mode);
int sim_stop_mode_from_name(const char *name, int *mode);

/* Commissioning's results in SI units (the controller's Q14 ratios times
 * the userparms.h values the core was built with; the friction from its
 * q currents and the measured flux's Kt); `ran`: a commissioning was
 * started, `valid`: it ended with its results. */
typedef struct {
    int ran, valid;
    int mech;                /* J and the friction measured (MECH ran) */
    const char *failed_step; /* "NONE" unless a step failed */
    double rs_ohm, ld_h, lq_h, flux_wb;
    double j_kgm2;     /* inertia */
    double b_nms;      /* viscous friction, Nm per rad/s */
    double coulomb_nm; /* dry friction (the friction line at zero speed) */
    /* (without `mech`: userparms.h's) */
    double deadtime_s; /* the bridge's effective dead time (0: a build */
                       /* without dead time, not measured) */
} sim_commission_t;

void sim_commission_results(const sim_t *s, sim_commission_t *out);

/* The summary's keys id_rs_ohm, id_ld_h, id_lq_h, id_flux_wb, id_deadtime_s, then
 * commission_mech=measured|not_run and, measured, id_j_kgm2, id_b_nms,
 * id_coulomb_nm (and commission_step when one failed), only if a
 * commissioning ran. */
void sim_commission_print(const sim_t *s, FILE *f);

/* A motor description tools/tune.py reads ([motor], per-phase values of
 * the star equivalent) from the results and the userparms.h the firmware
 * was built with (pole pairs, speeds and currents, which commissioning
 * does not measure, and the inertia and friction when MECH did not run);
 * -1 without valid results. */
int sim_commission_ini(const sim_t *s, FILE *f);

/* Q15 speed to mechanical rpm and back (saturating). */
double sim_rpm_from_q15(q15_t speed);
q15_t sim_q15_from_rpm(double rpm);

#endif /* FOCSIM_SIM_H */
