/*
 * Compile-time derivation of the core's fixed-point constants from
 * userparms.h (physical units).
 *
 * Per-unit bases (Q15 1.0, 32768 counts):
 *   current  FOC_I_BASE_A   = BOARD_CURRENT_FULL_SCALE_A (ADC full scale)
 *   voltage  FOC_V_BASE_V   = BOARD_VDC_NOMINAL_V / sqrt(3) (largest phase
 *                             amplitude of linear SVM on the nominal bus)
 *   speed    SPEED_BASE_RPM (mechanical; the same per-unit value is the
 *                             electrical speed in units of p x base)
 *   bus      FOC_VDC_BASE_V = BOARD_VDC_FULL_SCALE_V (bus ADC full scale)
 *   angle    uint16_t, 65536 = 360 electrical degrees
 *
 * Gains above 1 are held as a Q15 mantissa and a shift (see pi.h):
 * FOC_GAIN_SHIFT(x) is the smallest shift with x / 2^shift < 1 and
 * FOC_GAIN_MANT(x) the mantissa.
 *
 * The file userparms.h is selected by the build: FOC_USERPARMS_FILE is a
 * string naming it.
 */
#ifndef FOC_CONFIG_H
#define FOC_CONFIG_H

#include "foc/q15.h"

#ifndef FOC_USERPARMS_FILE
#define FOC_USERPARMS_FILE "userparms.h"
#endif
#include FOC_USERPARMS_FILE

/* Static assertion that names what to change.  Floating-point constant
 * expressions are folded by GCC/XC16 (not ISO C; no -pedantic on the core).
 * In strict C99 mode glibc replaces the keyword by a bit-field trick that
 * loses the message; GCC has the keyword in C99 as well, so take it back. */
#ifdef _Static_assert
#undef _Static_assert
#endif
#if defined(__GNUC__) && (__GNUC__ * 100 + __GNUC_MINOR__) < 406
/* XC16 (GCC 4.5) predates the keyword, and clang (which reports GCC 4.2)
 * rejects floating-point expressions in it: a negative array size stops the
 * build; the message is then in the line the compiler points at. */
#define FOC_STATIC_ASSERT_CAT2(a, b) a##b
#define FOC_STATIC_ASSERT_CAT(a, b) FOC_STATIC_ASSERT_CAT2(a, b)
#if defined(__clang__)
/* clang folds the floating-point size as GCC does, but warns that it is an
 * extension (-Wgnu-folding-constant): the folding is the point here. */
#define FOC_STATIC_ASSERT(cond, msg)                                           \
    _Pragma("clang diagnostic push")                                           \
    _Pragma("clang diagnostic ignored \"-Wgnu-folding-constant\"")            \
    typedef char FOC_STATIC_ASSERT_CAT(foc_static_assert_line_, __LINE__)[(cond) ? 1 : -1] \
    _Pragma("clang diagnostic pop")
#else
#define FOC_STATIC_ASSERT(cond, msg)                                           \
    typedef char FOC_STATIC_ASSERT_CAT(foc_static_assert_line_, __LINE__)[(cond) ? 1 : -1]
#endif
#else
#define FOC_STATIC_ASSERT(cond, msg) _Static_assert(cond, msg)
#endif

/* ----------------------------------------------- userparms.h's inputs --
 * Each parameter on its own, before anything is derived from it, so that a
 * value out of its physical range stops the build with its own name (the
 * derived checks below then name what combination is impossible).  The
 * ranges are wide: they refuse what no motor or board has, not unusual
 * values.  A NaN fails every comparison and an infinity the upper bound;
 * an integer parameter must be a whole number. */
