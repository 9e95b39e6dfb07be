/*
 * PMSM + inverter + DC bus + current-sense model, host only, double precision.
 *
 * Plays the inverter, the ADC and the motor for the host port.  Physics in
 * the rotor dq frame (amplitude-invariant Park, same convention as the core:
 * d along the magnet flux, q leading by 90 electrical degrees, positive
 * rotation counter-clockwise, angle of phase A axis = 0):
 *
 *   vd = Rs id + Ld did/dt - we Lq iq
 *   vq = Rs iq + Lq diq/dt + we (Ld id + flux)
 *   Te = 1.5 p (flux iq + (Ld - Lq) id iq)
 *   J dwm/dt = Te - B wm - (Tc + Tload) sgn(wm)      (passive load, with
 *              stiction: at wm = 0 the rotor stays put while |Te| <= Tc+Tload)
 *
 * Inverter: average-value model over each PWM period.  Phase-to-DC-minus
 * voltages are Vdc * duty; the star point floats, so only the differential
 * part reaches the windings.  Optional dead-time error per phase
 * -sgn(i_x) * Vdc * t_dead * f_pwm, fading in proportionally within the
 * PWM-ripple band around zero current (the period average of a rippling
 * current's error; band (2/3) Vdc / (8 L f_pwm)).  Bridge off: each phase is clamped by its
 * free-wheeling diodes (i > 0 -> 0 V, i < 0 -> Vdc) and a phase current
 * that reaches zero stays zero while the back-EMF cannot drive it through
 * the diodes.  Low sides on: all phases at 0 V (windings shorted).
 *
 * Computation delay: duties set during period k are applied during period
 * k+1 (pmsm_set_duties latches, the end of pmsm_step_period makes them
 * active), like a PWM unit's shadow registers loaded at the period boundary.
 *
 * Integration: RK4 with `substeps` steps per PWM period.
 *
 * DC bus: an ideal source of `vdc_source` V.  If `bus_cap_f` > 0 the bus is
 * a capacitor fed from the source through a diode (the source can only
 * deliver current) and 0.05 ohm (raised to 2 substeps / bus_cap_f for small
 * capacitors, to keep the integration stable), so regenerated energy
 * raises the bus voltage; a brake resistor `brake_r_ohm` across the bus can
 * be switched on.  With bus_cap_f = 0 the bus is stiff at vdc_source (and
 * the brake resistor has no effect).
 *
 * Current sensing: the value of each phase current at the sampling instant
 * (start of the period, the centre of the low-side on-time), converted by an
 * ADC of `adc_bits` bits whose full scale spans +-`current_fs_a`, with
 * per-phase offset (codes) and gain error, plus deterministic seeded
 * Gaussian noise (sigma in codes).
 *
 * Plant options (issue 13; each default keeps the ideal model above, bit
 * for bit; focsim's `plant` command for each in brackets; tested in
 * test_model.c against a closed form or the average model):
 * - switched (0) [switched]: the bridge's real switching states within
 *   each period instead of its average: centre-aligned PWM with the ADC's
 *   sampling instant in the middle of the low-side on-time (the ports,
 *   docs/porting.md; [RM0008] TIM1 centre-aligned mode, [DS70283] PWM
 *   section 14); dead time per edge as a dead-time generator inserts it
 *   (each switch turns on deadtime_s after its command, off at once;
 *   meanwhile the free-wheeling diode sets the terminal by the current's
 *   sign), so the average error is -sgn(i) Vdc t_dead f_pwm per leg, the
 *   average model's outside its ripple band.  Integrated by RK4 segment by
 *   segment between switching instants (steps <= 1 / (pwm_hz substeps)).
 *   pmsm_sample_t's i_min_a / i_max_a give the current ripple.
 * - sample_mid_period (0) [midsample]: the ADC samples at mid-period
 *   (pmsm_run_to_sample integrates up to it), as both ports do; duties
 *   still change at the period boundary, so a voltage computed from a
 *   sample is centred 1.0 period after it (0.5 periods of waiting, then
 *   the period), against 1.5 periods when sampling at the period start.
 *   The core assumes SAMPLE_DELAY_PERIODS (config.h, 1.5 by default).
 * - gain_error[3] (0) [gaina/b/c], offset_codes[3] (0) [offseta/b/c: a
 *   step at the command's time, after the core's calibration if later],
 *   offset_drift_codes_per_s[3] (0) [drifta/b/c]: current-sensor gain
 *   mismatch and offset drift (codes = mid + (1 + gain) i / FS half-scale
 *   + offset + drift t).
 * - emf_h5, emf_h7 (0) [emf5, emf7]: back-EMF 5th and 7th harmonics as
 *   fractions of the fundamental: e_a = -we flux (sin th + h5 sin 5th +
 *   h7 sin 7th), in the voltage equations and, by power balance, the
 *   torque (typical surface-magnet values: a few % 5th, about 1 % 7th).
 * - cogging_nm (0), cogging_periods (60: 12 slots x 10 poles, assumed for
 *   the Hurst075) [cogging, coggingperiods]: -cogging_nm sin(N th_m).
 * - ld_sat_a, lq_sat_a (0) [ldsat, lqsat]: saturation of each axis (no
 *   cross-saturation): incremental inductance L0 / (1 + (i / i_sat)^2),
 *   flux linkage its integral L0 i_sat atan(i / i_sat); di/dt uses the
 *   incremental inductance, the rotational EMF and the torque the flux
 *   linkage (1.5 p (psi_d iq - psi_q id)), which keeps the energy balance
 *   exact.
 * - thermal_r_k_per_w (0), thermal_tau_s (600), rs_tempco_per_k (0.0039,
 *   copper) [rth, thermaltau]: Rs = rs_ohm (1 + a rise), the winding's
 *   rise above ambient following tau d(rise)/dt = Rth P - rise with the
 *   copper loss P = 1.5 Rs (id^2 + iq^2).  E.g. the Hurst075 at its rated
 *   1.64 A peak (10 W cold) with Rth 12 K/W settles about 90 K up: Rs
 *   +35 %.
 */
