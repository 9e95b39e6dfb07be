/*
 * userparms.h — motor and application parameters, in physical units.
 *
 * Motor: Shinano Kenshi LA052-080E3NL1, described in
 *   motors/shinano_la052.ini: Ke 4.0 V rms line-to-line per krpm, rated
 *   current 1.6 A rms (ST's figures); rotor inertia and friction are assumed
 *   values.
 * Board: ST STM3210B-MCKIT (STM32F103 + MB459 three-shunt inverter),
 *   described in boards/stm3210b_mckit/board.ini: MB459 figures from ST's
 *   PMSM FOC library v2.0 for this kit (sources in
 *   docs/boards/stm3210b_mckit.md): bus divider BUS_ADC_CONV_RATIO 0.008
 *   (MC_Control_Param.h); phase current = X x 0.64 V / (32767 x Rshunt) with
 *   0.22 ohm shunts, i.e. 0.64 V across the shunt swings the amplifier over
 *   half the ADC range (gain 2.58, offset mid-scale, output falling for
 *   current into the motor), ST's MAX_CURRENT 2.9 A; the heatsink NTC read
 *   as T = 14 degC + 195 degC x (V / 3.3 V) (MC_MotorControl_Layer.c). These
 *   are the kit's nominal values: check them against the board in hand.
 * Written by tools/tune.py: current loop 1000 Hz, speed loop 381.972 rad/s,
 *   observer 5326.97 rad/s.
 *
 * The template userparms.h.in is this file for its motor and board (the
 * defaults).  For another motor describe the motor and the board and run
 * tools/tune.py (docs/new-motor.md), or copy the template and change the
 * values; the host build uses userparms.h at the repository root if there
 * is one, or the file FOC_USERPARMS=<path> names.
 *
 * Every Q15 constant the firmware uses is derived from these values at
 * compile time (include/foc/config.h); a value that would overflow its
 * fixed-point format stops the build with a message naming the parameter.
 *
 * Conventions: resistances and inductances are per phase of the equivalent
 * star (for a line-to-line measurement divide by 2; for a delta motor's
 * phase values divide by 3); currents are peak phase amperes; speeds are
 * mechanical rpm unless the name says otherwise.
 */
#ifndef USERPARMS_H
#define USERPARMS_H

/* ---------------------------------------------------------------- motor -- */
#define MOTOR_POLE_PAIRS            2        /* pole pairs */
#define MOTOR_RS_OHM                0.35     /* stator resistance, ohm */
#define MOTOR_LD_H                  6.0e-4   /* d-axis inductance, H */
#define MOTOR_LQ_H                  6.0e-4   /* q-axis inductance, H */
#define MOTOR_KE_VPK_PER_KRPM       5.657    /* back-EMF constant, V peak */
                                             /* line-to-line per 1000 rpm */
#define MOTOR_NOMINAL_SPEED_RPM     3000.0   /* rated speed, rpm */
#define MOTOR_MAX_SPEED_RPM         4000.0   /* mechanical limit, rpm */
#define MOTOR_RATED_CURRENT_A       2.263    /* rated current, A peak */
/* Rotor inertia and friction: the motor description's, or estimated from
 * the rated torque (see the header). */
#define MOTOR_INERTIA_KGM2          1.0e-5   /* rotor inertia, kg m^2 */
#define MOTOR_VISCOUS_NM_PER_KRPM   3.14e-4  /* viscous friction, Nm per */
                                             /* 1000 rpm (3e-6 Nm s/rad) */
#define MOTOR_COULOMB_NM            1.0e-3   /* dry friction, Nm */

/* ------------------------------------------------------ inverter / board -- */
#define BOARD_VDC_NOMINAL_V         24.0     /* DC bus, V (voltage base) */
#define BOARD_VDC_FULL_SCALE_V      412.5    /* bus voltage at ADC full */
                                             /* scale: Vref / divider */
#define BOARD_CURRENT_FULL_SCALE_A  2.9      /* phase current at ADC full */
                                             /* scale (current base): */
                                             /* Vref / 2 / (shunt x gain) */
#define BOARD_ADC_BITS              12       /* ADC resolution, bits */
#define BOARD_ADC_VREF_V            3.3      /* ADC reference, V */
#define BOARD_TEMP_V_AT_0C          (-0.2369) /* temperature sensor output */
#define BOARD_TEMP_V_PER_DEGC       0.016923 /* at 0 degC and its slope */
#define PWM_FREQUENCY_HZ            16000.0  /* PWM and control rate, Hz */
#define PWM_DEADTIME_S              8.0e-7   /* dead time, s */
#define DEADTIME_EFFECTIVE_S        PWM_DEADTIME_S /* the bridge's */
                                             /* effective dead time, s */
                                             /* (config.h; commissioning */
                                             /* measures it) */