#define FOC_PARAM_RANGE(name, lo, hi)                                          \
    FOC_STATIC_ASSERT((name) >= (lo) && (name) <= (hi),                         \
                      #name " must be within [" #lo ", " #hi "] (finite)")
#define FOC_PARAM_POSITIVE(name, hi)                                           \
    FOC_STATIC_ASSERT((name) > 0 && (name) <= (hi), #name " must be > 0 and <= " #hi " (finite)")
#define FOC_PARAM_WHOLE(name, lo, hi)                                          \
    FOC_STATIC_ASSERT((name) >= (lo) && (name) <= (hi) && (name) == (long)(name), \
                      #name " must be a whole number within [" #lo ", " #hi "]")
FOC_PARAM_WHOLE(MOTOR_POLE_PAIRS, 1, 64);
FOC_PARAM_POSITIVE(MOTOR_RS_OHM, 1000.0);
FOC_PARAM_POSITIVE(MOTOR_LD_H, 10.0);
FOC_PARAM_POSITIVE(MOTOR_LQ_H, 10.0);
FOC_PARAM_POSITIVE(MOTOR_KE_VPK_PER_KRPM, 100000.0);
FOC_PARAM_POSITIVE(MOTOR_NOMINAL_SPEED_RPM, 200000.0);
FOC_PARAM_POSITIVE(MOTOR_MAX_SPEED_RPM, 200000.0);
FOC_PARAM_POSITIVE(MOTOR_RATED_CURRENT_A, 10000.0);
FOC_PARAM_POSITIVE(MOTOR_INERTIA_KGM2, 1000.0);
FOC_PARAM_RANGE(MOTOR_VISCOUS_NM_PER_KRPM, 0.0, 10000.0);
FOC_PARAM_RANGE(MOTOR_COULOMB_NM, 0.0, 10000.0);
FOC_PARAM_POSITIVE(BOARD_VDC_NOMINAL_V, 2000.0);
FOC_PARAM_POSITIVE(BOARD_VDC_FULL_SCALE_V, 4000.0);
FOC_PARAM_POSITIVE(BOARD_CURRENT_FULL_SCALE_A, 10000.0);
FOC_PARAM_WHOLE(BOARD_ADC_BITS, 8, 16);
FOC_PARAM_RANGE(PWM_FREQUENCY_HZ, 1000.0, 100000.0);
FOC_PARAM_RANGE(PWM_DEADTIME_S, 0.0, 20e-6);
FOC_PARAM_WHOLE(CONTROL_SLOW_DIVIDER, 1, 255);
FOC_PARAM_POSITIVE(SPEED_BASE_RPM, 200000.0);
FOC_PARAM_POSITIVE(CURRENT_LIMIT_A, 10000.0);
FOC_PARAM_POSITIVE(CURRENT_KP_V_PER_A, 1e6);
FOC_PARAM_POSITIVE(CURRENT_KI_V_PER_AS, 1e9);
FOC_PARAM_POSITIVE(VOLTAGE_LIMIT_FRACTION, 1.0);
FOC_PARAM_POSITIVE(SPEED_KP_A_PER_RPM, 1e6);
FOC_PARAM_POSITIVE(SPEED_KI_A_PER_RPM_S, 1e9);
FOC_PARAM_POSITIVE(SPEED_RAMP_RPM_PER_S, 1e7);
FOC_PARAM_POSITIVE(STARTUP_ALIGN_CURRENT_A, 10000.0);
FOC_PARAM_POSITIVE(STARTUP_ALIGN_TIME_S, 600.0);
FOC_PARAM_POSITIVE(STARTUP_RAMP_TIME_S, 600.0);
FOC_PARAM_POSITIVE(STARTUP_FINAL_SPEED_RPM, 200000.0);
FOC_PARAM_POSITIVE(STARTUP_MIN_SPEED_RPM, 200000.0);
FOC_PARAM_POSITIVE(STARTUP_TIMEOUT_S, 3600.0);
FOC_PARAM_WHOLE(STARTUP_CONV_TESTS, 1, 255);
FOC_PARAM_POSITIVE(STARTUP_SPEED_WINDOW_MIN, 1.0);
FOC_STATIC_ASSERT(STARTUP_SPEED_WINDOW_MAX > STARTUP_SPEED_WINDOW_MIN && STARTUP_SPEED_WINDOW_MAX <= 16.0,
                  "STARTUP_SPEED_WINDOW_MAX must be above STARTUP_SPEED_WINDOW_MIN and <= 16");
FOC_PARAM_POSITIVE(OVERVOLTAGE_V, 4000.0);
FOC_PARAM_POSITIVE(UNDERVOLTAGE_V, 4000.0);

#define FOC_PI_D 3.14159265358979323846
#define FOC_SQRT3_D 1.73205080756887729353

/* ------------------------------------------------------------ bases -- */
#define FOC_I_BASE_A (BOARD_CURRENT_FULL_SCALE_A)
#define FOC_V_BASE_V (BOARD_VDC_NOMINAL_V / FOC_SQRT3_D)
#define FOC_VDC_BASE_V (BOARD_VDC_FULL_SCALE_V)
#define FOC_TS_S (1.0 / PWM_FREQUENCY_HZ)
#define FOC_SLOW_TS_S (FOC_TS_S * CONTROL_SLOW_DIVIDER)
/* electrical rad/s at speed 1.0 */
#define FOC_WE_BASE_RAD_S (SPEED_BASE_RPM * MOTOR_POLE_PAIRS * 2.0 * FOC_PI_D / 60.0)
/* flux linkage from Ke (V peak line-to-line per 1000 rpm) */
#define FOC_FLUX_WB                                                            \
    (MOTOR_KE_VPK_PER_KRPM / FOC_SQRT3_D /                                     \
     (1000.0 * MOTOR_POLE_PAIRS * 2.0 * FOC_PI_D / 60.0))

/* Physical value -> Q15 of a base, with range checks done below. */
#define FOC_I_Q15(amps) Q15((amps) / FOC_I_BASE_A)
#define FOC_V_Q15(volts) Q15((volts) / FOC_V_BASE_V)
#define FOC_SPEED_Q15(rpm) Q15((rpm) / SPEED_BASE_RPM)
#define FOC_VDC_Q15(volts) Q15((volts) / FOC_VDC_BASE_V)

/* Gain mantissa/shift for 0 <= x < 32768. */
#define FOC_GAIN_SHIFT(x)                                                      \
    ((x) < 1.0 ? 0 : (x) < 2.0 ? 1 : (x) < 4.0 ? 2 : (x) < 8.0 ? 3           \
     : (x) < 16.0 ? 4 : (x) < 32.0 ? 5 : (x) < 64.0 ? 6 : (x) < 128.0 ? 7     \
     : (x) < 256.0 ? 8 : (x) < 512.0 ? 9 : (x) < 1024.0 ? 10                  \
     : (x) < 2048.0 ? 11 : (x) < 4096.0 ? 12 : (x) < 8192.0 ? 13             \
     : (x) < 16384.0 ? 14 : 15)
#define FOC_GAIN_MANT(x) Q15((x) / (double)(1L << FOC_GAIN_SHIFT(x)))

/* --------------------------------------------------- current control -- */
/* The current PI of userparms.h (Kp = Lq wc, Ki = Kp z: a first-order
 * loop of bandwidth wc when its zero z lies on the winding pole Rs / L)
 * rejects a voltage disturbance (a back-EMF that changes with a jam or a
 * load step, a bus step) only at the rate z (1 / z = 2.0 ms on the servo
 * of the torture campaign).  Two degrees of freedom move that pole to `a` =
 * max(z, CURRENT_DIST_RATIO wc) and the other to wc + z - a, keeping Kp
 * (the loop's robustness to an inductance off by half): the integral gain
 * a (Kp - Kref), Kref = Lq (a - z), and the reference's proportional gain
 * Kp - Kref, whose zero cancels the pole at a (the reference's response
 * stays first order, bandwidth wc + z - a): the integrator carries -Kref x
 * each step of the reference (current_ctrl.h).  With a = z the PI is the
 * plain one. */
#ifndef CURRENT_DIST_RATIO
#define CURRENT_DIST_RATIO 0.5
#endif
#define FOC_CURRENT_ZERO_RAD_S (CURRENT_KI_V_PER_AS / CURRENT_KP_V_PER_A)
#define FOC_CURRENT_DIST_RAD_S                                                 \
    ((CURRENT_DIST_RATIO * CURRENT_KP_V_PER_A / MOTOR_LQ_H > FOC_CURRENT_ZERO_RAD_S) \
         ? CURRENT_DIST_RATIO * CURRENT_KP_V_PER_A / MOTOR_LQ_H                \
         : FOC_CURRENT_ZERO_RAD_S)
#define FOC_CURRENT_KREF_V_PER_A (MOTOR_LQ_H * (FOC_CURRENT_DIST_RAD_S - FOC_CURRENT_ZERO_RAD_S))
/* PI gains in per-unit: volts per ampere x I_BASE / V_BASE; Ki per PWM
 * period. */
#define FOC_CURRENT_KP_PU (CURRENT_KP_V_PER_A * FOC_I_BASE_A / FOC_V_BASE_V)
#define FOC_CURRENT_KI_PU                                                      \
    (((FOC_CURRENT_KREF_V_PER_A > 0.0)                                         \
          ? FOC_CURRENT_DIST_RAD_S * (CURRENT_KP_V_PER_A - FOC_CURRENT_KREF_V_PER_A) \
          : CURRENT_KI_V_PER_AS) *                                             \
     FOC_TS_S * FOC_I_BASE_A / FOC_V_BASE_V)
#define FOC_CURRENT_KP_MANT FOC_GAIN_MANT(FOC_CURRENT_KP_PU)
#define FOC_CURRENT_KP_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_CURRENT_KP_PU))
#define FOC_CURRENT_KI Q15(FOC_CURRENT_KI_PU)
/* The reference's step gain Lq (a - z), per unit, and as the Q30 integrator
 * change per Q15 step of the reference. */
#define FOC_CURRENT_KREF_PU (FOC_CURRENT_KREF_V_PER_A * FOC_I_BASE_A / FOC_V_BASE_V)
#define FOC_CURRENT_KREF_Q30 ((int32_t)(FOC_CURRENT_KREF_PU * 32768.0 + 0.5))
/* The least Kp mantissa (at FOC_CURRENT_KP_SHIFT) the monitor takes: Kref,
 * rounded up, so that the reference's proportional gain Kp - Kref is never
 * negative. */
#define FOC_CURRENT_KP_MIN_MANT                                                \
    ((uint16_t)(FOC_CURRENT_KREF_PU / (double)(1L << FOC_CURRENT_KP_SHIFT) * 32768.0 + 0.999))
/* Back-calculation gain: Ki/Kp (the PI's own zero), the usual choice. */
#define FOC_CURRENT_KC Q15(FOC_CURRENT_KI_PU / FOC_CURRENT_KP_PU)
/* The current references stay CURRENT_REF_MARGIN below CURRENT_LIMIT_A:
 * the room the current loop's transients need (a load step, a jam, a
 * plant whose inductance is half the parameter's, an estimate losing its
 * angle) to keep the peak phase current within CURRENT_LIMIT_A + 5 %
 * (docs/safety.md: with 5 % of room, 74 of the 85 runs of the long
 * campaign that exceeded it peaked at 1.05-1.07 x the limit). */
#ifndef CURRENT_REF_MARGIN
#define CURRENT_REF_MARGIN 0.10
#endif
#define FOC_CURRENT_LIMIT FOC_I_Q15(CURRENT_LIMIT_A * (1.0 - CURRENT_REF_MARGIN))
/* Where the current loop has lost the current (an estimate gone wrong, a
 * plant far from the parameters), the fast step trips OVERCURRENT on the
 * sampled current vector's amplitude above CURRENT_LIMIT_A x (1 +
 * CURRENT_TRIP_MARGIN), before the peak reaches CURRENT_LIMIT_A + 5 %: the
 * regulated currents stay CURRENT_REF_MARGIN below the limit, so a run
 * under control never reaches it (docs/safety.md).  At the limit itself:
 * the sample is the ripple's middle, read through sensors up to 3 % off,
 * and 2 % above it let the true peak reach 1.05-1.08 x on the realistic
 * plant (seeds 109, 289, 957).  Compared squared, Q30 (no square root). */
#ifndef CURRENT_TRIP_MARGIN
#define CURRENT_TRIP_MARGIN 0.0
#endif
#define FOC_CURRENT_TRIP_PU (CURRENT_LIMIT_A * (1.0 + CURRENT_TRIP_MARGIN) / FOC_I_BASE_A)
#define FOC_CURRENT_TRIP_SQ_Q30                                                \
    ((uint32_t)(FOC_CURRENT_TRIP_PU * FOC_CURRENT_TRIP_PU * 1073741824.0))
/* The fast step's slew of the current references.  The estimators
 * subtract L di/dt from the measured voltage: with the plant's inductance
 * off by half (the envelope of docs/safety.md), a current changing at
 * E / Lq (E the phase back-EMF at STARTUP_MIN_SPEED_RPM, the lowest
 * estimated speed the loop runs at) fakes half that EMF, and faster, the
 * estimate swings with every torque step and the speed loop chases it
 * (docs/safety.md, "The current references' slew").  The slew is that
 * rate, but a reversal (-limit to +limit) within 6 slow ticks at the
 * slowest (slower, the speed loop loses phase: the Luenberger estimator
 * stops running at 500 rpm with ADC noise) and within one at the fastest;
 * Q15 per PWM period, rounded down to 2^(bits-1) - 1 for one SSAT. */
#define FOC_IREF_REVERSAL_PU (2.0 * CURRENT_LIMIT_A * (1.0 - CURRENT_REF_MARGIN) / FOC_I_BASE_A * 32768.0)
#define FOC_IREF_STEP_EMF_PU                                                   \
    (MOTOR_KE_VPK_PER_KRPM / FOC_SQRT3_D * STARTUP_MIN_SPEED_RPM / 1000.0 / MOTOR_LQ_H * FOC_TS_S / \
     FOC_I_BASE_A * 32768.0)
/* SSAT widths: the EMF rate rounded down, the bounds rounded up */
#define FOC_IREF_BITS_EMF ((FOC_IREF_STEP_EMF_PU < 2.0) ? 2 : FOC_GAIN_SHIFT(FOC_IREF_STEP_EMF_PU))
#define FOC_IREF_BITS_SLOWEST (1 + FOC_GAIN_SHIFT(FOC_IREF_REVERSAL_PU / (6.0 * CONTROL_SLOW_DIVIDER)))
#define FOC_IREF_BITS_FASTEST (1 + FOC_GAIN_SHIFT(FOC_IREF_REVERSAL_PU / CONTROL_SLOW_DIVIDER))
#define FOC_IREF_STEP_BITS                                                     \
    ((FOC_IREF_BITS_EMF < FOC_IREF_BITS_SLOWEST)   ? FOC_IREF_BITS_SLOWEST                         \
     : (FOC_IREF_BITS_EMF > FOC_IREF_BITS_FASTEST) ? FOC_IREF_BITS_FASTEST                         \
                                                   : FOC_IREF_BITS_EMF)
#define FOC_VOLTAGE_LIMIT Q15(VOLTAGE_LIMIT_FRACTION)

/* ----------------------------------------------------- speed control -- */
#define FOC_SPEED_KP_PU (SPEED_KP_A_PER_RPM * SPEED_BASE_RPM / FOC_I_BASE_A)
#define FOC_SPEED_KI_PU                                                        \
    (SPEED_KI_A_PER_RPM_S * FOC_SLOW_TS_S * SPEED_BASE_RPM / FOC_I_BASE_A)
#define FOC_SPEED_KP_MANT FOC_GAIN_MANT(FOC_SPEED_KP_PU)
#define FOC_SPEED_KP_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_SPEED_KP_PU))
#define FOC_SPEED_KI_MANT FOC_GAIN_MANT(FOC_SPEED_KI_PU)
#define FOC_SPEED_KI_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_SPEED_KI_PU))
#define FOC_SPEED_KC Q15(FOC_SPEED_KI_PU / FOC_SPEED_KP_PU)
/* The speed loop hunting (speed_ctrl.c): its q current from beyond half
 * the limit one way to beyond half the other way is a swing.  Swings are
 * counted leakily, FOC_SPEED_HUNT_SWING_TICKS up each, 1 down each slow
 * tick; at FOC_SPEED_HUNT_TRIP_TICKS the loop's gains are halved, at most
 * FOC_SPEED_HUNT_SHIFT_MAX times in a run.  Swings more often than one per
 * 20 ms are needed to get there: at one per 4.4 ms (seed 1275) the fourth
 * does it, and fewer than four never do. */
#define FOC_SPEED_HUNT_SWING_TICKS FOC_TICKS(0.02)
#define FOC_SPEED_HUNT_TRIP_TICKS (3u * FOC_SPEED_HUNT_SWING_TICKS)
#define FOC_SPEED_HUNT_SHIFT_MAX 2u
/* Reference slew per slow tick in Q15.15 (speed x 32768), so slow ramps
 * keep their rate exactly. */
#define FOC_SPEED_RAMP_STEP_PU (SPEED_RAMP_RPM_PER_S * FOC_SLOW_TS_S / SPEED_BASE_RPM)
#define FOC_SPEED_RAMP_STEP15 ((int32_t)(FOC_SPEED_RAMP_STEP_PU * 32768.0 * 32768.0 + 0.5))
#define FOC_STOP_SPEED FOC_SPEED_Q15(STOP_SPEED_RPM)
/* Filter constant K = 1 - exp(-Ts/tau) ~ Ts/(tau + Ts) per PWM period. */
#define FOC_SPEED_FILTER_K Q15(FOC_TS_S / (SPEED_FILTER_TIME_S + FOC_TS_S))

/* ------------------------------------------------------------ angle -- */
/* Angle counts per PWM period at speed 1.0, and its inverse as a gain:
 * speed (Q15) = d_theta (counts per period) x FOC_DTHETA_TO_SPEED. */
#define FOC_DTHETA_AT_BASE (65536.0 * FOC_WE_BASE_RAD_S / (2.0 * FOC_PI_D) * FOC_TS_S)
#define FOC_DTHETA_TO_SPEED_PU (32768.0 / FOC_DTHETA_AT_BASE)
#define FOC_DTHETA_TO_SPEED_MANT FOC_GAIN_MANT(FOC_DTHETA_TO_SPEED_PU)
#define FOC_DTHETA_TO_SPEED_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_DTHETA_TO_SPEED_PU))

/* Angle accumulator (uint32_t, 2^32 = 360 deg): increment per PWM period
 * per Q15 speed count, rounded by up to 0.5 / it: the Shinano build's 2185
 * for 2184.53 runs its speeds 0.021 % fast (docs/estimators.md). */
#define FOC_THETA32_PER_SPEED ((int32_t)(2.0 * FOC_DTHETA_AT_BASE + 0.5))
/* Angle turned in half a PWM period at speed 1.0, as a Q15 gain (< 0.25). */
#define FOC_HALF_PERIOD_ANGLE Q15(0.5 * FOC_DTHETA_AT_BASE / 32768.0)

/* ------------------------------------------------- machine constants -- */
/* Per-unit winding resistance, inductance per PWM period and back-EMF per
 * unit speed (the normalisation of AN1292 equations 5 and 6 in our bases). */
#define FOC_RS_PU (MOTOR_RS_OHM * FOC_I_BASE_A / FOC_V_BASE_V)
/* Rs in the PLL's and the flux estimator's EMF, a run-time mantissa over
 * FOC_RS2_SHIFT with room for twice MOTOR_RS_OHM (FOC_RS2_MANT): the
 * alignment measures it (controller.c, identify_rs) as a ratio to
 * MOTOR_RS_OHM, Q14, within [0.5, 2). */
#define FOC_RS2_SHIFT ((uint8_t)FOC_GAIN_SHIFT(2.0 * FOC_RS_PU))
#define FOC_RS2_MANT FOC_GAIN_MANT(2.0 * FOC_RS_PU)
#define FOC_RS_MANT FOC_GAIN_MANT(FOC_RS_PU)
#define FOC_RS_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_RS_PU))
/* The alignment's measures (Rs, and Ls: identify_ls) as ratios to their
 * parameters, Q14, within [0.5, 2). */
#define FOC_RATIO_ONE_Q14 ((q15_t)16384)
#define FOC_RATIO_MIN_Q14 ((q15_t)8192)
/* ALIGN's vd and id filtered for the Rs measure over the alignment's last
 * quarter (from the tick FOC_ALIGN_AVG_FROM; the rotor turned to the start
 * angle at the second half's beginning), a time constant of a third of
 * it. */
#define FOC_ALIGN_AVG_FROM ((uint16_t)(FOC_ALIGN_HALF_TICKS + FOC_ALIGN_HALF_TICKS / 2u))
#define FOC_ALIGN_AVG_K Q15(FOC_SLOW_TS_S / (STARTUP_ALIGN_TIME_S / 12.0 + FOC_SLOW_TS_S))
#define FOC_LS_DT_PU (MOTOR_LQ_H * FOC_I_BASE_A / (FOC_V_BASE_V * FOC_TS_S))
#define FOC_KFI_PU (FOC_FLUX_WB * FOC_WE_BASE_RAD_S / FOC_V_BASE_V)
#define FOC_INV_KFI_PU (1.0 / FOC_KFI_PU)
/* Largest current change in one period the winding allows (full voltage
 * across Ls), Q15 of the current base: the di/dt limit of the estimator. */
#define FOC_DI_MAX Q15(FOC_V_BASE_V * FOC_TS_S / MOTOR_LQ_H / FOC_I_BASE_A)

/* -------------------------------------------------- PLL estimator -- */
/* Ls/dt with room for the field-weakening scale up to 2x nominal. */
#define FOC_PLL_LSDT_SHIFT ((uint8_t)FOC_GAIN_SHIFT(2.0 * FOC_LS_DT_PU))
#define FOC_PLL_LSDT_MANT Q15(FOC_LS_DT_PU / (double)(1L << FOC_PLL_LSDT_SHIFT))
/* The back-EMF exceeds the voltage base above base speed (that is why
 * field weakening is needed), so the estimator holds it at half scale:
 * EMF Q15 of 2 x the voltage base, range +-2 pu.  KFi and 1/KFi below are
 * per unit of that half-scale EMF. */
#define FOC_PLL_KFI_PU (FOC_KFI_PU / 2.0)
#define FOC_PLL_INV_KFI_PU (2.0 * FOC_INV_KFI_PU)
/* 1/KFi with room for the field-weakening table up to 4x nominal. */
#define FOC_PLL_INVKFI_SHIFT ((uint8_t)FOC_GAIN_SHIFT(4.0 * FOC_PLL_INV_KFI_PU))
#define FOC_PLL_INVKFI Q15(FOC_PLL_INV_KFI_PU / (double)(1L << FOC_PLL_INVKFI_SHIFT))
#define FOC_PLL_KFI_MANT FOC_GAIN_MANT(FOC_PLL_KFI_PU)
#define FOC_PLL_KFI_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_PLL_KFI_PU))
#define FOC_PLL_EMF_FILTER_K Q15(FOC_TS_S / (PLL_EMF_FILTER_TIME_S + FOC_TS_S))
#define FOC_PLL_SPEED_FILTER_K Q15(FOC_TS_S / (PLL_SPEED_FILTER_TIME_S + FOC_TS_S))
#define FOC_PLL_LOW_SPEED FOC_SPEED_Q15(PLL_LOW_SPEED_RPM)
/* Flux tracking: the integrator on -sgn(w) Ed that takes the magnet flux's
 * deviation from MOTOR_KE off the angle (pll_est.h).  Its rate, per second,
 * is a quarter of the electrical speed at STARTUP_MIN_SPEED_RPM, so the
 * loop it closes with eq. 2 stays damped (zeta >= 0.7 down to that speed
 * with a flux 0.5x nominal); per slow tick, Q14. */
#define FOC_PLL_TRACK_GAIN_Q14                                                 \
    ((int32_t)(16384.0 * STARTUP_MIN_SPEED_RPM * MOTOR_POLE_PAIRS * 2.0 * FOC_PI_D / 60.0 / \
               4.0 * FOC_SLOW_TS_S + 0.5))
#define FOC_SENSORED_HANDOVER_SPEED FOC_SPEED_Q15(SENSORED_HANDOVER_RPM)

/* --------------------------------------------- Luenberger observer -- */
/* ST's constants ([ST-FOC]) in our bases: ST holds the current in units of
 * Imax (ours: FOC_I_BASE_A), the voltage in Vmax (ours: FOC_V_BASE_V) and
 * the EMF in Emax (ours: the back-EMF at SPEED_BASE_RPM, so an EMF's Q15
 * amplitude equals the speed's Q15 value).  States: current Q15 x F1, EMF
 * Q15 x F2, so C x (Q15 value) is a state increment with no shift:
 *   C1 = F1 (1 - exp(-Rs T/Ls))              ST: F1 Rs/(Ls fs)
 *   C2 = F1 K1 T                             ST: F1 K1/fs
 *   C3 = F1 B Emax/Imax, C5 = F1 B Vmax/Imax ST: B = 1/(Ls fs)
 *   C4 = F2 K2 T Imax/Emax                   ST: the same
 * with B = (1 - exp(-Rs T/Ls))/Rs, the exact (zero-order-hold) winding
 * response, instead of ST's Euler T/Ls.  The EMF rotation w T per period:
 *   h = speed x C6 / 2^15 (rad, Q16), C6 = 2^16 w_base T
 * then h x e >> (16 - log2 F2), the same product as ST's
 * C6 = F2 F3 2 pi/65536 (speed in 1/65536 turn per period) with
 * F3 = 2^(31 - log2 F2) split into two 16-bit multiplications.  Ls is
 * Lq: the extended-EMF model, exact for a salient rotor (luenberger.h). */
#define FOC_LUEN_LS_H (MOTOR_LQ_H)
#define FOC_LUEN_E_BASE_V (FOC_KFI_PU * FOC_V_BASE_V)
#define FOC_LUEN_X (MOTOR_RS_OHM * FOC_TS_S / FOC_LUEN_LS_H) /* Rs T/Ls */
/* (1 - exp(-x))/x by its series; error below x^5/720 (x < 0.5) */
#define FOC_LUEN_ZOH                                                           \
    (1.0 - FOC_LUEN_X / 2.0 + FOC_LUEN_X * FOC_LUEN_X / 6.0 -                  \
     FOC_LUEN_X * FOC_LUEN_X * FOC_LUEN_X / 24.0 +                             \
     FOC_LUEN_X * FOC_LUEN_X * FOC_LUEN_X * FOC_LUEN_X / 120.0)
#define FOC_LUEN_G (FOC_LUEN_X * FOC_LUEN_ZOH)                   /* 1 - exp(-x) */
#define FOC_LUEN_B_A_PER_V (FOC_TS_S / FOC_LUEN_LS_H * FOC_LUEN_ZOH) /* B */
#define FOC_LUEN_C1_D (LUENBERGER_F1 * FOC_LUEN_G)
#define FOC_LUEN_C2_D (LUENBERGER_F1 * LUENBERGER_K1_PER_S * FOC_TS_S)
#define FOC_LUEN_C3_D (LUENBERGER_F1 * FOC_LUEN_B_A_PER_V * FOC_LUEN_E_BASE_V / FOC_I_BASE_A)
#define FOC_LUEN_C4_D                                                          \
    (LUENBERGER_F2 * LUENBERGER_K2_V_PER_AS * FOC_TS_S * FOC_I_BASE_A / FOC_LUEN_E_BASE_V)
#define FOC_LUEN_C5_D (LUENBERGER_F1 * FOC_LUEN_B_A_PER_V * FOC_V_BASE_V / FOC_I_BASE_A)
#define FOC_LUEN_C6_D (65536.0 * FOC_WE_BASE_RAD_S * FOC_TS_S)
#define FOC_LUEN_ROUND(x) ((q15_t)((x) >= 0.0 ? (x) + 0.5 : (x) - 0.5))
#define FOC_LUEN_C1 FOC_LUEN_ROUND(FOC_LUEN_C1_D)
#define FOC_LUEN_C2 FOC_LUEN_ROUND(FOC_LUEN_C2_D)
#define FOC_LUEN_C3 FOC_LUEN_ROUND(FOC_LUEN_C3_D)
#define FOC_LUEN_C4 FOC_LUEN_ROUND(FOC_LUEN_C4_D)
#define FOC_LUEN_C5 FOC_LUEN_ROUND(FOC_LUEN_C5_D)
#define FOC_LUEN_C6 FOC_LUEN_ROUND(FOC_LUEN_C6_D)
#define FOC_LUEN_F1_LOG2 ((uint8_t)(FOC_GAIN_SHIFT((double)LUENBERGER_F1) - 1))
#define FOC_LUEN_F2_LOG2 ((uint8_t)(FOC_GAIN_SHIFT((double)LUENBERGER_F2) - 1))
/* The alignment's Ls ratio r (controller.c identify_ls) moves the model to
 * the measured winding (luenberger.c foc_luen_set_winding): C3, C5 (T/Ls)
 * over r, C1 (Rs T/Ls) and C2's share F1 Rs T/Ls (FOC_LUEN_C2X) times the
 * measured Rs's ratio over r (below), C4 (K2 =
 * Ls wo^2 from tune.py) times r, so that the observer keeps the poles it
 * was designed with.  r is held where every constant and sum keeps its
 * format: 1/r at most FOC_LUEN_INV_R_MAX_D (C1, C3, C5 below 32767, the
 * current update's sum below 2^16, C2 at most -16), r at most
 * FOC_LUEN_R_MAX_D (C4 below 32767, the EMF update's sum below 2^16). */
#define FOC_LUEN_MIN_D(a, b) ((a) < (b) ? (a) : (b))
#define FOC_LUEN_C2X_D (LUENBERGER_F1 * FOC_LUEN_X)
#define FOC_LUEN_C2X FOC_LUEN_ROUND(FOC_LUEN_C2X_D)
#define FOC_LUEN_INV_R_MAX_D                                                   \
    FOC_LUEN_MIN_D(FOC_LUEN_MIN_D(2.0, 32767.0 / FOC_LUEN_C1_D),               \
                   FOC_LUEN_MIN_D(FOC_LUEN_MIN_D(32767.0 / FOC_LUEN_C3_D, 32767.0 / FOC_LUEN_C5_D), \
                                  FOC_LUEN_MIN_D((65535.0 - LUENBERGER_F1 + FOC_LUEN_C2_D - FOC_LUEN_C2X_D) / \
                                                     (FOC_LUEN_C1_D + FOC_LUEN_C3_D + FOC_LUEN_C5_D - FOC_LUEN_C2X_D), \
                                                 1.0 + (-16.0 - FOC_LUEN_C2_D) / FOC_LUEN_C2X_D)))
#define FOC_LUEN_R_MAX_D                                                       \
    FOC_LUEN_MIN_D(FOC_LUEN_MIN_D(2.0, 32767.0 / FOC_LUEN_C4_D),               \
                   (65535.0 - 1.5 * LUENBERGER_F2) / FOC_LUEN_C4_D)
#define FOC_LUEN_RATIO_MIN ((q15_t)(16384.0 / FOC_LUEN_INV_R_MAX_D + 1.0))
#define FOC_LUEN_RATIO_MAX ((q15_t)(FOC_LUEN_R_MAX_D >= 2.0 ? 32767.0 : 16384.0 * FOC_LUEN_R_MAX_D))
/* The alignment's Rs ratio moves C1 and C2's share with Rs T/Ls: their
 * ratio x = rs / r (Q14 in an int32_t) is held within [1/4,
 * FOC_LUEN_X_MAX_D] (Rs at half and Ls at twice the parameters' down to
 * 1/4; up to 4, Rs at twice and Ls at half the parameters' (the largest
 * the two ratios' formats give), where C1 stays below 32767 and C2 at most
 * -16).  The ceiling was 1/r's, 2: a winding measured at Rs +60 % and
 * Ls -49 % (x = 3.1, torture fan_highj seed 791) kept 0.68 ohm out of the
 * model, whose drop looked like a back-EMF turning with the forced
 * current; a held rotor then passed the start-up's convergence test. */
#define FOC_LUEN_X_RATIO_MIN_D 0.25
#define FOC_LUEN_X_RATIO_MIN ((q15_t)(16384.0 * FOC_LUEN_X_RATIO_MIN_D))
#define FOC_LUEN_X_MAX_D                                                       \
    FOC_LUEN_MIN_D(4.0, FOC_LUEN_MIN_D(32767.0 / FOC_LUEN_C1_D,                \
                                       1.0 + (-16.0 - FOC_LUEN_C2_D) / FOC_LUEN_C2X_D))
#define FOC_LUEN_X_RATIO_MAX ((int32_t)(16384.0 * FOC_LUEN_X_MAX_D))
/* The current update's sum of |constants| (below 2^16) with C1 and C2
 * at the ratio x and C3, C5 at the largest 1/r. */
#define FOC_LUEN_SUM_AT_X_D(x)                                                 \
    (LUENBERGER_F1 + FOC_LUEN_C1_D * (x) - FOC_LUEN_C2_D + FOC_LUEN_C2X_D * (1.0 - (x)) + \
     (FOC_LUEN_C3_D + FOC_LUEN_C5_D) * FOC_LUEN_INV_R_MAX_D)
/* Observer error dynamics per axis (rotation aside): x = (current error
 * after correction, EMF error), x(k+1) = M x(k) with
 * det M = (1 + K1 T)(1 - G) and trace M = det M + 1 - K2 T B. */
#define FOC_LUEN_DET ((1.0 + LUENBERGER_K1_PER_S * FOC_TS_S) * (1.0 - FOC_LUEN_G))
#define FOC_LUEN_K2TB (LUENBERGER_K2_V_PER_AS * FOC_TS_S * FOC_LUEN_B_A_PER_V)
/* PLL: ST's gains act on the EMF in Q15 of the EMF at maximum speed, which
 * is sin(angle error) at maximum speed, and give the speed in 1/65536 turn
 * per period, Kp over 2^14, Ki over 2^16.  Ours act on sin(angle error)
 * (the EMF normalised by its amplitude) at every speed and give the speed
 * in Q15 of SPEED_BASE_RPM: ST's loop at maximum speed, at all speeds
 * (plus the EMF feed-forward, see luenberger.h). */
#define FOC_LUEN_PLL_UNIT (32768.0 / FOC_DTHETA_AT_BASE)
#define FOC_LUEN_PLL_KP_PU (LUENBERGER_PLL_KP / 16384.0 * FOC_LUEN_PLL_UNIT)
#define FOC_LUEN_PLL_KI_PU (LUENBERGER_PLL_KI / 65536.0 * FOC_LUEN_PLL_UNIT)
#define FOC_LUEN_PLL_KP_MANT FOC_GAIN_MANT(FOC_LUEN_PLL_KP_PU)
#define FOC_LUEN_PLL_KP_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_LUEN_PLL_KP_PU))
#define FOC_LUEN_PLL_KI Q15(FOC_LUEN_PLL_KI_PU)
/* ST's Kp and Ki are designed at maximum speed.  Below it the phase
 * detector is divided by the EMF at LUENBERGER_PLL_FULL_SPEED_RPM instead of
 * its own amplitude, and Ki acts on it times the filtered speed over that
 * EMF: Kp falls in proportion to the speed, Ki to its square, so the PLL's
 * natural frequency follows the electrical frequency at constant damping
 * (luenberger.h).
 * Q15 EMF amplitude (= speed at nominal flux), within AMP_MIN (1/64) and
 * 32767. */
#ifndef LUENBERGER_PLL_FULL_SPEED_RPM
#define LUENBERGER_PLL_FULL_SPEED_RPM MOTOR_MAX_SPEED_RPM
#endif
#define FOC_LUEN_PLL_FULL_AMP ((int32_t)FOC_SPEED_Q15(LUENBERGER_PLL_FULL_SPEED_RPM))
/* 1 / that EMF as a gain (1..64: mantissa, shift) on the filtered speed:
 * the integrator's g_w = min(1, |speed| / e_max), Q15 (luenberger.c). */
#define FOC_LUEN_PLL_INV_FULL_PU (32768.0 / (double)FOC_LUEN_PLL_FULL_AMP)
#define FOC_LUEN_PLL_INV_FULL_MANT FOC_GAIN_MANT(FOC_LUEN_PLL_INV_FULL_PU)
#define FOC_LUEN_PLL_INV_FULL_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_LUEN_PLL_INV_FULL_PU))
#define FOC_LUEN_SPEED_FILTER_K Q15(FOC_TS_S / (LUENBERGER_SPEED_FILTER_TIME_S + FOC_TS_S))

FOC_STATIC_ASSERT(LUENBERGER_F1 >= 16 && LUENBERGER_F1 <= 16384 &&
                  (LUENBERGER_F1 & (LUENBERGER_F1 - 1)) == 0,
                  "LUENBERGER_F1 must be a power of two, 16..16384");
FOC_STATIC_ASSERT(LUENBERGER_F2 >= 16 && LUENBERGER_F2 <= 16384 &&
                  (LUENBERGER_F2 & (LUENBERGER_F2 - 1)) == 0,
                  "LUENBERGER_F2 must be a power of two, 16..16384");
FOC_STATIC_ASSERT(FOC_LUEN_X < 0.5,
                  "MOTOR_RS_OHM / MOTOR_LD_H, MOTOR_LQ_H: winding time constant below "
                  "2 PWM periods, too short for the Luenberger observer");
FOC_STATIC_ASSERT(FOC_LUEN_C1_D >= 1.0 && FOC_LUEN_C1_D < 32767.0 &&
                  FOC_LUEN_C5_D >= 16.0 && FOC_LUEN_C5_D < 32767.0,
                  "LUENBERGER_F1 out of range for MOTOR_RS_OHM, MOTOR_LQ_H at "
                  "PWM_FREQUENCY_HZ (observer constants C1, C5)");
FOC_STATIC_ASSERT(FOC_LUEN_C3_D >= 16.0 && FOC_LUEN_C3_D < 32767.0,
                  "LUENBERGER_F1 out of range for MOTOR_KE_VPK_PER_KRPM x SPEED_BASE_RPM "
                  "(observer constant C3)");
FOC_STATIC_ASSERT(FOC_LUEN_C2_D <= -16.0 && FOC_LUEN_C2_D > -32767.0,
                  "LUENBERGER_K1_PER_S must be negative and LUENBERGER_K1_PER_S x "
                  "LUENBERGER_F1 / PWM_FREQUENCY_HZ within -32767..-16");
FOC_STATIC_ASSERT(FOC_LUEN_C4_D >= 16.0 && FOC_LUEN_C4_D < 32767.0,
                  "LUENBERGER_K2_V_PER_AS must be positive and LUENBERGER_K2_V_PER_AS x "
                  "LUENBERGER_F2 (observer constant C4) within 16..32767");
/* Current update: |state| <= 2^15 F1 plus four products |C| 2^15. */
FOC_STATIC_ASSERT(FOC_LUEN_C1_D - FOC_LUEN_C2_D + FOC_LUEN_C3_D + FOC_LUEN_C5_D +
                  LUENBERGER_F1 < 65535.0,
                  "LUENBERGER_F1 too large: the observer current update could "
                  "overflow 32 bits");
/* EMF update: |state| <= 2^15 F2, C4 2^15, rotation <= 2^15 F2/2. */
FOC_STATIC_ASSERT(1.5 * LUENBERGER_F2 + FOC_LUEN_C4_D < 65535.0,
                  "LUENBERGER_F2 or LUENBERGER_K2_V_PER_AS too large: the observer "
                  "EMF update could overflow 32 bits");
FOC_STATIC_ASSERT(FOC_LUEN_INV_R_MAX_D >= 1.0 && FOC_LUEN_R_MAX_D >= 1.0,
                  "the Luenberger observer's constants leave no room for the measured Ls");
FOC_STATIC_ASSERT(FOC_LUEN_SUM_AT_X_D(FOC_LUEN_X_RATIO_MIN_D) < 65535.0 &&
                  FOC_LUEN_SUM_AT_X_D(FOC_LUEN_X_MAX_D) < 65535.0 &&
                  FOC_LUEN_C2_D - FOC_LUEN_C2X_D * (1.0 - FOC_LUEN_X_RATIO_MIN_D) > -32767.0,
                  "the Luenberger observer's constants leave no room for the measured Rs");
FOC_STATIC_ASSERT(FOC_LUEN_C6_D < 32767.0,
                  "SPEED_BASE_RPM x MOTOR_POLE_PAIRS too high for PWM_FREQUENCY_HZ "
                  "(Luenberger observer: over 0.5 rad per period at base speed)");
FOC_STATIC_ASSERT(FOC_LUEN_DET > -1.0 && FOC_LUEN_DET < 1.0 && FOC_LUEN_K2TB > 0.0 &&
                  FOC_LUEN_K2TB < 2.0 * (1.0 + FOC_LUEN_DET),
                  "LUENBERGER_K1_PER_S, LUENBERGER_K2_V_PER_AS: the observer error "
                  "dynamics are unstable at PWM_FREQUENCY_HZ (Jury test)");
FOC_STATIC_ASSERT(FOC_LUEN_PLL_KP_PU > 0.0 && FOC_LUEN_PLL_KP_PU < 32768.0,
                  "LUENBERGER_PLL_KP out of range");
FOC_STATIC_ASSERT(FOC_LUEN_PLL_KI_PU > 1.0 / 32768.0 && FOC_LUEN_PLL_KI_PU < 1.0,
                  "LUENBERGER_PLL_KI out of range (Ki per period must be < 1 pu)");
FOC_STATIC_ASSERT(LUENBERGER_SPEED_FILTER_TIME_S >= 0.0,
                  "LUENBERGER_SPEED_FILTER_TIME_S must be >= 0");
FOC_STATIC_ASSERT(FOC_LUEN_PLL_FULL_AMP >= 512,
                  "LUENBERGER_PLL_FULL_SPEED_RPM must be at least 1/64 of SPEED_BASE_RPM");

/* ------------------------------------------------- flux estimator -- */
/* Constants of 15 significant bits for foc_mul_norm32(): x = mant / 2^rshift
 * with a Q15 mantissa in [0.5, 1), for 2^-15 <= x < 2^14. */
#define FOC_NORM_RSHIFT(x)                                                     \
    ((uint8_t)((x) >= 1.0 ? 15 - FOC_GAIN_SHIFT(x)                              \
                          : 30 - FOC_GAIN_SHIFT((x) * 32768.0)))
#define FOC_NORM_MANT(x) Q15((x) * (double)(1L << FOC_NORM_RSHIFT(x)) / 32768.0)
#define FOC_NORM_OK(x) ((x) >= 1.0 / 32768.0 && (x) < 16384.0)
/* Flux per unit: 1.0 is the flux whose back-EMF at speed 1.0 is
 * 2^FOC_FLUX_SHIFT voltage bases, FOC_FLUX_BASE_WB = 2^FOC_FLUX_SHIFT x
 * V_BASE / w_e_base.  The shift is the smallest that keeps the magnet flux
 * plus Lq x the current base (the largest stator flux the ADC can show)
 * within 0.5: 2x headroom for parameter error and transients. */
#define FOC_FLUX_BASE0_WB (FOC_V_BASE_V / FOC_WE_BASE_RAD_S)
#define FOC_FLUX_PEAK_PU0 ((FOC_FLUX_WB + MOTOR_LQ_H * FOC_I_BASE_A) / FOC_FLUX_BASE0_WB)
#define FOC_FLUX_SHIFT FOC_GAIN_SHIFT(2.0 * FOC_FLUX_PEAK_PU0)
#define FOC_FLUX_BASE_WB (FOC_FLUX_BASE0_WB * (double)(1L << FOC_FLUX_SHIFT))
#define FOC_FLUX_PSI_M Q15(FOC_FLUX_WB / FOC_FLUX_BASE_WB)
#define FOC_FLUX_LS_PU (MOTOR_LQ_H * FOC_I_BASE_A / FOC_FLUX_BASE_WB)
#define FOC_FLUX_LS Q15(FOC_FLUX_LS_PU)
/* Integrator: Q31 flux per PWM period per count of (v - Rs i) / 2 (Q15):
 * w_e_base Ts 2^(17 - FOC_FLUX_SHIFT). */
#define FOC_FLUX_KINT_X (FOC_WE_BASE_RAD_S * FOC_TS_S * 131072.0 / (double)(1L << FOC_FLUX_SHIFT))
#define FOC_FLUX_KINT_MANT FOC_NORM_MANT(FOC_FLUX_KINT_X)
#define FOC_FLUX_KINT_RSHIFT FOC_NORM_RSHIFT(FOC_FLUX_KINT_X)
/* Correction gain per period: (k_min + c |w_e|) Ts = MIN + SPEED x |speed|
 * (limited to 0.5 at run time). */
#define FOC_FLUX_CORR_MIN_PU (FLUX_CORR_MIN_RAD_S * FOC_TS_S)
#define FOC_FLUX_CORR_SPEED_PU (FLUX_CORR_PER_SPEED * FOC_WE_BASE_RAD_S * FOC_TS_S)
#define FOC_FLUX_CORR_MIN Q15(FOC_FLUX_CORR_MIN_PU)
#define FOC_FLUX_CORR_SPEED Q15(FOC_FLUX_CORR_SPEED_PU)
/* Low-pass gain per period of the learned magnet flux: FLUX_MAG_PER_SPEED
 * |w_e| Ts = FOC_FLUX_MAG_SPEED x |speed|. */
#define FOC_FLUX_MAG_SPEED_PU (FLUX_MAG_PER_SPEED * FOC_WE_BASE_RAD_S * FOC_TS_S)
#define FOC_FLUX_MAG_SPEED Q15(FOC_FLUX_MAG_SPEED_PU)
/* Speed observer (speed_obs.h): three poles at -wo; l1 = 3 wo Ts per
 * period (Q15), l2 = 3 wo^2 Ts as Q31 speed per count of angle error,
 * l3 = wo^3 Ts / a_pu as Q27 current per count, the feed-forward a_pu Ts
 * as Q31 speed per Q15 count of current, with a_pu = p 1.5 p flux I_BASE / J
 * the electrical acceleration (rad/s^2) of 1.0 of q current. */
#define FOC_SOBS_WO (FLUX_SPEED_OBS_BW_RAD_S)
#define FOC_SOBS_RAD_PER_COUNT (2.0 * FOC_PI_D / 65536.0)
#define FOC_SOBS_Q31_PER_RAD_S (2147483648.0 / FOC_WE_BASE_RAD_S)
#define FOC_SOBS_ACCEL_PU                                                      \
    (1.5 * MOTOR_POLE_PAIRS * MOTOR_POLE_PAIRS * FOC_FLUX_WB * FOC_I_BASE_A / MOTOR_INERTIA_KGM2)
#define FOC_SOBS_L1_PU (3.0 * FOC_SOBS_WO * FOC_TS_S)
#define FOC_SOBS_L1 Q15(FOC_SOBS_L1_PU)
#define FOC_SOBS_L2_X                                                          \
    (3.0 * FOC_SOBS_WO * FOC_SOBS_WO * FOC_TS_S * FOC_SOBS_RAD_PER_COUNT * FOC_SOBS_Q31_PER_RAD_S)
#define FOC_SOBS_L2_MANT FOC_NORM_MANT(FOC_SOBS_L2_X)
#define FOC_SOBS_L2_RSHIFT FOC_NORM_RSHIFT(FOC_SOBS_L2_X)
#define FOC_SOBS_L3_X                                                          \
    (FOC_SOBS_WO * FOC_SOBS_WO * FOC_SOBS_WO * FOC_TS_S * FOC_SOBS_RAD_PER_COUNT /  \
     FOC_SOBS_ACCEL_PU * 134217728.0)
#define FOC_SOBS_L3_MANT FOC_NORM_MANT(FOC_SOBS_L3_X)
#define FOC_SOBS_L3_RSHIFT FOC_NORM_RSHIFT(FOC_SOBS_L3_X)
#define FOC_SOBS_FF_X (FOC_SOBS_ACCEL_PU * FOC_TS_S * FOC_SOBS_Q31_PER_RAD_S / 32768.0)
#define FOC_SOBS_FF_MANT FOC_NORM_MANT(FOC_SOBS_FF_X)
#define FOC_SOBS_FF_RSHIFT FOC_NORM_RSHIFT(FOC_SOBS_FF_X)

FOC_STATIC_ASSERT(FOC_FLUX_SHIFT <= 14 && FOC_FLUX_LS_PU < 0.5,
                  "MOTOR_LQ_H / MOTOR_KE_VPK_PER_KRPM out of range for the flux format");
FOC_STATIC_ASSERT(FOC_FLUX_KINT_X < 8192.0 && FOC_NORM_OK(FOC_FLUX_KINT_X),
                  "SPEED_BASE_RPM x MOTOR_POLE_PAIRS / PWM_FREQUENCY_HZ out of range "
                  "for the flux integrator");
FOC_STATIC_ASSERT(FLUX_CORR_MIN_RAD_S > 0.0 && FOC_FLUX_CORR_MIN_PU <= 0.5,
                  "FLUX_CORR_MIN_RAD_S must be > 0 and at most 0.5 x PWM_FREQUENCY_HZ");
FOC_STATIC_ASSERT(FLUX_CORR_PER_SPEED >= 0.0 && FOC_FLUX_CORR_SPEED_PU < 1.0,
                  "FLUX_CORR_PER_SPEED must be >= 0 and x the electrical base speed "
                  "(rad/s) below PWM_FREQUENCY_HZ");
FOC_STATIC_ASSERT(FLUX_MAG_PER_SPEED >= 0.0 && FOC_FLUX_MAG_SPEED_PU < 0.5,
                  "FLUX_MAG_PER_SPEED must be >= 0 and x the electrical base speed "
                  "(rad/s) below 0.5 x PWM_FREQUENCY_HZ");
FOC_STATIC_ASSERT(FOC_SOBS_L1_PU < 0.5,
                  "FLUX_SPEED_OBS_BW_RAD_S too high for PWM_FREQUENCY_HZ (3 wo Ts < 0.5)");
FOC_STATIC_ASSERT(FOC_NORM_OK(FOC_SOBS_L2_X) && FOC_NORM_OK(FOC_SOBS_L3_X),
                  "FLUX_SPEED_OBS_BW_RAD_S out of range for the speed observer gains "
                  "(or MOTOR_INERTIA_KGM2 out of range)");
FOC_STATIC_ASSERT(FOC_NORM_OK(FOC_SOBS_FF_X),
                  "MOTOR_INERTIA_KGM2 out of range for the speed observer feed-forward");

/* ------------------------------------------------- field weakening -- */
#define FOC_FW_ID_MAX FOC_I_Q15(FW_ID_MAX_A)
#define FOC_FW_MARGIN Q15(FW_VOLTAGE_MARGIN)
/* Voltage PI (slow tick): error in volts per-unit, output Id per-unit. */
#define FOC_FW_KP_PU (FW_VOLTAGE_KP_A_PER_V * FOC_V_BASE_V / FOC_I_BASE_A)
#define FOC_FW_KI_PU (FW_VOLTAGE_KI_A_PER_VS * FOC_SLOW_TS_S * FOC_V_BASE_V / FOC_I_BASE_A)
#define FOC_FW_KP_MANT FOC_GAIN_MANT(FOC_FW_KP_PU)
#define FOC_FW_KP_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_FW_KP_PU))
#define FOC_FW_KI Q15(FOC_FW_KI_PU)
#define FOC_FW_KC Q15(FOC_FW_KI_PU / FOC_FW_KP_PU)
/* Tables: 18 entries from FW_START_RPM to FW_END_RPM.  Position in the
 * table in 1/256 of an entry = (|speed ref| - start) x FOC_FW_POS_GAIN. */
#define FOC_FW_TABLE_SIZE 18
#define FOC_FW_START FOC_SPEED_Q15(FW_START_RPM)
#define FOC_FW_POS_GAIN_PU                                                     \
    (256.0 * (FOC_FW_TABLE_SIZE - 1) /                                        \
     ((FW_END_RPM - FW_START_RPM) / SPEED_BASE_RPM * 32768.0))
#define FOC_FW_POS_MANT FOC_GAIN_MANT(FOC_FW_POS_GAIN_PU)
#define FOC_FW_POS_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_FW_POS_GAIN_PU))
/* A 1/KFi table entry from its ratio to nominal (for FW_INVKFI_TABLE). */
#define FOC_FW_INVKFI_Q(ratio) Q15((ratio) * FOC_PLL_INV_KFI_PU / (double)(1L << FOC_PLL_INVKFI_SHIFT))
/* Initial Id table: the no-load voltage balance w (Ld Id + flux) = Vfw at
 * the entry's speed, Vfw = the voltage limit x margin on the nominal bus;
 * clamped to [-FW_ID_MAX_A, 0]. */
#define FOC_FW_WE_AT(i)                                                        \
    ((FW_START_RPM + (i) * (FW_END_RPM - FW_START_RPM) / (FOC_FW_TABLE_SIZE - 1)) * \
     MOTOR_POLE_PAIRS * 2.0 * FOC_PI_D / 60.0)
#define FOC_FW_VFW_V (FOC_V_BASE_V * VOLTAGE_LIMIT_FRACTION * FW_VOLTAGE_MARGIN)
#define FOC_FW_ID_RAW_A(i) ((FOC_FW_VFW_V / FOC_FW_WE_AT(i) - FOC_FLUX_WB) / MOTOR_LD_H)
#define FOC_FW_ID_AT(i)                                                        \
    FOC_I_Q15(FOC_FW_ID_RAW_A(i) > 0.0 ? 0.0                                   \
              : FOC_FW_ID_RAW_A(i) < -FW_ID_MAX_A ? -FW_ID_MAX_A : FOC_FW_ID_RAW_A(i))

/* ------------------------------------------------------------- MTPA -- */
/* A salient rotor (MOTOR_LQ_H > MOTOR_LD_H) runs on the maximum-torque-
 * per-ampere d current in RUN (mtpa.h), combined with field weakening's
 * (the more negative); a round rotor keeps id = 0 below base speed, and
 * the controller's MTPA code folds away (FOC_SALIENT is a constant).
 * k = 2 (Lq - Ld) / psi per unit of current, Q12 (< 8).  An inverse-
 * salient rotor (Ld > Lq) would want a positive d current: not done. */
#define FOC_SALIENT (MOTOR_LQ_H > MOTOR_LD_H)
#define FOC_MTPA_K_PU                                                          \
    (FOC_SALIENT ? 2.0 * (MOTOR_LQ_H - MOTOR_LD_H) * FOC_I_BASE_A / FOC_FLUX_WB : 0.0)
#define FOC_MTPA_K_Q12 ((q15_t)(FOC_MTPA_K_PU * 4096.0 + 0.5))
FOC_STATIC_ASSERT(FOC_MTPA_K_PU < 7.999,
                  "MTPA: (MOTOR_LQ_H - MOTOR_LD_H) x BOARD_CURRENT_FULL_SCALE_A above 4 x the "
                  "magnet flux, beyond the MTPA block's format");

/* ------------------------------------------------ dead-time comp. -- */
/* The bridge's effective dead time: the phase voltage it loses in the
 * current's direction, over Vdc f_pwm.  The switches' delays and drops
 * add to the timer's PWM_DEADTIME_S (a slow gate driver takes from it);
 * self-commissioning measures it (docs/commissioning.md, "RS").  The
 * compensation, the estimators' model of the bridge and the dead time's
 * speed floor use it: 25 % off, the angle error at 500 rpm on `plant
 * realistic` was 4.9-8.5 deg instead of 1.8-2.2 (docs/estimators.md). */
#ifndef DEADTIME_EFFECTIVE_S
#define DEADTIME_EFFECTIVE_S PWM_DEADTIME_S
#endif
/* Phase voltage lost per dead time, Vdc t_dead f_pwm, in per-unit of the
 * voltage base Vdc/sqrt(3) (nominal bus); the soft-sign gain 1/I_soft in
 * per-unit of the current base. */
#define FOC_DT_VOLTAGE Q15(FOC_SQRT3_D * DEADTIME_EFFECTIVE_S * PWM_FREQUENCY_HZ)
#define FOC_DT_INV_SOFT_PU (FOC_I_BASE_A / DEADTIME_COMP_CURRENT_A)
/* Half the peak-to-peak PWM current ripple at 50 % duty with 2/3 of the bus
 * across the winding: within it the period-average dead-time error is
 * proportional to the current (the estimator's model of the bridge). */
#define FOC_DT_RIPPLE_BAND_A                                                   \
    ((2.0 / 3.0) * BOARD_VDC_NOMINAL_V / (8.0 * 0.5 * (MOTOR_LD_H + MOTOR_LQ_H) * PWM_FREQUENCY_HZ))
#define FOC_DT_INV_RIPPLE_PU (FOC_I_BASE_A / FOC_DT_RIPPLE_BAND_A)
#define FOC_DT_INV_RIPPLE_MANT FOC_GAIN_MANT(FOC_DT_INV_RIPPLE_PU)
#define FOC_DT_INV_RIPPLE_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_DT_INV_RIPPLE_PU))
/* The least current the sensorless drive keeps in the windings while the
 * compensation and field weakening are on (controller.c dt_floor_id): the
 * d current makes up what the load's q current lacks.  Where the PWM
 * ripple band is narrow, a light load's phase currents sit where the
 * bridge's dead-time error is nearly a step at each current's sign, which
 * neither the compensation nor the estimators' model (the band's slope)
 * follows, and the estimates ripple (docs/estimators.md, "Near zero
 * current").  By default twice the soft band where the ripple band is
 * under half of it (the Hurst075: 52 mA), else 0: with a wide band the
 * error is the slope the estimators model, and the floor's d current only
 * turns its residual into angle (the Shinano LA052, band 0.21 A, at 500
 * rpm: 0.47 -> 1.67 deg).  It is 0 up to 1.25 x the dead time's command
 * floor FOC_DT_FLOOR_RPM (439 rpm on the Hurst075: from the floor itself
 * the lowest steady speeds of docs/estimators.md's walk on `plant
 * realistic`, which starts at 400 rpm, fell from 300 to 400 rpm for the
 * Luenberger observer and 125 to 150 for the flux estimator), full from
 * 1.5 x, and at most the current whose ohmic drop is 1/4 of the back-EMF:
 * an Rs error times the floor's d current lies across the EMF, so an Rs
 * off by 30 % turns the angle by at most 4 deg. */
#ifndef DEADTIME_MIN_CURRENT_A
#define DEADTIME_MIN_CURRENT_A                                                 \
    ((FOC_DT_RIPPLE_BAND_A < DEADTIME_COMP_CURRENT_A / 2.0) ? 2.0 * DEADTIME_COMP_CURRENT_A : 0.0)
#endif
#define FOC_DT_MIN_CURRENT FOC_I_Q15(DEADTIME_MIN_CURRENT_A)
#define FOC_DT_MIN_PER_SPEED_PU (FOC_KFI_PU / (4.0 * FOC_RS_PU))
#define FOC_DT_MIN_PER_SPEED_MANT FOC_GAIN_MANT(FOC_DT_MIN_PER_SPEED_PU)
#define FOC_DT_MIN_PER_SPEED_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_DT_MIN_PER_SPEED_PU))
#define FOC_DT_MIN_FROM FOC_SPEED_Q15(1.25 * FOC_DT_FLOOR_RPM)
/* the ramp's slope, current per speed (+1 rpm: none without dead time) */
#define FOC_DT_MIN_RAMP_PU                                                     \
    (DEADTIME_MIN_CURRENT_A / FOC_I_BASE_A / (0.25 * (FOC_DT_FLOOR_RPM + 1.0) / SPEED_BASE_RPM))
#define FOC_DT_MIN_RAMP_MANT FOC_GAIN_MANT(FOC_DT_MIN_RAMP_PU)
#define FOC_DT_MIN_RAMP_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_DT_MIN_RAMP_PU))
#define FOC_DT_INV_SOFT_MANT FOC_GAIN_MANT(FOC_DT_INV_SOFT_PU)
#define FOC_DT_INV_SOFT_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_DT_INV_SOFT_PU))

/* -------------------------------------------------------------- bus -- */
/* Nominal bus in bus-ADC counts; the modulation compensation is
 * Vdc_nominal / Vdc_measured in Q14 (up to 2.0), from the bus filtered
 * over 2 slow ticks, a step taken at once by the fast step (bus.h): a bus
 * that steps (a supply switched, a surge) must be compensated at once, or
 * the bridge applies the step's ratio of what the current loop asks (a
 * 20 % step with a 10 ms filter left the current 10 % above the limit;
 * 42 % with only the 2 slow ticks' filter, 1.08 x at the drone's maximum
 * speed); the ADC's noise on one sample is a few counts of thousands. */
#define FOC_VDC_NOMINAL FOC_VDC_Q15(BOARD_VDC_NOMINAL_V)
#define FOC_VDC_FILTER_K Q15(0.5)

/* ------------------------------------------------------- calibration -- */
#define FOC_CALIB_PERIODS_LOG2 10 /* 1024 periods averaged for the offsets */
/* Commissioning's: 16384 periods.  An offset error turns in the rotor
 * frame and, through the estimator's angle, leaves a q current bias that
 * the friction's few mA feel: with 1024 periods and 2 codes of noise the
 * Hurst075's viscous friction came out 4 % (1 sigma) off, with 16384 1 %. */
#define FOC_COMM_CALIB_PERIODS_LOG2 14
#define FOC_CALIB_TICKS ((uint16_t)(CALIB_TIME_S / FOC_SLOW_TS_S + 0.5))

/* ---------------------------------------------------------- start-up -- */
/* Slow ticks of a duration, at least 1. */
#define FOC_TICKS(seconds)                                                     \
    ((uint16_t)((seconds) / FOC_SLOW_TS_S < 1.0 ? 1 : (seconds) / FOC_SLOW_TS_S + 0.5))
/* A Q15 change spread over a number of ticks, at least 1 LSB per tick
 * when the change is not 0. */
#define FOC_STEP_PER_TICK(q15_change, ticks)                                  \
    ((q15_t)((q15_change) == 0 ? 0                                             \
             : (int32_t)(q15_change) / (int32_t)(ticks) == 0                   \
                 ? 1 : (int32_t)(q15_change) / (int32_t)(ticks)))
#define FOC_ALIGN_CURRENT FOC_I_Q15(STARTUP_ALIGN_CURRENT_A)
#define FOC_ALIGN_HALF_TICKS FOC_TICKS(STARTUP_ALIGN_TIME_S / 2.0)
#define FOC_ALIGN_CURRENT_STEP FOC_STEP_PER_TICK(FOC_ALIGN_CURRENT, FOC_ALIGN_HALF_TICKS)
/* The second half's ramp from half the alignment current (the turn's,
 * startup.c) back to the whole, at four times the first half's rate: the
 * whole from an eighth of the second half on. */
#define FOC_ALIGN_RERAMP_STEP \
    FOC_STEP_PER_TICK(FOC_ALIGN_CURRENT, (FOC_ALIGN_HALF_TICKS / 4u > 0u ? FOC_ALIGN_HALF_TICKS / 4u : 1u))
/* The turn from the first alignment position to the start angle (90 deg,
 * 2^30 in the 32-bit angle) over a twelfth of the second half (5 ms for
 * the Hurst075's 0.12 s alignment), per tick. */
#define FOC_ALIGN_TURN_TICKS (FOC_ALIGN_HALF_TICKS / 12u > 0u ? FOC_ALIGN_HALF_TICKS / 12u : 1u)
#define FOC_ALIGN_TURN_STEP32 ((int32_t)(1073741824L / (int32_t)FOC_ALIGN_TURN_TICKS + 1))
/* The inductance probe (controller.c, l_probe, identify_ls): with the
 * current held on d (ALIGN: the rotor by the alignment current; CATCH:
 * -FOC_LPROBE_DI, the field weakened a little), both current PIs are held
 * and the d voltage stepped down by FOC_LPROBE_DV for FOC_LPROBE_N
 * periods, then up as long, so the current deviates by about
 * dV N Ts / Ld and comes back.  N: the shortest probe whose step fits in
 * the voltage the alignment current's Rs drop leaves (FOC_LPROBE_V_ROOM_V,
 * twice the parameter's Rs: the winding's may be), 2 to 16 periods: a
 * turning rotor turns little during it, and Rs bends the ramp little (its
 * first-order share, Rs T / 2, is taken off: FOC_LPROBE_RT_Q14); dV: a
 * deviation of a quarter of the alignment current with the parameter's Ld
 * (FOC_LPROBE_DI).  Two more periods for
 * the PWM's and the sample's lag; the state after the last
 * (FOC_LPROBE_DONE) tells the slow step it is over. */
#define FOC_LPROBE_V_ROOM_V                                                    \
    (VOLTAGE_LIMIT_FRACTION * FOC_V_BASE_V - 2.0 * MOTOR_RS_OHM * STARTUP_ALIGN_CURRENT_A)
#define FOC_LPROBE_N_D (MOTOR_LD_H * STARTUP_ALIGN_CURRENT_A / 4.0 / FOC_TS_S / FOC_LPROBE_V_ROOM_V)
#define FOC_LPROBE_N                                                           \
    ((uint8_t)(FOC_LPROBE_N_D < 2.0 ? 2.0 : FOC_LPROBE_N_D > 15.0 ? 16.0 : FOC_LPROBE_N_D + 0.999))
#define FOC_LPROBE_T_S ((double)FOC_LPROBE_N * FOC_TS_S)
#define FOC_LPROBE_DI_A (STARTUP_ALIGN_CURRENT_A / 4.0)
#define FOC_LPROBE_DI FOC_I_Q15(FOC_LPROBE_DI_A)
#define FOC_LPROBE_DV_V (MOTOR_LD_H * FOC_LPROBE_DI_A / FOC_LPROBE_T_S)
#define FOC_LPROBE_DV Q15(FOC_LPROBE_DV_V / FOC_V_BASE_V)
#define FOC_LPROBE_RT_Q14 ((int32_t)(16384.0 * MOTOR_RS_OHM * FOC_LPROBE_T_S / (2.0 * MOTOR_LD_H) + 0.5))
#define FOC_LPROBE_PERIODS ((uint8_t)(2u * FOC_LPROBE_N + 2u))
#define FOC_LPROBE_DONE ((uint8_t)(FOC_LPROBE_PERIODS + 1u))
/* The slow step's request (controller.h lprobe_req): the probe runs while
 * it is FOC_LPROBE_GO.  ALIGN asks at once (its current is long settled);
 * CATCH counts from 1 the slow ticks its hold current (-FOC_LPROBE_DI on
 * d, 0 on q) has been within FOC_LPROBE_DI / 8 on both axes. */
#define FOC_LPROBE_GO ((uint8_t)5u)
/* ALIGN's probes, averaged: one dip of a quarter of the alignment current
 * is 43 codes on the Hurst075's 10-bit ADC, and 2 codes of noise left its
 * Ld 7 % RMS off (12 seeds of the realistic plant). */
#define FOC_LPROBE_REPEAT 4u
/* CATCH probes a rotor turning at most 0.5 rad (electrical) per FOC_LPROBE_N
 * periods: the deviation's magnitude is then within 1 % of dV t / L (the
 * held voltages' own error, which rotation turns into current, stays small
 * against dV too); a faster rotor keeps the inductance it has. */
#define FOC_LPROBE_SPEED_MAX_RPM (0.5 * 60.0 / (2.0 * FOC_PI_D * MOTOR_POLE_PAIRS * FOC_LPROBE_T_S))
/* Q15 of SPEED_BASE_RPM in 32 bits: above 32767 where every speed qualifies. */
#define FOC_LPROBE_SPEED_MAX ((int32_t)(FOC_LPROBE_SPEED_MAX_RPM * 32768.0 / SPEED_BASE_RPM))
#define FOC_OL_FINAL_SPEED FOC_SPEED_Q15(STARTUP_FINAL_SPEED_RPM)
#define FOC_OL_RAMP_TICKS FOC_TICKS(STARTUP_RAMP_TIME_S)
/* Forced-speed step per slow tick in Q15.16, so the ramp time is exact. */
#define FOC_OL_SPEED_STEP16                                                    \
    ((int32_t)((double)FOC_OL_FINAL_SPEED * 65536.0 / FOC_OL_RAMP_TICKS + 0.5))
#define FOC_OL_CURRENT_FIRST FOC_I_Q15(STARTUP_CURRENT_FIRST_A)
#define FOC_OL_CURRENT_FINAL FOC_I_Q15(STARTUP_CURRENT_FINAL_A)
/* Signed division: with a 16-bit int a uint16_t tick count would make it
 * unsigned. */
#define FOC_OL_CURRENT_STEP                                                    \
    ((q15_t)(((int32_t)FOC_OL_CURRENT_FINAL - (int32_t)FOC_OL_CURRENT_FIRST) /  \
             (int32_t)FOC_OL_RAMP_TICKS))
/* Start-up q voltage of a rotor turning with the forced frame: back-EMF
 * w psi plus the cross-coupling w Ld id, per unit of speed (and of speed x
 * current), both in voltage per-unit. */
#define FOC_EMF_PER_SPEED_PU FOC_KFI_PU
#define FOC_EMF_PER_SPEED_MANT FOC_GAIN_MANT(FOC_EMF_PER_SPEED_PU)
#define FOC_EMF_PER_SPEED_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_EMF_PER_SPEED_PU))
/* Rs x the current limit, Q15 of the voltage base: the most a q voltage
 * below the back-EMF drives (the EMF feedforward's floor). */
#define FOC_RS_ILIM_V Q15(MOTOR_RS_OHM * CURRENT_LIMIT_A / FOC_V_BASE_V)
#define FOC_XD_PU (FOC_WE_BASE_RAD_S * MOTOR_LD_H * FOC_I_BASE_A / FOC_V_BASE_V)
#define FOC_XD_MANT FOC_GAIN_MANT(FOC_XD_PU)
#define FOC_XD_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_XD_PU))
#define FOC_XQ_PU (FOC_WE_BASE_RAD_S * MOTOR_LQ_H * FOC_I_BASE_A / FOC_V_BASE_V)
#define FOC_XQ_MANT FOC_GAIN_MANT(FOC_XQ_PU)
#define FOC_XQ_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_XQ_PU))
/* Online Rs adaptation (rs_adapt.c): its inputs' filter (20 ms at the
 * slow tick) and the Newton step's divisor, Rs in per unit x 2^7 (one
 * 64th of the step, rs_adapt.h), at least 1. */
#define FOC_RSA_FILTER_K Q15(FOC_SLOW_TS_S / (0.020 + FOC_SLOW_TS_S))
#define FOC_RSA_STEP_DIV ((int32_t)(FOC_RS_PU * 128.0 + 1.0))
#define FOC_STARTUP_MIN_SPEED FOC_SPEED_Q15(STARTUP_MIN_SPEED_RPM)
/* ---------------------------------------------------- commissioning -- */
/* commission.c (docs/commissioning.md).  Two d currents for Rs: the high
 * one the rated current, at most 0.9 x the regulated limit; the low one
 * half of it (also the hold of the inductance pulses). */
#define FOC_COMM_I_HIGH_A                                                      \
    ((MOTOR_RATED_CURRENT_A < 0.9 * CURRENT_LIMIT_A * (1.0 - CURRENT_REF_MARGIN))  \
         ? MOTOR_RATED_CURRENT_A : 0.9 * CURRENT_LIMIT_A * (1.0 - CURRENT_REF_MARGIN))
#define FOC_COMM_I_HIGH FOC_I_Q15(FOC_COMM_I_HIGH_A)
#define FOC_COMM_I_LOW FOC_I_Q15(FOC_COMM_I_HIGH_A / 2.0)
/* Means over 2^FOC_COMM_SUM_LOG2 periods (sums of Q15 within 2^27). */
#define FOC_COMM_SUM_LOG2 12
#define FOC_COMM_SUM_N ((uint16_t)((uint16_t)1u << FOC_COMM_SUM_LOG2))
/* The currents' electrical settling before a sum, and the rotor's after
 * the alignment (as long as the alignment itself). */
#define FOC_COMM_SETTLE_TICKS FOC_TICKS(0.03)
#define FOC_COMM_ROTOR_SETTLE_TICKS FOC_TICKS(STARTUP_ALIGN_TIME_S)
/* Inductance pulses: a square wave of +-dV on one axis, half-period N
 * periods, on top of the held voltages; N a quarter of the parameters'
 * L / Rs (8 to 32 periods), dV the one that gives FOC_COMM_PULSE_DI_A
 * peak to peak with the parameter's L. */
#define FOC_COMM_TAU_S ((MOTOR_LD_H < MOTOR_LQ_H ? MOTOR_LD_H : MOTOR_LQ_H) / MOTOR_RS_OHM)
#define FOC_COMM_PULSE_N_D (FOC_COMM_TAU_S / 4.0 / FOC_TS_S)
#define FOC_COMM_PULSE_N                                                       \
    ((uint8_t)(FOC_COMM_PULSE_N_D < 8.0 ? 8.0 : FOC_COMM_PULSE_N_D > 32.0 ? 32.0 : FOC_COMM_PULSE_N_D))
#define FOC_COMM_PULSE_DI_A (FOC_COMM_I_HIGH_A / 4.0)
#define FOC_COMM_PULSE_DV_D Q15(MOTOR_LD_H * FOC_COMM_PULSE_DI_A / (FOC_COMM_PULSE_N * FOC_TS_S) / FOC_V_BASE_V)
#define FOC_COMM_PULSE_DV_Q Q15(MOTOR_LQ_H * FOC_COMM_PULSE_DI_A / (FOC_COMM_PULSE_N * FOC_TS_S) / FOC_V_BASE_V)
/* Each half's regression window: its samples 3 .. N-1 (the PWM's and the
 * sample's lag, 2 periods at most, kept out), n = N - 3 of them; the
 * weights u = 2 j - (n - 1) have sum u^2 = n (n^2 - 1) / 3. */
#define FOC_COMM_WIN_N ((uint8_t)(FOC_COMM_PULSE_N - 3u))
#define FOC_COMM_SUM_U2_D ((double)FOC_COMM_WIN_N * ((double)FOC_COMM_WIN_N * FOC_COMM_WIN_N - 1.0) / 3.0)
/* Cycles summed (after 2 to settle): about 2^FOC_COMM_SUM_LOG2 periods. */
#define FOC_COMM_PULSE_CYCLES ((uint16_t)(FOC_COMM_SUM_N / (2u * FOC_COMM_PULSE_N)))
/* The regression sum the parameter's L gives: cycles x 2 halves x the
 * slope (dV Ts / L per period, Q15 current per Q15 voltage) x sum u^2 / 2. */
#define FOC_COMM_SLOPE_PER_V(l_h) (FOC_TS_S * FOC_V_BASE_V / ((l_h) * FOC_I_BASE_A))
#define FOC_COMM_PULSE_SUM_D                                                   \
    ((int32_t)((double)FOC_COMM_PULSE_CYCLES * FOC_COMM_PULSE_DV_D * FOC_COMM_SLOPE_PER_V(MOTOR_LD_H) * FOC_COMM_SUM_U2_D + 0.5))
#define FOC_COMM_PULSE_SUM_Q                                                   \
    ((int32_t)((double)FOC_COMM_PULSE_CYCLES * FOC_COMM_PULSE_DV_Q * FOC_COMM_SLOPE_PER_V(MOTOR_LQ_H) * FOC_COMM_SUM_U2_D + 0.5))
/* Rs's share of the slope: Ts Rs / L of the parameters, Q20 (< 2^20:
 * a winding with Ts > L / Rs is refused below). */
#define FOC_COMM_TS_TAU_D_Q20 ((int32_t)(FOC_TS_S * MOTOR_RS_OHM / MOTOR_LD_H * 1048576.0 + 0.5))
#define FOC_COMM_TS_TAU_Q_Q20 ((int32_t)(FOC_TS_S * MOTOR_RS_OHM / MOTOR_LQ_H * 1048576.0 + 0.5))
/* The I/f spin for the flux: twice the start-up's final speed, within
 * 0.15 .. 0.3 of the maximum (at 0.5, 4500 rpm, the drone's rotor swung
 * by +-12 A about the forced angle with Ld 1.3 and Lq 0.7 x the
 * parameters); the rotor's swing settles for 0.3 s. */
#define FOC_COMM_SPIN_RPM_D (2.0 * STARTUP_FINAL_SPEED_RPM)
#define FOC_COMM_SPIN_RPM                                                      \
    (FOC_COMM_SPIN_RPM_D < 0.15 * MOTOR_MAX_SPEED_RPM ? 0.15 * MOTOR_MAX_SPEED_RPM    \
     : FOC_COMM_SPIN_RPM_D > 0.3 * MOTOR_MAX_SPEED_RPM ? 0.3 * MOTOR_MAX_SPEED_RPM   \
                                                      : FOC_COMM_SPIN_RPM_D)
#define FOC_COMM_SPIN_SPEED FOC_SPEED_Q15(FOC_COMM_SPIN_RPM)
#define FOC_COMM_SPIN_SETTLE_TICKS FOC_TICKS(0.3)
/* A step that has not ended in this time failed: the start-up's timeout,
 * twice, plus a second, at most 65000 slow ticks (the counter is 16-bit:
 * the fan's 47 s are 94000 ticks, which the conversion cannot hold). */
#define FOC_COMM_STEP_TIMEOUT_S (2.0 * STARTUP_TIMEOUT_S + 1.0)
#define FOC_COMM_STEP_TIMEOUT_TICKS                                            \
    FOC_TICKS(FOC_COMM_STEP_TIMEOUT_S < 65000.0 * FOC_SLOW_TS_S ? FOC_COMM_STEP_TIMEOUT_S \
                                                                 : 65000.0 * FOC_SLOW_TS_S)
/* A calibrated offset beyond 1/8 of the full scale is a broken sensor. */
#define FOC_COMM_OFFSET_MAX ((q15_t)4096)
/* The parameters in per-unit, scaled by 2^20 (each below 2^30): Rs, the
 * reactances at the speed base, the back-EMF per speed base (Q15). */
#define FOC_COMM_RS_Q20 ((int32_t)(FOC_RS_PU * 1048576.0 + 0.5))
#define FOC_COMM_XD_Q20 ((int32_t)(FOC_WE_BASE_RAD_S * MOTOR_LD_H * FOC_I_BASE_A / FOC_V_BASE_V * 1048576.0 + 0.5))
#define FOC_COMM_XQ_Q20 ((int32_t)(FOC_WE_BASE_RAD_S * MOTOR_LQ_H * FOC_I_BASE_A / FOC_V_BASE_V * 1048576.0 + 0.5))
#define FOC_COMM_KE_Q15 ((int32_t)(FOC_KFI_PU * 32768.0 + 0.5))
/* MECH (inertia and friction) in RUN on the speed loop: a low and a high
 * speed below field weakening (the high 0.9 x the rated speed, the low
 * the spin's, at most half the high), each held while the q current is
 * summed over 2^FOC_COMM_MECH_SUM_LOG2 slow ticks; between them a window
 * up and one down, FOC_COMM_MECH_WINDOW_TICKS each: the reference's ramp
 * (the reference's rate, slower if the parameter's inertia would take
 * more than 0.3 x the current limit) and 0.5 s to settle. */
#define FOC_COMM_MECH_HIGH_RPM \
    (0.9 * (MOTOR_NOMINAL_SPEED_RPM < MOTOR_MAX_SPEED_RPM ? MOTOR_NOMINAL_SPEED_RPM : MOTOR_MAX_SPEED_RPM))
#define FOC_COMM_MECH_LOW_RPM \
    (STARTUP_FINAL_SPEED_RPM > 0.25 * FOC_COMM_MECH_HIGH_RPM ? STARTUP_FINAL_SPEED_RPM : 0.25 * FOC_COMM_MECH_HIGH_RPM)
#define FOC_COMM_MECH_HIGH FOC_SPEED_Q15(FOC_COMM_MECH_HIGH_RPM)
#define FOC_COMM_MECH_LOW FOC_SPEED_Q15(FOC_COMM_MECH_LOW_RPM)
/* MECH runs only with the measured flux, Ld and Lq within 15 % of the
 * parameters (commission.h) */
#define FOC_COMM_MECH_MATCH_MIN_Q14 ((int32_t)(0.85 * 16384.0 + 0.5))
#define FOC_COMM_MECH_MATCH_MAX_Q14 ((int32_t)(1.15 * 16384.0 + 0.5))
/* 2^13 slow ticks (4 s at 2 kHz) with a 12-bit ADC, twice as long per
 * bit less, up to 2^15: the Hurst075's 10-bit MCLV put its viscous
 * friction 5.3 % off in 2 of 10 seeds in 4 s (half the friction: its
 * current changes by 2.3 mA, 0.27 codes, between the speeds). */
#define FOC_COMM_MECH_SUM_LOG2 \
    (BOARD_ADC_BITS >= 12 ? 13 : BOARD_ADC_BITS <= 10 ? 15 : 13 + (12 - BOARD_ADC_BITS))
#define FOC_COMM_MECH_SUM_N ((uint16_t)((uint16_t)1u << (unsigned)FOC_COMM_MECH_SUM_LOG2))
/* Kt of the parameters (Nm/A) and the accelerations (rpm/s) */
#define FOC_KT_NM_PER_A (1.5 * MOTOR_POLE_PAIRS * FOC_FLUX_WB)
#define FOC_COMM_MECH_ACCEL_J_RPM_S \
    (0.3 * FOC_KT_NM_PER_A * CURRENT_LIMIT_A / MOTOR_INERTIA_KGM2 * 60.0 / (2.0 * FOC_PI_D))
#define FOC_COMM_MECH_ACCEL_RPM_S \
    (FOC_COMM_MECH_ACCEL_J_RPM_S < SPEED_RAMP_RPM_PER_S ? FOC_COMM_MECH_ACCEL_J_RPM_S : SPEED_RAMP_RPM_PER_S)
#define FOC_COMM_MECH_RAMP_STEP15 \
    ((int32_t)(FOC_COMM_MECH_ACCEL_RPM_S * FOC_SLOW_TS_S / SPEED_BASE_RPM * 32768.0 * 32768.0 + 0.5))
#define FOC_COMM_MECH_WINDOW_S \
    ((FOC_COMM_MECH_HIGH_RPM - FOC_COMM_MECH_LOW_RPM) / FOC_COMM_MECH_ACCEL_RPM_S + 0.5)
#define FOC_COMM_MECH_WINDOW_TICKS FOC_TICKS(FOC_COMM_MECH_WINDOW_S)
/* The speed step the windows cross, as the Q15 speeds give it (rad/s) */
#define FOC_COMM_MECH_DW_RAD_S \
    ((double)(FOC_COMM_MECH_HIGH - FOC_COMM_MECH_LOW) / 32768.0 * SPEED_BASE_RPM * 2.0 * FOC_PI_D / 60.0)
/* The windows' difference of q current sums (Q15 x slow ticks) that
 * MOTOR_INERTIA_KGM2 gives: 2 J dw = Kt I_base Ts x sum / 32768. */
#define FOC_COMM_MECH_J_SUM \
    ((int32_t)(2.0 * MOTOR_INERTIA_KGM2 * FOC_COMM_MECH_DW_RAD_S * 32768.0 / \
               (FOC_KT_NM_PER_A * FOC_I_BASE_A * FOC_SLOW_TS_S) + 0.5))
/* 2^24 / the speed step (Q15): the friction's slope in Q24 per Q15 speed */
#define FOC_COMM_MECH_INV_DW_Q24 \
    ((int32_t)(16777216.0 / (double)(FOC_COMM_MECH_HIGH - FOC_COMM_MECH_LOW) + 0.5))
/* STOP (ramp mode) leaves the rotor to coast at STOP_SPEED_RPM, but on an
 * estimate not below STARTUP_MIN_SPEED_RPM, the lowest speed the
 * estimators carry the loop at: lower, the drone's Luenberger observer
 * lost its angle in the ramp (1.11 x the current limit, torture seed 434).
 * The position sensor runs down to STOP_SPEED_RPM. */
#define FOC_STOP_SPEED_ESTIMATED ((FOC_STOP_SPEED > FOC_STARTUP_MIN_SPEED) ? FOC_STOP_SPEED : FOC_STARTUP_MIN_SPEED)
/* Speed window as ratios in Q8 (256 = 1.0). */
#define FOC_STARTUP_WINDOW_MIN_Q8 ((int32_t)(STARTUP_SPEED_WINDOW_MIN * 256.0 + 0.5))
#define FOC_STARTUP_WINDOW_MAX_Q8 ((int32_t)(STARTUP_SPEED_WINDOW_MAX * 256.0 + 0.5))
#define FOC_STARTUP_VARIANCE_THRESHOLD Q15(STARTUP_VARIANCE_THRESHOLD)
#define FOC_STARTUP_TIMEOUT_TICKS FOC_TICKS(STARTUP_TIMEOUT_S)
#define FOC_HANDOVER_TICKS FOC_TICKS(STARTUP_HANDOVER_TIME_S)
/* The hand-over d current (at most the start-up current) fades at this
 * rate per slow tick. */
#define FOC_HANDOVER_ID_STEP FOC_STEP_PER_TICK(FOC_ALIGN_CURRENT, FOC_HANDOVER_TICKS)
#define FOC_TUNING_RAMP_STEP15                                                 \
    ((int32_t)(TUNING_RAMP_RPM_PER_S * FOC_SLOW_TS_S / SPEED_BASE_RPM * 32768.0 * 32768.0 + 0.5))

/* ------------------------------------------------------- supervision -- */
#define FOC_STALL_VARIANCE_THRESHOLD Q15(STALL_VARIANCE_THRESHOLD)
#define FOC_STALL_EMF_RATIO Q15(STALL_EMF_RATIO)
/* Motoring (current along the speed), a resistance above the model's adds
 * its unknown drop to the back-EMF the Luenberger observer sees: a held
 * rotor looks like one turning at the drop's worth of speed (torture
 * 6882).  The stricter ratio applies then; braking, the same drop hides
 * back-EMF and only STALL_EMF_RATIO is safe from false trips (torture
 * 4313).  The PLL estimator keeps STALL_EMF_RATIO: its flux tracking may
 * legitimately take its speed to twice what its EMF implies. */
#ifndef STALL_EMF_RATIO_MOTORING
#define STALL_EMF_RATIO_MOTORING 0.7
#endif
#define FOC_STALL_EMF_RATIO_MOTORING Q15(STALL_EMF_RATIO_MOTORING)
#define FOC_OVERVOLTAGE FOC_VDC_Q15(OVERVOLTAGE_V)
#define FOC_OVERVOLTAGE_HARD FOC_VDC_Q15(1.2 * OVERVOLTAGE_V)
#define FOC_OVERVOLTAGE_CLEAR FOC_VDC_Q15(OVERVOLTAGE_V - BUS_HYSTERESIS_V)
#define FOC_UNDERVOLTAGE FOC_VDC_Q15(UNDERVOLTAGE_V)
#define FOC_UNDERVOLTAGE_CLEAR FOC_VDC_Q15(UNDERVOLTAGE_V + BUS_HYSTERESIS_V)
/* Temperature thresholds as sensor readings, Q15 of BOARD_ADC_VREF_V. */
#define FOC_TEMP_READING(degc)                                                 \
    Q15((BOARD_TEMP_V_AT_0C + BOARD_TEMP_V_PER_DEGC * (degc)) / BOARD_ADC_VREF_V)
#define FOC_OVERTEMP FOC_TEMP_READING(OVERTEMP_DEGC)
#define FOC_OVERTEMP_CLEAR FOC_TEMP_READING(OVERTEMP_DEGC - TEMP_HYSTERESIS_DEGC)
#define FOC_ACK_MIN_TICKS FOC_TICKS(FAULT_ACK_MIN_TIME_S)

/* ----------------------------------------------------------- braking -- */
/* Shorted windings carry w psi / sqrt(R^2 + (w L)^2), which stays within
 * the current limit I for w^2 (psi^2 - (I L)^2) <= (I R)^2 (any speed when
 * psi <= I L).  The safe speed squared, with a 10 % speed margin, as Q30 of
 * the speed base squared (compared with speed x speed, no square root). */
#define FOC_SHORT_IL (CURRENT_LIMIT_A * MOTOR_LD_H)
#define FOC_SHORT_IR (CURRENT_LIMIT_A * MOTOR_RS_OHM)
#define FOC_SHORT_SAFE_SPEED2_PU                                               \
    (FOC_FLUX_WB <= FOC_SHORT_IL ? 1.0                                          \
     : 0.81 * FOC_SHORT_IR * FOC_SHORT_IR /                                     \
           ((FOC_FLUX_WB * FOC_FLUX_WB - FOC_SHORT_IL * FOC_SHORT_IL) *          \
            FOC_WE_BASE_RAD_S * FOC_WE_BASE_RAD_S))
#define FOC_SHORT_SAFE_SPEED2                                                  \
    ((int32_t)(FOC_SHORT_SAFE_SPEED2_PU >= 1.0 ? 1073741823.0                   \
                                               : FOC_SHORT_SAFE_SPEED2_PU * 1073741824.0))
/* Shorted windings brake a slow rotor with the time constant
 * J R / (1.5 p^2 psi^2); they stay shorted for 20 of them (at least
 * 0.1 s), by which time the rotor stands still. */
#define FOC_SHORT_TAU_S                                                        \
    (MOTOR_INERTIA_KGM2 * MOTOR_RS_OHM /                                        \
     (1.5 * MOTOR_POLE_PAIRS * MOTOR_POLE_PAIRS * FOC_FLUX_WB * FOC_FLUX_WB))
#define FOC_SHORT_HOLD_TICKS FOC_TICKS(20.0 * FOC_SHORT_TAU_S < 0.1 ? 0.1 : 20.0 * FOC_SHORT_TAU_S)
#define FOC_BRAKE_RESISTOR_ON FOC_VDC_Q15(BRAKE_RESISTOR_ON_V)
#define FOC_BRAKE_RESISTOR_OFF FOC_VDC_Q15(BRAKE_RESISTOR_OFF_V)

/* ------------------------------------------------------------ checks -- */
FOC_STATIC_ASSERT(MOTOR_POLE_PAIRS >= 1 && MOTOR_POLE_PAIRS <= 64,
                  "MOTOR_POLE_PAIRS must be 1..64");
FOC_STATIC_ASSERT(CURRENT_TRIP_MARGIN >= 0.0 && CURRENT_TRIP_MARGIN < 0.05 &&
                  CURRENT_LIMIT_A * (1.0 + CURRENT_TRIP_MARGIN) < BOARD_CURRENT_FULL_SCALE_A,
                  "CURRENT_TRIP_MARGIN within [0, 5 %) and its trip level below "
                  "BOARD_CURRENT_FULL_SCALE_A");
FOC_STATIC_ASSERT(CURRENT_LIMIT_A > 0.0 && CURRENT_LIMIT_A < BOARD_CURRENT_FULL_SCALE_A,
                  "CURRENT_LIMIT_A must be below BOARD_CURRENT_FULL_SCALE_A");
FOC_STATIC_ASSERT(BOARD_VDC_NOMINAL_V < BOARD_VDC_FULL_SCALE_V,
                  "BOARD_VDC_NOMINAL_V must be below BOARD_VDC_FULL_SCALE_V");
FOC_STATIC_ASSERT(MOTOR_MAX_SPEED_RPM < SPEED_BASE_RPM,
                  "SPEED_BASE_RPM must exceed MOTOR_MAX_SPEED_RPM");
FOC_STATIC_ASSERT(FOC_DTHETA_AT_BASE < 16384.0,
                  "SPEED_BASE_RPM x MOTOR_POLE_PAIRS too high for PWM_FREQUENCY_HZ "
                  "(more than 90 electrical degrees per PWM period)");
/* Below 2^14: the monitor may double a proportional mantissa (pi.h). */
FOC_STATIC_ASSERT(FOC_CURRENT_KP_PU < 16384.0,
                  "CURRENT_KP_V_PER_A overflows its per-unit gain format");
FOC_STATIC_ASSERT(CURRENT_DIST_RATIO >= 0.0 && CURRENT_DIST_RATIO <= 1.0,
                  "CURRENT_DIST_RATIO must be in [0, 1] (the disturbance rejection "
                  "as a fraction of the current loop's bandwidth)");
FOC_STATIC_ASSERT(FOC_CURRENT_KREF_PU * 32768.0 * (double)(1L << (FOC_IREF_STEP_BITS - 1)) <
                      268435456.0,
                  "CURRENT_DIST_RATIO: the reference's step gain overflows the current PI's "
                  "integrator");
FOC_STATIC_ASSERT(FOC_CURRENT_KI_PU < 0.5,
                  "CURRENT_KI_V_PER_AS (with CURRENT_DIST_RATIO) too high: Ki per PWM "
                  "period must be < 0.5 pu");
FOC_STATIC_ASSERT(FOC_CURRENT_KREF_V_PER_A < CURRENT_KP_V_PER_A,
                  "CURRENT_DIST_RATIO too high for CURRENT_KP_V_PER_A and "
                  "CURRENT_KI_V_PER_AS: the reference's gain must stay positive");
FOC_STATIC_ASSERT(FOC_CURRENT_KI_PU / FOC_CURRENT_KP_PU < 1.0,
                  "CURRENT_KI_V_PER_AS / CURRENT_KP_V_PER_A too high for the "
                  "anti-windup gain");
FOC_STATIC_ASSERT(FOC_SPEED_KP_PU < 16384.0,
                  "SPEED_KP_A_PER_RPM overflows its per-unit gain format");
FOC_STATIC_ASSERT(FOC_SPEED_KI_PU < 32768.0,
                  "SPEED_KI_A_PER_RPM_S overflows its per-unit gain format");
FOC_STATIC_ASSERT(FOC_SPEED_KI_PU / FOC_SPEED_KP_PU < 1.0,
                  "SPEED_KI_A_PER_RPM_S / SPEED_KP_A_PER_RPM too high for the "
                  "anti-windup gain");
FOC_STATIC_ASSERT(FOC_SPEED_HUNT_TRIP_TICKS + FOC_SPEED_HUNT_SWING_TICKS <= 255u,
                  "CONTROL_SLOW_DIVIDER too small for the speed loop's hunting count");
FOC_STATIC_ASSERT(FOC_SPEED_RAMP_STEP15 >= 1 && FOC_TUNING_RAMP_STEP15 >= 1,
                  "SPEED_RAMP_RPM_PER_S / TUNING_RAMP_RPM_PER_S too small");
FOC_STATIC_ASSERT(FOC_SPEED_RAMP_STEP_PU < 0.5,
                  "SPEED_RAMP_RPM_PER_S too high for the slow tick");
FOC_STATIC_ASSERT(VOLTAGE_LIMIT_FRACTION > 0.0 && VOLTAGE_LIMIT_FRACTION <= 1.0,
                  "VOLTAGE_LIMIT_FRACTION must be in (0, 1]");
FOC_STATIC_ASSERT(CONTROL_SLOW_DIVIDER >= 1 && CONTROL_SLOW_DIVIDER <= 100,
                  "CONTROL_SLOW_DIVIDER must be 1..100");
FOC_STATIC_ASSERT(CALIB_TIME_S / FOC_SLOW_TS_S < 65535.0 &&
                  CALIB_TIME_S * PWM_FREQUENCY_HZ >= 1024.0,
                  "CALIB_TIME_S must cover at least 1024 PWM periods");
FOC_STATIC_ASSERT(SPEED_FILTER_TIME_S >= 0.0, "SPEED_FILTER_TIME_S must be >= 0");
FOC_STATIC_ASSERT(FOC_LPROBE_DV_V < FOC_LPROBE_V_ROOM_V,
                  "the alignment's inductance probe needs more voltage than the bus "
                  "gives at STARTUP_ALIGN_CURRENT_A (MOTOR_LD_H, MOTOR_RS_OHM)");
FOC_STATIC_ASSERT(2.0 * FOC_RS_PU < 32768.0, "MOTOR_RS_OHM too high for the per-unit format");
FOC_STATIC_ASSERT(2.0 * FOC_LS_DT_PU < 32768.0,
                  "MOTOR_LQ_H too high for the per-unit format at PWM_FREQUENCY_HZ");
FOC_STATIC_ASSERT(FOC_PLL_TRACK_GAIN_Q14 >= 4 && FOC_PLL_TRACK_GAIN_Q14 < 16384,
                  "PLL flux tracking: STARTUP_MIN_SPEED_RPM x poles too low or too high "
                  "for the PWM frequency");
FOC_STATIC_ASSERT(FOC_KFI_PU > 1.0 / 8192.0 && 4.0 * FOC_PLL_INV_KFI_PU < 32768.0,
                  "MOTOR_KE_VPK_PER_KRPM too low for SPEED_BASE_RPM and the bus voltage");
FOC_STATIC_ASSERT(FOC_KFI_PU < 32768.0, "MOTOR_KE_VPK_PER_KRPM too high");
FOC_STATIC_ASSERT(PLL_EMF_FILTER_TIME_S >= 0.0 && PLL_SPEED_FILTER_TIME_S >= 0.0,
                  "PLL filter time constants must be >= 0");
FOC_STATIC_ASSERT(PLL_LOW_SPEED_RPM >= 0.0 && PLL_LOW_SPEED_RPM < SPEED_BASE_RPM,
                  "PLL_LOW_SPEED_RPM out of range");
FOC_STATIC_ASSERT(PWM_DEADTIME_S >= 0.0 && PWM_DEADTIME_S * PWM_FREQUENCY_HZ < 0.1,
                  "PWM_DEADTIME_S must be under 10 % of the PWM period");
FOC_STATIC_ASSERT(DEADTIME_EFFECTIVE_S >= 0.0 && DEADTIME_EFFECTIVE_S * PWM_FREQUENCY_HZ < 0.1,
                  "DEADTIME_EFFECTIVE_S must be under 10 % of the PWM period");
FOC_STATIC_ASSERT(DEADTIME_COMP_CURRENT_A > 0.0 && FOC_DT_INV_SOFT_PU < 32768.0,
                  "DEADTIME_COMP_CURRENT_A out of range");
FOC_STATIC_ASSERT(DEADTIME_MIN_CURRENT_A >= 0.0 && DEADTIME_MIN_CURRENT_A <= CURRENT_LIMIT_A / 4.0,
                  "DEADTIME_MIN_CURRENT_A must be 0 .. CURRENT_LIMIT_A / 4");
FOC_STATIC_ASSERT(FOC_DT_INV_RIPPLE_PU < 32768.0,
                  "PWM ripple band too narrow for the per-unit format (MOTOR_LD_H/LQ_H)");
FOC_STATIC_ASSERT(STARTUP_CONV_TESTS >= 1 && STARTUP_CONV_TESTS <= 255,
                  "STARTUP_CONV_TESTS must be 1..255");
FOC_STATIC_ASSERT(STARTUP_TIMEOUT_S / FOC_SLOW_TS_S < 65000.0 && STALL_TICKS < 32000 &&
                  FAULT_ACK_MIN_TIME_S / FOC_SLOW_TS_S < 65000.0,
                  "STARTUP_TIMEOUT_S, STALL_TICKS or FAULT_ACK_MIN_TIME_S too long");
FOC_STATIC_ASSERT(STARTUP_ALIGN_CURRENT_A <= CURRENT_LIMIT_A &&
                  STARTUP_CURRENT_FIRST_A <= CURRENT_LIMIT_A &&
                  STARTUP_CURRENT_FINAL_A <= CURRENT_LIMIT_A,
                  "start-up currents must be within CURRENT_LIMIT_A");
FOC_STATIC_ASSERT(STARTUP_MIN_SPEED_RPM < STARTUP_FINAL_SPEED_RPM * STARTUP_SPEED_WINDOW_MAX,
                  "STARTUP_MIN_SPEED_RPM cannot be reached by the open-loop ramp");
FOC_STATIC_ASSERT(UNDERVOLTAGE_V + BUS_HYSTERESIS_V < BOARD_VDC_NOMINAL_V &&
                  OVERVOLTAGE_V - BUS_HYSTERESIS_V > BOARD_VDC_NOMINAL_V &&
                  1.2 * OVERVOLTAGE_V < BOARD_VDC_FULL_SCALE_V,
                  "bus thresholds must bracket BOARD_VDC_NOMINAL_V within the ADC range");
FOC_STATIC_ASSERT(BRAKE_RESISTOR_OFF_V < BRAKE_RESISTOR_ON_V,
                  "BRAKE_RESISTOR_OFF_V must be below BRAKE_RESISTOR_ON_V");
FOC_STATIC_ASSERT(FW_ID_MAX_A >= 0.0 && FW_ID_MAX_A <= CURRENT_LIMIT_A,
                  "FW_ID_MAX_A must be within [0, CURRENT_LIMIT_A]");
FOC_STATIC_ASSERT(FW_VOLTAGE_MARGIN > 0.5 && FW_VOLTAGE_MARGIN <= 1.0,
                  "FW_VOLTAGE_MARGIN must be in (0.5, 1]");
FOC_STATIC_ASSERT(FOC_FW_KP_PU > 0.0 && FOC_FW_KP_PU < 16384.0 && FOC_FW_KI_PU < 1.0 &&
                  FOC_FW_KI_PU / FOC_FW_KP_PU < 1.0,
                  "FW_VOLTAGE_KP_A_PER_V / FW_VOLTAGE_KI_A_PER_VS out of range");
FOC_STATIC_ASSERT(FW_START_RPM > 0.0 && FW_END_RPM > FW_START_RPM && FW_END_RPM < SPEED_BASE_RPM,
                  "need 0 < FW_START_RPM < FW_END_RPM < SPEED_BASE_RPM");
FOC_STATIC_ASSERT(FOC_FW_POS_GAIN_PU < 32768.0, "FW_END_RPM - FW_START_RPM too small");
FOC_STATIC_ASSERT(STOP_SPEED_RPM >= 0.0 && STOP_SPEED_RPM < SPEED_BASE_RPM,
                  "STOP_SPEED_RPM out of range");

/* ------------------------------------------------------- supervision -- */
/* Defaults for parameters older userparms.h files do not have. */
#ifndef MOTOR_THERMAL_TIME_S
#define MOTOR_THERMAL_TIME_S 20.0 /* winding thermal time constant, s */
#endif
#ifndef OVERSPEED_MARGIN
#define OVERSPEED_MARGIN 0.1 /* overspeed fault above (1 + margin) x max speed */
#endif
/* 1: the estimators' Rs follows the warming winding in field weakening
 * (rs_adapt.h).  It trusts the build's flux, so it is for a motor whose
 * flux was measured (commissioning) and a magnet that keeps it: with the
 * flux 10-20 % off it moves Rs the wrong way (the safety campaign's fan,
 * seeds 101 and 209).  Off by default. */
#ifndef RS_ADAPTATION
#define RS_ADAPTATION 0
#endif
/* Its code is in the firmware only where RS_ADAPTATION turns it on (590
 * bytes on Cortex-M3), and in builds of every estimator (focsim), where
 * the option foc_options_t.rs_adapt chooses. */
#ifdef FOC_ALL_ESTIMATORS
#define FOC_RS_ADAPT_BUILT 1
#else
#define FOC_RS_ADAPT_BUILT (RS_ADAPTATION != 0)
#endif
/* The current-sensor gain balance (gain_balance.h): the negative-sequence
 * impedance Zn = Rs - j w L, L = (Ld + Lq) / 2, in Q15 of 2^FOC_GB_Z_SHIFT
 * per-unit (Rs, and w L at the speed base: the largest); it learns where
 * twice the electrical frequency turns at least once in 16 slow ticks
 * (the voltage's mean then rejects it, and a transient's lag turns away
 * within the hold) and stays below 0.3 x the slow-tick rate. */
#define FOC_GB_XL_BASE_PU                                                      \
    (FOC_WE_BASE_RAD_S * 0.5 * (MOTOR_LD_H + MOTOR_LQ_H) * FOC_I_BASE_A / FOC_V_BASE_V)
#define FOC_GB_Z_SHIFT                                                         \
    FOC_GAIN_SHIFT(FOC_RS_PU > FOC_GB_XL_BASE_PU ? FOC_RS_PU : FOC_GB_XL_BASE_PU)
#define FOC_GB_RS_Z Q15(FOC_RS_PU / (double)(1L << FOC_GB_Z_SHIFT))
#define FOC_GB_XL_Z Q15(FOC_GB_XL_BASE_PU / (double)(1L << FOC_GB_Z_SHIFT))
#define FOC_GB_V_TO_Z Q15(1.0 / (double)(1L << FOC_GB_Z_SHIFT)) /* a voltage in that scale */
#define FOC_GB_MIN_WE_RAD_S (2.0 * FOC_PI_D / (16.0 * FOC_SLOW_TS_S) / 2.0)
#define FOC_GB_MAX_WE_RAD_S (2.0 * FOC_PI_D * 0.3 / FOC_SLOW_TS_S / 2.0)
#define FOC_GB_MIN_SPEED Q15(FOC_GB_MIN_WE_RAD_S / FOC_WE_BASE_RAD_S)
#define FOC_GB_MAX_SPEED Q15(FOC_GB_MAX_WE_RAD_S / FOC_WE_BASE_RAD_S) /* Q15 saturates */

/* Sample to voltage: the voltage computed from the sample of period k is
 * centred SAMPLE_DELAY_PERIODS periods after that sample.  1.5 where the
 * port samples at the start of a period and the duties load at its end
 * (focsim's model); 1.0 where it samples mid-period and loads at the next
 * boundary (the STM32 port, measured by make pil: docs/pil.md). */
#ifndef SAMPLE_DELAY_PERIODS
#define SAMPLE_DELAY_PERIODS 1.5
#endif
/* The inverse Park's advance, and the share of the last command in the
 * voltage that acted between the last two samples (0 for 1.5, 1/2 for 1.0). */
#define FOC_ADVANCE_GAIN Q15(SAMPLE_DELAY_PERIODS * FOC_DTHETA_AT_BASE / 32768.0)
#define FOC_V_NEW_WEIGHT Q15(1.5 - SAMPLE_DELAY_PERIODS)
FOC_STATIC_ASSERT(SAMPLE_DELAY_PERIODS >= 1.0 && SAMPLE_DELAY_PERIODS <= 1.5,
                  "SAMPLE_DELAY_PERIODS must be in [1.0, 1.5]");

#ifndef CATCH_TIME_S
#define CATCH_TIME_S 0.04 /* start: time the estimator looks for a turning rotor */
#endif
/* CATCH lasts at least the speed statistic's 64 slow ticks; while the
 * estimate says the rotor turns but is not yet steady (its first samples
 * hold the estimator's own convergence), it waits up to twice as long. */
#define FOC_CATCH_TICKS                                                        \
    (FOC_TICKS(CATCH_TIME_S) > 64u ? FOC_TICKS(CATCH_TIME_S) : (uint16_t)64u)
#define FOC_CATCH_MAX_TICKS ((uint16_t)(2u * FOC_CATCH_TICKS))
/* CATCH's probe (controller.c, catch_probe): two shorts of the windings,
 * each after FOC_PROBE_OFF_PERIODS with the bridge off, so
 * FOC_PROBE_SPACING periods apart.  Each begins half a period after a
 * sample and ends at the next one, or at the one after (FOC_PROBE_LONG:
 * 0.5 or 1.5 periods), the longer where its current at the maximum speed
 * stays within FOC_PROBE_SHORT_MAX of the limit (the motor's parameters;
 * the plant may have half the inductance and 1.2 x the flux, 2.4 x that
 * current: the Shinano caught at its maximum speed drove 1.29 x the limit
 * in a whole period, seed 109).  The shorter current is a third as far
 * above the ADC's noise, so a motor that allows the longer keeps it (the
 * Hurst075 caught at 1000 rpm: 4 codes in half a period).
 * A rotor is taken on the probe when the
 * first short drove at least the current of a rotor at
 * STARTUP_MIN_SPEED_RPM (FOC_IREF_STEP_EMF_PU is a whole period's at that
 * speed, x FOC_PROBE_SHORT_PERIODS), and at least FOC_PROBE_NOISE_CODES ADC codes (2 codes of noise
 * stay 3 sigma below it); Q15 of the current base, compared squared, / 4
 * as probe_mag2.  Twice the minimum speed's current (before) let the
 * Shinano's rotor at 10 % of its maximum speed (400 rpm, 1.25 x its
 * minimum) slip through to the estimator from rest, which locked too late
 * (tools/flying_start.py).
 * The speed is the angle turned from one short to the other, so the
 * shorts are as far apart as a rotor at the overspeed limit allows for a
 * quarter turn (half a turn would alias), 8 .. 64 periods: each short's
 * angle has the noise of a current of a few ADC codes (+-6 deg at 10
 * codes), which on the 8 periods of before (the Hurst075 caught at 1172
 * rpm, 0.088 A) gave the speed 56 % high. */
#define FOC_PROBE_SHORT_MAX 0.4
/* a whole period's short at the maximum speed, A */
#define FOC_PROBE_PERIOD_AT_MAX_A                                              \
    (MOTOR_KE_VPK_PER_KRPM / FOC_SQRT3_D * MOTOR_MAX_SPEED_RPM / 1000.0 * FOC_TS_S / \
     (MOTOR_LD_H < MOTOR_LQ_H ? MOTOR_LD_H : MOTOR_LQ_H))
#define FOC_PROBE_LONG                                                         \
    ((uint8_t)(1.5 * FOC_PROBE_PERIOD_AT_MAX_A <= FOC_PROBE_SHORT_MAX * CURRENT_LIMIT_A))
/* the short in periods; the sample that ends it (1, 2 after the one it
 * follows); a quarter of its length in periods, x 4 (the rotor's advance
 * from the short's middle to its end) */
#define FOC_PROBE_SHORT_PERIODS (FOC_PROBE_LONG != 0u ? 1.5 : 0.5)
#define FOC_PROBE_END ((uint8_t)(FOC_PROBE_LONG != 0u ? 2u : 1u))
#define FOC_PROBE_ADVANCE_X4 ((FOC_PROBE_LONG != 0u) ? (int32_t)3 : (int32_t)1)
#define FOC_PROBE_OFF_PERIODS 4u
#define FOC_PROBE_TURN_AT_OVERSPEED                                            \
    (FOC_DTHETA_AT_BASE * MOTOR_MAX_SPEED_RPM * (1.0 + OVERSPEED_MARGIN) / SPEED_BASE_RPM)
#define FOC_PROBE_SPACING_D (16384.0 / FOC_PROBE_TURN_AT_OVERSPEED)
#define FOC_PROBE_SPACING                                                      \
    ((uint8_t)(FOC_PROBE_SPACING_D < 8.0 ? 8.0 : FOC_PROBE_SPACING_D > 64.0 ? 64.0 : FOC_PROBE_SPACING_D))
#define FOC_PROBE_NOISE_CODES 6.0
#define FOC_PROBE_NOISE_PU (FOC_PROBE_NOISE_CODES * 65536.0 / (double)(1L << BOARD_ADC_BITS))
#define FOC_PROBE_MIN_CURRENT                                                  \
    ((int32_t)(FOC_IREF_STEP_EMF_PU * FOC_PROBE_SHORT_PERIODS > FOC_PROBE_NOISE_PU \
                   ? FOC_IREF_STEP_EMF_PU * FOC_PROBE_SHORT_PERIODS                \
                   : FOC_PROBE_NOISE_PU))
#define FOC_PROBE_MIN_MAG2 ((FOC_PROBE_MIN_CURRENT * FOC_PROBE_MIN_CURRENT) >> 2)
#define FOC_PROBE_SPEED_PER_ANGLE_PU (32768.0 / FOC_DTHETA_AT_BASE)
#define FOC_PROBE_SPEED_MANT FOC_GAIN_MANT(FOC_PROBE_SPEED_PER_ANGLE_PU)
#define FOC_PROBE_SPEED_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_PROBE_SPEED_PER_ANGLE_PU))
FOC_STATIC_ASSERT(FOC_PROBE_MIN_CURRENT >= 1 && FOC_PROBE_MIN_CURRENT < 16384,
                  "CATCH probe: STARTUP_MIN_SPEED_RPM's one-period short current out of range");
FOC_STATIC_ASSERT(FOC_PROBE_SPACING * FOC_DTHETA_AT_BASE * MOTOR_MAX_SPEED_RPM *
                          (1.0 + OVERSPEED_MARGIN) / SPEED_BASE_RPM < 32768.0,
                  "CATCH probe: PWM_FREQUENCY_HZ below 16 x the electrical frequency at "
                  "the overspeed limit");
/* The speed command is clamped to +-MOTOR_MAX_SPEED_RPM. */
#define FOC_MAX_SPEED FOC_SPEED_Q15(MOTOR_MAX_SPEED_RPM)
/* A sensorless command below SENSORLESS_MIN_SPEED_RPM (not 0) is raised to
 * it, sign kept.  By default the lowest speed the estimators carry the
 * loop at: STARTUP_MIN_SPEED_RPM (also where STOP leaves the rotor), and
 * no lower than where the back-EMF is FOC_DT_EMF_MARGIN x the dead time's
 * fundamental, (4/pi) Vdc t_dead f_pwm (a square wave of the dead-time
 * voltage per phase).  Below either a dead time or a resistance off by
 * the campaign's envelope is a large part of the back-EMF, and the
 * estimates drift or limit-cycle unseen (docs/safety.md).  Near zero
 * current the switched bridge's dead-time error is a near step, not the
 * ripple band's slope (docs/estimators.md): on `plant realistic` the
 * Hurst075 unloaded after a sensorless start tripped SPEED_FEEDBACK at
 * 250 rpm (back-EMF 0.86 x that fundamental) and ran at 300 (1.03 x);
 * the margin 1.2 puts its floor at 351 rpm.  0 lets every command
 * through, for a motor whose parameters are known well. */
#define FOC_DT_EMF_MARGIN 1.2
#define FOC_DT_FLOOR_RPM_PER_S                                                 \
    (FOC_DT_EMF_MARGIN * (4.0 / FOC_PI_D) * BOARD_VDC_NOMINAL_V * PWM_FREQUENCY_HZ /   \
     (FOC_FLUX_WB * MOTOR_POLE_PAIRS * 2.0 * FOC_PI_D / 60.0))
#define FOC_DT_FLOOR_RPM (DEADTIME_EFFECTIVE_S * FOC_DT_FLOOR_RPM_PER_S)
#ifndef SENSORLESS_MIN_SPEED_RPM
FOC_STATIC_ASSERT(DEADTIME_EFFECTIVE_S * FOC_DT_FLOOR_RPM_PER_S <= MOTOR_MAX_SPEED_RPM,
                  "PWM_DEADTIME_S (DEADTIME_EFFECTIVE_S): at MOTOR_MAX_SPEED_RPM the back-EMF is "
                  "below 1.2 x the dead time's voltage, no speed where the estimators hold; "
                  "shorten the dead time or define SENSORLESS_MIN_SPEED_RPM");
#define SENSORLESS_MIN_SPEED_RPM                                               \
    ((FOC_DT_FLOOR_RPM > STARTUP_MIN_SPEED_RPM) ? FOC_DT_FLOOR_RPM : STARTUP_MIN_SPEED_RPM)
#endif
#define FOC_SENSORLESS_MIN_SPEED FOC_SPEED_Q15(SENSORLESS_MIN_SPEED_RPM)
FOC_STATIC_ASSERT(FOC_DT_MIN_RAMP_PU < 32768.0 && FOC_DT_MIN_PER_SPEED_PU < 32768.0,
                  "DEADTIME_MIN_CURRENT_A: the floor's slopes beyond the gain format");
#define FOC_OVERSPEED FOC_SPEED_Q15(MOTOR_MAX_SPEED_RPM * (1.0 + OVERSPEED_MARGIN))
#define FOC_OVERSPEED_TICKS FOC_TICKS(0.002)
/* I2t: (I / I_rated)^2, Q20 (1.0 = rated), from the Q15 sum of squares of
 * the dq current (1.0 = I_base^2): x 2^5 (I_base / I_rated)^2 as a
 * normalised constant (I_base / I_rated up to 22); filtered with
 * k = Ts_slow / tau, Q30.  Trips at 1.0 (the rated current held for ever
 * never trips; 1.5 x rated after 0.59 tau), acknowledged below 0.5. */
#define FOC_I2T_X (32.0 * (FOC_I_BASE_A / MOTOR_RATED_CURRENT_A) *                 \
                   (FOC_I_BASE_A / MOTOR_RATED_CURRENT_A))
#define FOC_I2T_MANT FOC_NORM_MANT(FOC_I2T_X)
#define FOC_I2T_RSHIFT FOC_NORM_RSHIFT(FOC_I2T_X)
#define FOC_I2T_K_Q30 ((int32_t)(FOC_SLOW_TS_S / MOTOR_THERMAL_TIME_S * 1073741824.0 + 0.5))
#define FOC_I2T_TRIP ((int32_t)0x100000) /* 2^20 */
#define FOC_I2T_CLEAR ((int32_t)0x80000) /* 2^19 */
/* A rotor that does not follow: the speed loop at its current limit, the
 * speed below 7/8 of the command and not gaining on it, for this long
 * (two windows, above and below 10 % of the maximum speed; the speed loop
 * needs some tens of ms to reach its limit, inside the 200 / 500 ms of
 * docs/safety.md). */
#define FOC_FOLLOW_FAST_S 0.06
#define FOC_FOLLOW_SLOW_S 0.20
#define FOC_FOLLOW_FAST_TICKS FOC_TICKS(FOC_FOLLOW_FAST_S)
#define FOC_FOLLOW_SLOW_TICKS FOC_TICKS(FOC_FOLLOW_SLOW_S)
#define FOC_FOLLOW_SPEED_SPLIT FOC_SPEED_Q15(0.1 * MOTOR_MAX_SPEED_RPM)
/* Gaining: the mean speed moves toward the command's direction by this
 * per window: 0.2 % of the maximum speed + 1 rpm (above the estimate's
 * noise), kept between a tenth and a half of what the largest inertia
 * FOLLOW_INERTIA_MAX_KGM2 gains at the current limit in a window.  Half
 * at most: a fan with 20 x its rotor's inertia gains 3 rpm in a fast
 * window, the 4 rpm asked of it tripped SPEED_FEEDBACK on a rotor that
 * followed.  A tenth at least: a rotor gaining less carries a load of 90 %
 * of the limit's torque or more, whatever its inertia within the
 * envelope; less asked let an estimate drifting 40 rpm a window on a
 * rotor held at rest run on (the Hurst075's PLL at 1.4 x the dead time
 * and 1.18 x the resistance, a load of 2.2 x the limit's torque: seed
 * 5484). */
#ifndef FOLLOW_INERTIA_MAX_KGM2
#define FOLLOW_INERTIA_MAX_KGM2 (20.0 * MOTOR_INERTIA_KGM2)
#endif
#define FOC_FOLLOW_ACCEL_MIN_RPM_S                                             \
    (1.5 * MOTOR_POLE_PAIRS * FOC_FLUX_WB * CURRENT_LIMIT_A * (1.0 - CURRENT_REF_MARGIN) / \
     FOLLOW_INERTIA_MAX_KGM2 * 60.0 / (2.0 * FOC_PI_D))
#define FOC_FOLLOW_NOISE_RPM (0.002 * MOTOR_MAX_SPEED_RPM + 1.0)
#define FOC_FOLLOW_GAIN_MAX_RPM(window_s) (FOC_FOLLOW_ACCEL_MIN_RPM_S * (window_s))
#define FOC_FOLLOW_PROGRESS_RPM(window_s)                                      \
    ((0.5 * FOC_FOLLOW_GAIN_MAX_RPM(window_s) < FOC_FOLLOW_NOISE_RPM)          \
         ? 0.5 * FOC_FOLLOW_GAIN_MAX_RPM(window_s)                             \
     : (0.1 * FOC_FOLLOW_GAIN_MAX_RPM(window_s) > FOC_FOLLOW_NOISE_RPM)        \
         ? 0.1 * FOC_FOLLOW_GAIN_MAX_RPM(window_s)                             \
         : FOC_FOLLOW_NOISE_RPM)
/* Beyond this speed the fast step lets no current drive the rotor
 * further (a load let go at the maximum speed: the speed loop acts a slow
 * tick and its filter later): the maximum plus twice the estimate's noise,
 * so a speed loop holding the maximum is not chopped. */
#define FOC_DRIVE_CUT_SPEED FOC_SPEED_Q15(MOTOR_MAX_SPEED_RPM + 2.0 * FOC_FOLLOW_NOISE_RPM)
/* The check trips below three quarters of that progress: a margin for the
 * estimate's error in the difference of two windows' means, so a rotor
 * gaining just the progress is not tripped (seed 893: the fan gaining
 * 1.72 rpm a window against the 1.6 asked, its estimate's window means
 * within 0.2 rpm of the true ones, tripped at one window of 1.51). */
#define FOC_FOLLOW_TRIP_FAST FOC_SPEED_Q15(0.75 * FOC_FOLLOW_PROGRESS_RPM(FOC_FOLLOW_FAST_S))
#define FOC_FOLLOW_TRIP_SLOW FOC_SPEED_Q15(0.75 * FOC_FOLLOW_PROGRESS_RPM(FOC_FOLLOW_SLOW_S))
FOC_STATIC_ASSERT(FOC_FOLLOW_TRIP_FAST >= 2,
                  "FOLLOW_INERTIA_MAX_KGM2 too large for the follow check's resolution");
FOC_STATIC_ASSERT(FOC_FOLLOW_SLOW_TICKS < 16384 && FOC_FOLLOW_FAST_TICKS < 16384,
                  "CONTROL_SLOW_DIVIDER too small for the follow windows");
/* Transitional states end within their time (else coast, or a fault):
 * STOP and BRAKE the ramp from the maximum speed plus 0.4 s, a reversal's
 * ramp down the same; STOP also 0.4 s after its own ramp reached zero. */
#define FOC_STOP_SETTLE_S 0.4
#define FOC_STOP_SETTLE_TICKS FOC_TICKS(FOC_STOP_SETTLE_S)
#define FOC_RAMP_DOWN_TICKS                                                    \
    FOC_TICKS(MOTOR_MAX_SPEED_RPM / SPEED_RAMP_RPM_PER_S + FOC_STOP_SETTLE_S)
/* A reversal's ramp down goes on for another window while the rotor slows
 * by at least the follow check's progress rate (0.2 % of the maximum speed
 * + 1 rpm per 60 ms) over the window: a large inertia at the current limit
 * (the campaign's fan at 2.3 x its inertia: 411 rpm/s). */
#define FOC_REVERSAL_PROGRESS                                                  \
    FOC_SPEED_Q15((0.002 * MOTOR_MAX_SPEED_RPM + 1.0) *                            \
                  (MOTOR_MAX_SPEED_RPM / SPEED_RAMP_RPM_PER_S + FOC_STOP_SETTLE_S) / 0.06)

FOC_STATIC_ASSERT(CURRENT_REF_MARGIN >= 0.0 && CURRENT_REF_MARGIN < 0.5,
                  "CURRENT_REF_MARGIN must be in [0, 0.5)");
FOC_STATIC_ASSERT(MOTOR_THERMAL_TIME_S > 0.0 && FOC_I2T_K_Q30 >= 1 &&
                  FOC_I2T_K_Q30 < 1073741824,
                  "MOTOR_THERMAL_TIME_S out of range (0, 10^5 s]");
FOC_STATIC_ASSERT(MOTOR_RATED_CURRENT_A > 0.0 && MOTOR_RATED_CURRENT_A <= FOC_I_BASE_A &&
                  FOC_NORM_OK(FOC_I2T_X),
                  "MOTOR_RATED_CURRENT_A must be in [BOARD_CURRENT_FULL_SCALE_A / 22, "
                  "BOARD_CURRENT_FULL_SCALE_A]");
FOC_STATIC_ASSERT(OVERSPEED_MARGIN > 0.0 &&
                  MOTOR_MAX_SPEED_RPM * (1.0 + OVERSPEED_MARGIN) < SPEED_BASE_RPM,
                  "OVERSPEED_MARGIN must be > 0 with (1 + margin) x max speed below "
                  "SPEED_BASE_RPM");
FOC_STATIC_ASSERT(FOC_RAMP_DOWN_TICKS < 65000, "SPEED_RAMP_RPM_PER_S too slow");
FOC_STATIC_ASSERT(FOC_COMM_RS_Q20 > 0 && FOC_RS_PU < 1000.0 &&
                  FOC_WE_BASE_RAD_S * MOTOR_LQ_H * FOC_I_BASE_A / FOC_V_BASE_V < 1000.0 &&
                  FOC_WE_BASE_RAD_S * MOTOR_LD_H * FOC_I_BASE_A / FOC_V_BASE_V < 1000.0,
                  "commissioning: Rs or a reactance beyond 1000 per-unit (commission.c)");
FOC_STATIC_ASSERT(FOC_COMM_MECH_LOW >= FOC_STARTUP_MIN_SPEED && FOC_COMM_MECH_HIGH > FOC_COMM_MECH_LOW + FOC_COMM_MECH_LOW / 4,
                  "commissioning's inertia step: the low and high speeds (FOC_COMM_MECH_*_RPM) too close or too low");
FOC_STATIC_ASSERT(FOC_COMM_MECH_WINDOW_TICKS <= 32767 && FOC_COMM_MECH_J_SUM > 1000 &&
                      (double)FOC_COMM_MECH_J_SUM < 536870912.0,
                  "commissioning's inertia step: the ramp too slow (inertia too large for the current limit) or the inertia's sum out of range");
FOC_STATIC_ASSERT(FOC_COMM_TS_TAU_D_Q20 < 1048576 && FOC_COMM_TS_TAU_Q_Q20 < 1048576,
                  "commissioning: L / Rs shorter than a PWM period");
FOC_STATIC_ASSERT(FOC_COMM_PULSE_DV_D > 0 && FOC_COMM_PULSE_DV_Q > 0 &&
                  FOC_COMM_PULSE_DV_D < 16384 && FOC_COMM_PULSE_DV_Q < 16384,
                  "commissioning: the inductance pulse's voltage out of range");
FOC_STATIC_ASSERT(FOC_COMM_PULSE_SUM_D > 64 && FOC_COMM_PULSE_SUM_Q > 64 &&
                  (double)FOC_COMM_PULSE_SUM_D < 536870912.0 && (double)FOC_COMM_PULSE_SUM_Q < 536870912.0,
                  "commissioning: the inductance regression sum out of range");
FOC_STATIC_ASSERT(SENSORLESS_MIN_SPEED_RPM >= 0.0 && SENSORLESS_MIN_SPEED_RPM <= MOTOR_MAX_SPEED_RPM,
                  "SENSORLESS_MIN_SPEED_RPM must be in [0, MOTOR_MAX_SPEED_RPM]");

#endif /* FOC_CONFIG_H */