#ifndef PMSM_MODEL_H
#define PMSM_MODEL_H

#include <stdint.h>

typedef enum {
    PMSM_BRIDGE_OFF = 0,       /* all six switches off (diodes only) */
    PMSM_BRIDGE_PWM = 1,       /* duties applied */
    PMSM_BRIDGE_LOW_SIDES = 2  /* all low sides on: windings shorted */
} pmsm_bridge_t;

typedef enum {
    PMSM_ROTOR_FREE = 0,   /* mechanics integrated */
    PMSM_ROTOR_LOCKED = 1, /* speed held at 0, angle frozen */
    PMSM_ROTOR_SPIN = 2    /* speed forced to spin_rpm by an external drive */
} pmsm_rotor_mode_t;

typedef struct {
    /* motor, star-equivalent per phase */
    double rs_ohm;
    double ld_h;
    double lq_h;
    double flux_wb;       /* permanent-magnet flux linkage (peak, per phase) */
    int pole_pairs;
    /* mechanics */
    double j_kgm2;
    double b_nm_per_rad_s; /* viscous friction */
    double coulomb_nm;     /* dry friction */
    /* inverter */
    double pwm_hz;
    double deadtime_s;     /* 0: ideal */
    /* DC bus */
    double vdc_source_v;
    double bus_cap_f;      /* 0: stiff bus */
    double brake_r_ohm;    /* brake resistor value (used when switched on) */
    /* sensing */
    int adc_bits;          /* 10 or 12 */
    double current_fs_a;   /* current at ADC positive full scale */
    double offset_codes[3];/* ADC offset per phase, codes */
    double gain_error[3];  /* relative gain error per phase, e.g. 0.01 */
    double noise_codes;    /* Gaussian noise sigma, codes */
    uint32_t seed;         /* noise seed */
    /* numerics */
    int substeps;          /* RK4 steps per PWM period, >= 1 */
    /* Plant options (issue 13).  Each default leaves the ideal model above
     * exactly as it was; "Plant options" below says what each one does. */
    int switched;          /* 1: the bridge's switching states within */
                           /* each period; 0: average-value inverter */
    int sample_mid_period; /* 1: ADC samples at mid-period; 0: at the */
                           /* period start */
    double offset_drift_codes_per_s[3]; /* ADC offset drift per phase, */
                                        /* codes/s from t = 0 */
    double emf_h5, emf_h7; /* back-EMF 5th and 7th harmonics, fraction */
                           /* of the fundamental (0.03 = 3 %) */
    double cogging_nm;     /* cogging torque amplitude, N m (0: none) */
    int cogging_periods;   /* cogging periods per mechanical turn */
    double thermal_r_k_per_w; /* winding-to-ambient thermal resistance, */
                              /* K/W (0: Rs stays at rs_ohm) */
    double thermal_tau_s;  /* winding thermal time constant, s */
    double rs_tempco_per_k;/* Rs rise per kelvin (copper 0.0039) */
    double ld_sat_a, lq_sat_a; /* saturation current of each axis, A: */
                               /* incremental L = L0 / (1 + (i/i_sat)^2) */
                               /* (0: linear) */
} pmsm_params_t;

typedef struct {
    double id_a, iq_a;     /* rotor-frame currents */
    double wm_rad_s;       /* mechanical speed */
    double theta_e_rad;    /* electrical angle, wrapped to [0, 2 pi) */
    double vdc_v;          /* bus voltage */
} pmsm_state_t;

/* What the ADC and the true-value probes see at the sampling instant. */
typedef struct {
    double ia_a, ib_a, ic_a;        /* true phase currents (into the motor) */
    int32_t ia_code, ib_code, ic_code; /* ADC codes, 0 .. 2^bits - 1, */
                                    /* mid-scale 2^(bits-1) = 0 A */
    double vdc_v;
    double theta_e_rad;             /* [0, 2 pi) */
    double speed_rpm;               /* mechanical */
    double torque_nm;               /* electromagnetic */
    double vd_v, vq_v;              /* average winding voltages applied in */
                                    /* the last period, rotor frame */
    double i_min_a[3], i_max_a[3];  /* extremes of each phase current since */
                                    /* the previous sample: at every */
                                    /* switching instant with the switched */
                                    /* bridge (the ripple's peaks), else */
                                    /* at the sampling instants and period */
                                    /* ends only */
} pmsm_sample_t;

