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
#define FOC_STATIC_ASSERT(cond, msg) _Static_assert(cond, msg)

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
/* PI gains in per-unit: volts per ampere x I_BASE / V_BASE; Ki per PWM
 * period. */
#define FOC_CURRENT_KP_PU (CURRENT_KP_V_PER_A * FOC_I_BASE_A / FOC_V_BASE_V)
#define FOC_CURRENT_KI_PU                                                      \
    (CURRENT_KI_V_PER_AS * FOC_TS_S * FOC_I_BASE_A / FOC_V_BASE_V)
#define FOC_CURRENT_KP_MANT FOC_GAIN_MANT(FOC_CURRENT_KP_PU)
#define FOC_CURRENT_KP_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_CURRENT_KP_PU))
#define FOC_CURRENT_KI Q15(FOC_CURRENT_KI_PU)
/* Back-calculation gain: Ki/Kp (the PI's own zero), the usual choice. */
#define FOC_CURRENT_KC Q15(FOC_CURRENT_KI_PU / FOC_CURRENT_KP_PU)
#define FOC_CURRENT_LIMIT FOC_I_Q15(CURRENT_LIMIT_A)
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
/* Reference slew per slow tick, Q15 speed (at least 1 LSB). */
#define FOC_SPEED_RAMP_STEP_PU (SPEED_RAMP_RPM_PER_S * FOC_SLOW_TS_S / SPEED_BASE_RPM)
#define FOC_SPEED_RAMP_STEP                                                    \
    ((q15_t)(FOC_SPEED_RAMP_STEP_PU * 32768.0 < 1.0                            \
                 ? 1 : (int32_t)(FOC_SPEED_RAMP_STEP_PU * 32768.0 + 0.5)))
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
 * per Q15 speed count.  Rounding error below 0.02 % for any base speed that
 * passes the 90-degrees-per-period check. */
#define FOC_THETA32_PER_SPEED ((int32_t)(2.0 * FOC_DTHETA_AT_BASE + 0.5))
/* Angle turned in half a PWM period at speed 1.0, as a Q15 gain (< 0.25). */
#define FOC_HALF_PERIOD_ANGLE Q15(0.5 * FOC_DTHETA_AT_BASE / 32768.0)

/* ------------------------------------------------- machine constants -- */
/* Per-unit winding resistance, inductance per PWM period and back-EMF per
 * unit speed (the normalisation of AN1292 equations 5 and 6 in our bases). */
#define FOC_RS_PU (MOTOR_RS_OHM * FOC_I_BASE_A / FOC_V_BASE_V)
#define FOC_LS_DT_PU (MOTOR_LQ_H * FOC_I_BASE_A / (FOC_V_BASE_V * FOC_TS_S))
#define FOC_KFI_PU (FOC_FLUX_WB * FOC_WE_BASE_RAD_S / FOC_V_BASE_V)
#define FOC_INV_KFI_PU (1.0 / FOC_KFI_PU)
/* Largest current change in one period the winding allows (full voltage
 * across Ls), Q15 of the current base: the di/dt limit of the estimator. */
#define FOC_DI_MAX Q15(FOC_V_BASE_V * FOC_TS_S / MOTOR_LQ_H / FOC_I_BASE_A)

/* -------------------------------------------------- PLL estimator -- */
#define FOC_PLL_RS_MANT FOC_GAIN_MANT(FOC_RS_PU)
#define FOC_PLL_RS_SHIFT ((uint8_t)FOC_GAIN_SHIFT(FOC_RS_PU))
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
#define FOC_SENSORED_HANDOVER_SPEED FOC_SPEED_Q15(SENSORED_HANDOVER_RPM)

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

/* -------------------------------------------------------------- bus -- */
/* Nominal bus in bus-ADC counts; the modulation compensation is
 * Vdc_nominal / Vdc_measured in Q14 (up to 2.0). */
#define FOC_VDC_NOMINAL FOC_VDC_Q15(BOARD_VDC_NOMINAL_V)
#define FOC_VDC_FILTER_K Q15(0.05)

/* ------------------------------------------------------- calibration -- */
#define FOC_CALIB_PERIODS_LOG2 10 /* 1024 periods averaged for the offsets */
#define FOC_CALIB_TICKS ((uint16_t)(CALIB_TIME_S / FOC_SLOW_TS_S + 0.5))

/* ------------------------------------------------------------ checks -- */
FOC_STATIC_ASSERT(MOTOR_POLE_PAIRS >= 1 && MOTOR_POLE_PAIRS <= 64,
                  "MOTOR_POLE_PAIRS must be 1..64");
FOC_STATIC_ASSERT(CURRENT_LIMIT_A > 0.0 && CURRENT_LIMIT_A < BOARD_CURRENT_FULL_SCALE_A,
                  "CURRENT_LIMIT_A must be below BOARD_CURRENT_FULL_SCALE_A");
