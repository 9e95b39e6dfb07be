/*
 * userparms.h for the Shinano Kenshi LA052-080E3NL1 on ST's STM3210B-MCKIT
 * (MB459 three-shunt inverter, 24 V).  Written from userparms.h.in; the
 * motor facts are ST's (DESIGN.md section 3), the board facts are the kit's
 * nominal values and should be checked against the board in hand.
 * For another motor, copy it to userparms.h at the repository root (the
 * host build then uses that file) or point FOC_USERPARMS=<path> at a copy,
 * and change the values.  tools/tune.py writes such a file from a motor and
 * a board description.
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
#define MOTOR_LD_H                  0.6e-3   /* d-axis inductance, H */
#define MOTOR_LQ_H                  0.6e-3   /* q-axis inductance, H */
#define MOTOR_KE_VPK_PER_KRPM       5.657    /* back-EMF constant, V peak */
                                             /* line-to-line per 1000 rpm */
#define MOTOR_NOMINAL_SPEED_RPM     3000.0   /* rated speed, rpm */
#define MOTOR_MAX_SPEED_RPM         4000.0   /* mechanical limit, rpm */
#define MOTOR_RATED_CURRENT_A       2.26     /* rated current, A peak */
/* Ke: 4.0 V rms line-to-line per krpm = 5.657 V peak.  Rated current 1.6 A
 * rms.  Rotor inertia and friction: assumed values. */
#define MOTOR_INERTIA_KGM2          1.0e-5   /* rotor inertia, kg m^2 */
#define MOTOR_VISCOUS_NM_PER_KRPM   3.14e-4  /* viscous friction, Nm per */
                                             /* 1000 rpm (3e-6 Nm s/rad) */
#define MOTOR_COULOMB_NM            1.0e-3   /* dry friction, Nm */

/* ------------------------------------------------------ inverter / board -- */
#define BOARD_VDC_NOMINAL_V         24.0     /* DC bus, V (voltage base) */
#define BOARD_VDC_FULL_SCALE_V      63.2     /* bus voltage at ADC full */
                                             /* scale (divider 1/16, 3.3 V) */
#define BOARD_CURRENT_FULL_SCALE_A  2.9      /* phase current at ADC full */
                                             /* scale (assumed MB459 shunt */
                                             /* and amplifier)           */
#define BOARD_ADC_BITS              12       /* ADC resolution, bits */
#define BOARD_ADC_VREF_V            3.3      /* ADC reference, V */
#define BOARD_TEMP_V_AT_0C          0.5      /* temperature sensor output */
#define BOARD_TEMP_V_PER_DEGC       0.01     /* at 0 degC and its slope */
#define PWM_FREQUENCY_HZ            16000.0  /* PWM and control rate, Hz */
#define PWM_DEADTIME_S              0.8e-6   /* dead time, s */
#define CONTROL_SLOW_DIVIDER        8        /* PWM periods per slow tick */
                                             /* (speed loop, state machine) */

/* -------------------------------------------------------- per-unit bases -- */
#define SPEED_BASE_RPM              8000.0   /* speed of Q15 1.0, rpm; above */
                                             /* every speed the motor reaches */

/* ------------------------------------------------------- current control -- */
#define CURRENT_LIMIT_A             2.1      /* phase current limit, A peak */
/* Current PI, in volts per ampere: Kp = Ls wc and Ki = Rs wc place the PI
 * zero on the winding pole (wc = 2 pi 1000 rad/s). */
#define CURRENT_KP_V_PER_A          3.77
#define CURRENT_KI_V_PER_AS         2199.0
#define VOLTAGE_LIMIT_FRACTION      0.95     /* |Vdq| limit as a fraction of */
                                             /* Vdc/sqrt(3) (linear SVM) */

/* --------------------------------------------------------- speed control -- */
/* Speed PI: Kp = J wb / Kt, Ki = Kp wb / 4, wb = 600 rad/s. */
#define SPEED_KP_A_PER_RPM          1.34e-2
#define SPEED_KI_A_PER_RPM_S        2.01
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
#define PLL_LOW_SPEED_RPM           600.0
/* Sensored start (host test aid, boards with a position sensor): closed
 * loop on the sensor until this speed, then on the estimator. */
#define SENSORED_HANDOVER_RPM       300.0

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
#define FW_ID_MAX_A                 1.5      /* largest -Id, A peak */
#define FW_VOLTAGE_MARGIN           0.95     /* |Vdq| target / limit */
#define FW_VOLTAGE_KP_A_PER_V       0.05     /* voltage PI, A of Id per V */
#define FW_VOLTAGE_KI_A_PER_VS      80.0
#define FW_START_RPM                3000.0   /* table mode */
#define FW_END_RPM                  6000.0

/* ---------------------------------------------------------- application -- */
#define CALIB_TIME_S                0.07     /* current-offset calibration */
#define STOP_SPEED_RPM              50.0     /* STOP ramps down to this, then */
                                             /* turns the outputs off */

#endif /* USERPARMS_H */