#define DEADTIME_COMPENSATION       1        /* 1: correct the duties for */
                                             /* the dead time (deadtime.h) */
#define DEADTIME_COMP_CURRENT_A     0.15     /* compensation soft band, A */
#define CONTROL_SLOW_DIVIDER        8        /* PWM periods per slow tick */
                                             /* (speed loop, state machine) */

/* -------------------------------------------------------- per-unit bases -- */
#define SPEED_BASE_RPM              8000.0   /* speed of Q15 1.0, rpm; above */
                                             /* every speed the motor reaches */

/* ------------------------------------------------------- current control -- */
#define CURRENT_LIMIT_A             2.1      /* phase current limit, A peak */
/* Current PI, in volts per ampere: Kp = Ls wc and Ki = Rs wc place the PI
 * zero on the winding pole, giving a first-order loop of bandwidth wc
 * (the header gives wc / 2 pi). */
#define CURRENT_KP_V_PER_A          3.77
#define CURRENT_KI_V_PER_AS         2199.0
#define VOLTAGE_LIMIT_FRACTION      0.95     /* |Vdq| limit as a fraction of */
                                             /* Vdc/sqrt(3) (linear SVM) */

/* --------------------------------------------------------- speed control -- */
/* Speed PI from amperes of q current per rpm of error: Kp = J wb / Kt and
 * Ki = Kp wb / 4 for the bandwidth wb of the header, Kt = 1.5 p flux. */
#define SPEED_KP_A_PER_RPM          8.55e-3
#define SPEED_KI_A_PER_RPM_S        0.8165
#define SPEED_RAMP_RPM_PER_S        10000.0  /* reference slew rate */
#define SPEED_FILTER_TIME_S         0.5e-3   /* speed measurement filter */

/* ------------------------------------------------------------ estimator -- */
/* Angle/speed source for closed loop: FOC_EST_PLL (AN1292 back-EMF PLL),
 * FOC_EST_LUENBERGER (observer + PLL), FOC_EST_FLUX (flux linkage + speed
 * observer) or FOC_EST_SENSORED (a position sensor). */
#define FOC_ESTIMATOR               FOC_EST_PLL
/* PLL estimator (AN1292): filters on the rotor-frame back-EMF and on the
 * speed; below PLL_LOW_SPEED_RPM the back-EMF is averaged over 8 periods
 * (the L di/dt term is then a difference over 8 samples). */
#define PLL_EMF_FILTER_TIME_S       0.2e-3
#define PLL_SPEED_FILTER_TIME_S     1.0e-3
#define PLL_LOW_SPEED_RPM           640.0
/* Flux-linkage estimator (Wang/Luo/Guo): the integrated flux is pulled
 * toward a circle at FLUX_CORR_MIN_RAD_S + FLUX_CORR_PER_SPEED x |electrical
 * speed| (rad/s): higher rejects offsets better (angle error about offset
 * voltage / back-EMF at 1.5); an unknown initial flux is shed in about 1 to
 * 2 electrical turns, fastest near 1.5.  The circle's radius (the magnet
 * flux) is learned with a low-pass at FLUX_MAG_PER_SPEED x |electrical
 * speed|; keep it at most 0.05 x FLUX_CORR_PER_SPEED (0.2 x oscillated with
 * dead time at no load).  The speed observer (mechanical model, torque command fed forward
 * through MOTOR_INERTIA_KGM2, friction neglected) has three poles at
 * -FLUX_SPEED_OBS_BW_RAD_S. */
#define FLUX_CORR_MIN_RAD_S         30.0
#define FLUX_CORR_PER_SPEED         1.5
#define FLUX_MAG_PER_SPEED          0.075
#define FLUX_SPEED_OBS_BW_RAD_S     800.0
/* Luenberger observer + PLL (ST, docs/references.md [ST-FOC]).  K1, K2: the observer's
 * current-error gains, in ST's physical units, placed so that the observer
 * error obeys s^2 + (Rs/Ls - K1) s + K2/Ls = 0 with a double pole at the
 * observer bandwidth wo of the header: K2 = Ls wo^2, K1 = Rs/Ls - 2 wo,
 * wo where the steady angle error that the EMF model's Euler rotation
 * leaves is zero at the top speed, about 0.32 x PWM_FREQUENCY_HZ
 * (tools/tune.py observer_bw; ST's -12000 and 85200, 6661.5 rad/s, are
 * within 3 % of it on the Hurst075 at 20 kHz, whose error decays with
 * discrete poles 0.79 and 0.45, within about 1 ms; config.h checks that
 * the poles lie inside the unit circle).  F1, F2: the extra resolution of
 * the current and EMF states (powers of two; ST's values, or the nearest
 * that fit the motor).
 * PLL gains: ST's formulas Kp = 532 fe/fs, Ki = 1506742 fe/fs^2 with fe
 * the maximum electrical speed in electrical rpm, in ST's scaling (speed
 * in 1/65536 turn per period, EMF as Q15 of the EMF at maximum speed,
 * Kp over 2^14, Ki over 2^16): a loop of natural frequency
 * sqrt(72.2 fe) rad/s and damping 0.006 sqrt(fe) at maximum speed
 * (1124 rad/s and 0.79 on the Hurst075), which our PLL keeps at all
 * speeds (its input is normalised by the EMF amplitude, see
 * foc/luenberger.h). */