typedef struct {
    pmsm_params_t p;
    pmsm_state_t s;
    pmsm_bridge_t bridge;       /* applied this period */
    pmsm_bridge_t bridge_next;  /* latched for the next period */
    pmsm_bridge_t bridge_at_mode; /* a switch within the present period */
    double bridge_at_s;         /* (pmsm_set_bridge_at): its time into the */
                                /* period, s; < 0 none */
    double duty[3];             /* applied this period, [0, 1] */
    double duty_next[3];
    pmsm_rotor_mode_t rotor;
    double spin_rpm;
    double load_nm;             /* passive load torque magnitude */
    int brake_resistor_on;
    uint32_t rng;               /* noise generator state */
    double vd_last_v, vq_last_v;
    double time_s;
    double period_pos_s;        /* time into the present period (0 at its */
                                /* start; the sampling instant after */
                                /* pmsm_run_to_sample) */
    double vd_int_vs, vq_int_vs;/* winding-voltage integrals since the */
                                /* period start, V s */
    double offset_drift_codes[3]; /* ADC offset drift accumulated so far */
    double i_min_a[3], i_max_a[3];/* phase-current extremes since the */
                                  /* last sample */
    double winding_rise_k;      /* winding temperature above ambient, K */
                                /* (rs_ohm is the resistance at ambient) */
    /* cos/sin of s.theta_e_rad, computed once per period (internal) */
    int trig_valid;
    double trig_theta, trig_cos, trig_sin;
} pmsm_model_t;

/* Defaults: Hurst DMB0224C10002 on a dsPICDEM MCLV-like 24 V inverter,
 * 20 kHz, ideal inverter, stiff bus, 10-bit ADC, 4.4 A full scale, no
 * offset/gain error/noise, 4 RK4 substeps. */
void pmsm_default_params(pmsm_params_t *p);

/* Initialises state to rest (zero currents and speed, angle 0, bus at the
 * source voltage, bridge off, rotor free). */
void pmsm_init(pmsm_model_t *m, const pmsm_params_t *p);

/* Latches duties (each clamped to [0, 1]) and bridge mode for the next
 * period. */
void pmsm_set_duties(pmsm_model_t *m, double da, double db, double dc);
void pmsm_set_bridge(pmsm_model_t *m, pmsm_bridge_t mode);

/* The bridge switches to `mode` at once, for the rest of the present
 * period and after (the ports' turn-off: MOE or OVDCON, not latched at the
 * period boundary). */
void pmsm_set_bridge_now(pmsm_model_t *m, pmsm_bridge_t mode);

/* The bridge switches to `mode` at at_s into the present period (a time
 * after period_pos_s), or at the period boundary when at_s is not before
 * the period's end; it stays so after. */
void pmsm_set_bridge_at(pmsm_model_t *m, pmsm_bridge_t mode, double at_s);

/* Samples currents/bus at the present instant (the period start, or the
 * sampling instant after pmsm_run_to_sample).  Each call draws fresh
 * noise. */
void pmsm_sample(pmsm_model_t *m, pmsm_sample_t *out);

/* Integrates the present period from its start up to the ADC's sampling
 * instant (nothing when it samples at the period start).  A host port
 * calls it before pmsm_sample; pmsm_step_period then integrates the rest. */
void pmsm_run_to_sample(pmsm_model_t *m);

/* Integrates the rest of the PWM period with the active duties/bridge,
 * then makes the latched ones active. */
void pmsm_step_period(pmsm_model_t *m);

/* Run-time changes (scenario commands). */
void pmsm_set_rotor_angle(pmsm_model_t *m, double theta_e_rad);
void pmsm_set_rotor_mode(pmsm_model_t *m, pmsm_rotor_mode_t mode, double spin_rpm);
void pmsm_set_load(pmsm_model_t *m, double load_nm);
void pmsm_set_vdc(pmsm_model_t *m, double vdc_source_v);
void pmsm_set_brake_resistor(pmsm_model_t *m, int on);

/* cos and sin of the present electrical angle (s.theta_e_rad), as cos()
 * and sin() give them; computed once per period and shared with
 * pmsm_sample and pmsm_step_period. */
void pmsm_cos_sin(pmsm_model_t *m, double *cos_theta, double *sin_theta);

/* Torque on the rotor for the given currents at electrical angle
 * theta_e (magnet with its EMF harmonics, reluctance, cogging), N m. */
double pmsm_torque(const pmsm_params_t *p, double id_a, double iq_a, double theta_e_rad);

/* Winding resistance at the present winding temperature, ohm. */
double pmsm_rs_ohm(const pmsm_model_t *m);

#endif /* PMSM_MODEL_H */