FOC_STATIC_ASSERT(BOARD_VDC_NOMINAL_V < BOARD_VDC_FULL_SCALE_V,
                  "BOARD_VDC_NOMINAL_V must be below BOARD_VDC_FULL_SCALE_V");
FOC_STATIC_ASSERT(MOTOR_MAX_SPEED_RPM < SPEED_BASE_RPM,
                  "SPEED_BASE_RPM must exceed MOTOR_MAX_SPEED_RPM");
FOC_STATIC_ASSERT(FOC_DTHETA_AT_BASE < 16384.0,
                  "SPEED_BASE_RPM x MOTOR_POLE_PAIRS too high for PWM_FREQUENCY_HZ "
                  "(more than 90 electrical degrees per PWM period)");
FOC_STATIC_ASSERT(FOC_CURRENT_KP_PU < 32768.0,
                  "CURRENT_KP_V_PER_A overflows its per-unit gain format");
FOC_STATIC_ASSERT(FOC_CURRENT_KI_PU < 1.0,
                  "CURRENT_KI_V_PER_AS too high: Ki per PWM period must be < 1 pu");
FOC_STATIC_ASSERT(FOC_CURRENT_KI_PU / FOC_CURRENT_KP_PU < 1.0,
                  "CURRENT_KI_V_PER_AS / CURRENT_KP_V_PER_A too high for the "
                  "anti-windup gain");
FOC_STATIC_ASSERT(FOC_SPEED_KP_PU < 32768.0,
                  "SPEED_KP_A_PER_RPM overflows its per-unit gain format");
FOC_STATIC_ASSERT(FOC_SPEED_KI_PU < 32768.0,
                  "SPEED_KI_A_PER_RPM_S overflows its per-unit gain format");
FOC_STATIC_ASSERT(FOC_SPEED_KI_PU / FOC_SPEED_KP_PU < 1.0,
                  "SPEED_KI_A_PER_RPM_S / SPEED_KP_A_PER_RPM too high for the "
                  "anti-windup gain");
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
FOC_STATIC_ASSERT(FOC_RS_PU < 32768.0, "MOTOR_RS_OHM too high for the per-unit format");
FOC_STATIC_ASSERT(2.0 * FOC_LS_DT_PU < 32768.0,
                  "MOTOR_LQ_H too high for the per-unit format at PWM_FREQUENCY_HZ");
FOC_STATIC_ASSERT(FOC_KFI_PU > 1.0 / 8192.0 && 4.0 * FOC_PLL_INV_KFI_PU < 32768.0,
                  "MOTOR_KE_VPK_PER_KRPM too low for SPEED_BASE_RPM and the bus voltage");
FOC_STATIC_ASSERT(FOC_KFI_PU < 32768.0, "MOTOR_KE_VPK_PER_KRPM too high");
FOC_STATIC_ASSERT(PLL_EMF_FILTER_TIME_S >= 0.0 && PLL_SPEED_FILTER_TIME_S >= 0.0,
                  "PLL filter time constants must be >= 0");
FOC_STATIC_ASSERT(PLL_LOW_SPEED_RPM >= 0.0 && PLL_LOW_SPEED_RPM < SPEED_BASE_RPM,
                  "PLL_LOW_SPEED_RPM out of range");
FOC_STATIC_ASSERT(FW_ID_MAX_A >= 0.0 && FW_ID_MAX_A <= CURRENT_LIMIT_A,
                  "FW_ID_MAX_A must be within [0, CURRENT_LIMIT_A]");
FOC_STATIC_ASSERT(FW_VOLTAGE_MARGIN > 0.5 && FW_VOLTAGE_MARGIN <= 1.0,
                  "FW_VOLTAGE_MARGIN must be in (0.5, 1]");
FOC_STATIC_ASSERT(FOC_FW_KP_PU > 0.0 && FOC_FW_KP_PU < 32768.0 && FOC_FW_KI_PU < 1.0 &&
                  FOC_FW_KI_PU / FOC_FW_KP_PU < 1.0,
                  "FW_VOLTAGE_KP_A_PER_V / FW_VOLTAGE_KI_A_PER_VS out of range");
FOC_STATIC_ASSERT(FW_START_RPM > 0.0 && FW_END_RPM > FW_START_RPM && FW_END_RPM < SPEED_BASE_RPM,
                  "need 0 < FW_START_RPM < FW_END_RPM < SPEED_BASE_RPM");
FOC_STATIC_ASSERT(FOC_FW_POS_GAIN_PU < 32768.0, "FW_END_RPM - FW_START_RPM too small");
FOC_STATIC_ASSERT(STOP_SPEED_RPM >= 0.0 && STOP_SPEED_RPM < SPEED_BASE_RPM,
                  "STOP_SPEED_RPM out of range");

#endif /* FOC_CONFIG_H */