#define LUENBERGER_K1_PER_S         (-10070.0) /* 1/s, < 0 */
#define LUENBERGER_K2_V_PER_AS      17030.0    /* V/(A s), > 0 */
#define LUENBERGER_F1               2048
#define LUENBERGER_F2               8192
#define LUENBERGER_PLL_KP                                                      \
    (532.0 * MOTOR_MAX_SPEED_RPM * MOTOR_POLE_PAIRS / PWM_FREQUENCY_HZ)
#define LUENBERGER_PLL_KI                                                      \
    (1506742.0 * MOTOR_MAX_SPEED_RPM * MOTOR_POLE_PAIRS /                      \
     (PWM_FREQUENCY_HZ * PWM_FREQUENCY_HZ))
#define LUENBERGER_SPEED_FILTER_TIME_S 1.0e-3  /* speed output filter, s */
/* Sensored start (host test aid, boards with a position sensor): closed
 * loop on the sensor until this speed, then on the estimator. */
#define SENSORED_HANDOVER_RPM       380.0

/* ------------------------------------------------------ field weakening -- */
/* FW_MODE_VOLTAGE: a PI keeps |Vdq| at FW_VOLTAGE_MARGIN of the voltage
 * limit by driving Id negative (no per-motor tables).  FW_MODE_TABLE:
 * AN1292's three lookup tables indexed by the speed reference between
 * FW_START_RPM and FW_END_RPM (Id reference, 1/KFi and Ls/(2 Ls0) for the
 * estimator), linearly interpolated; past the last entry the last value
 * holds.  The initial Id table is computed from the motor data (no-load
 * voltage balance), 1/KFi and Ls are nominal; to use tuned tables define
 * FW_ID_TABLE as { FOC_I_Q15(-0.09), ... } (18 entries, amperes),
 * FW_INVKFI_TABLE as { FOC_FW_INVKFI_Q(1.0), ... } (ratio to nominal) and
 * FW_LS_TABLE (18 entries of Ls/(2 Ls0), Q15(0.5) = nominal).
 * FW_MODE_OFF: Id = 0. */
#define FW_MODE                     FW_MODE_VOLTAGE
#define FW_ID_MAX_A                 1.7      /* largest -Id, A peak */
#define FW_VOLTAGE_MARGIN           0.95     /* |Vdq| target / limit */
#define FW_VOLTAGE_KP_A_PER_V       0.24     /* voltage PI, A of Id per V */
#define FW_VOLTAGE_KI_A_PER_VS      380.0
#define FW_START_RPM                3000.0   /* table mode */
#define FW_END_RPM                  6000.0

/* ---------------------------------------------------------- application -- */
#define CALIB_TIME_S                0.07     /* current-offset calibration */
#define STOP_SPEED_RPM              50.0     /* STOP ramps down to this (on an */
                                             /* estimate, not below */
                                             /* STARTUP_MIN_SPEED_RPM), then */
                                             /* turns the outputs off */
/* Sensorless, a speed command between 0 and STARTUP_MIN_SPEED_RPM is
 * raised to it, sign kept (below it the estimates drift on a winding off
 * its parameters).  Define SENSORLESS_MIN_SPEED_RPM (0 .. max speed, 0: no
 * floor) for another floor: docs/safety.md. */

/* ------------------------------------------------------------- start-up -- */
/* ALIGN: the current rises to STARTUP_ALIGN_CURRENT_A in a first half of
 * STARTUP_ALIGN_TIME_S at 90 degrees before the start angle, then at the
 * start angle for the second half (two positions, so a rotor 180 degrees
 * away still feels torque) from half of it back to the whole in an eighth
 * of that half (a rotor left at the first position's dead point swings
 * with energy in proportion to the current).  OPENLOOP: the forced angle accelerates
 * to STARTUP_FINAL_SPEED_RPM in STARTUP_RAMP_TIME_S with a current ramped
 * from STARTUP_CURRENT_FIRST_A to STARTUP_CURRENT_FINAL_A; the estimator runs
 * alongside.  Hand-over to RUN only when the estimator has converged: for
 * STARTUP_CONV_TESTS consecutive slow ticks the estimated speed is reliable
 * (64-sample variance <= mean^2 x STARTUP_VARIANCE_THRESHOLD), its mean
 * within STARTUP_SPEED_WINDOW_MIN..MAX x the forced speed and above
 * STARTUP_MIN_SPEED_RPM, and its back-EMF matches its speed.  No
 * convergence within STARTUP_TIMEOUT_S of `start`: fault STARTUP_FAILED. */
#define STARTUP_ALIGN_CURRENT_A     1.6
#define STARTUP_ALIGN_TIME_S        0.31
#define STARTUP_CURRENT_FIRST_A     1.6
#define STARTUP_CURRENT_FINAL_A     1.6
#define STARTUP_FINAL_SPEED_RPM     640.0
#define STARTUP_RAMP_TIME_S         0.25
#define STARTUP_MIN_SPEED_RPM       320.0
#define STARTUP_SPEED_WINDOW_MIN    0.8
#define STARTUP_SPEED_WINDOW_MAX    1.2
#define STARTUP_VARIANCE_THRESHOLD  0.0625
#define STARTUP_CONV_TESTS          32
#define STARTUP_TIMEOUT_S           1.1
#define STARTUP_HANDOVER_TIME_S     0.05     /* forced d current fades out */
/* AN1292's tuning aids: stay in open loop with the estimator running
 * (OPEN_LOOP_FUNCTIONING), or ramp the speed reference slowly for
 * field-weakening tuning (TUNING, at TUNING_RAMP_RPM_PER_S).  Define to
 * enable. */
/* #define OPEN_LOOP_FUNCTIONING */
/* #define TUNING */
#define TUNING_RAMP_RPM_PER_S       150.0

/* ---------------------------------------------------------- supervision -- */
/* Stall / step-out in RUN (and from the hand-over on), fault
 * SPEED_FEEDBACK: the estimated speed unsteady (variance of the last 64
 * slow ticks >= mean^2 x threshold) for STALL_TICKS slow ticks, or, with
 * the estimate back within a quarter of the reference, for STALL_TICKS
 * beyond those 64 (one transient that passed, a load step's dip, keeps
 * the window unsteady for its length; a tick that looks steady takes
 * back half a tick: a rotor slipping poles looks steady a moment each
 * turn); or the estimate below half of STARTUP_MIN_SPEED_RPM, or its
 * back-EMF below STALL_EMF_RATIO of what its speed implies, for
 * STALL_TICKS.  STALL_TICKS < 32000. */
#define STALL_VARIANCE_THRESHOLD    0.0625
#define STALL_EMF_RATIO             0.5
#define STALL_TICKS                 60
/* Bus and temperature faults, with hysteresis for the acknowledge. */
#define OVERVOLTAGE_V               32.0
#define UNDERVOLTAGE_V              16.0
#define BUS_HYSTERESIS_V            1.0
#define OVERTEMP_DEGC               100.0
#define TEMP_HYSTERESIS_DEGC        10.0
#define FAULT_ACK_MIN_TIME_S        0.1      /* a fault stays at least this */

/* -------------------------------------------------------------- braking -- */
/* STOP_MODE_RAMP: speed ramps down, then outputs off.  STOP_MODE_COAST:
 * outputs off at once.  STOP_MODE_SHORT: ramp down to the speed where the
 * short-circuit current w psi / sqrt(R^2 + (w L)^2) stays within
 * CURRENT_LIMIT_A, then all low sides on until stopped.  With
 * BRAKE_RESISTOR_ENABLE 1 the resistor switches on above
 * BRAKE_RESISTOR_ON_V and off below BRAKE_RESISTOR_OFF_V, and a bus over
 * OVERVOLTAGE_V switches it instead of tripping (the trip then comes only
 * at 1.2 x OVERVOLTAGE_V, a resistor that cannot cope). */
#define STOP_MODE                   STOP_MODE_RAMP
/* FAULT_BRAKE 1: a fault other than over-current shorts the windings (when
 * the rotor is below the safe speed above) instead of letting it coast. */
#define FAULT_BRAKE                 0
#define BRAKE_RESISTOR_ENABLE       0
#define BRAKE_RESISTOR_ON_V         29.0
#define BRAKE_RESISTOR_OFF_V        27.0

#endif /* USERPARMS_H */
