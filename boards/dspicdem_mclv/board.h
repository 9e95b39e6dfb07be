/*
 * dsPICDEM MCLV (DM330021) with the dsPIC33FJ32MC204 plug-in module: the
 * board facts the dsPIC port and main.c use.  Motor and application
 * parameters, and the analog full scales the core needs (current, bus,
 * ADC), are in userparms.h (the repository's userparms.h.in holds this
 * board's values); this file adds clocks, pins, ADC channels, interrupt
 * priorities and the user interface.  docs/boards/dspicdem_mclv.md gives
 * the source of each figure and marks the ones to verify on the board.
 *
 * No register access here: main.c and hal/dspic33fj/dspic33fj.c turn these
 * numbers into register values.
 */
#ifndef BOARD_H
#define BOARD_H

#include "foc/config.h"

#define BOARD_NAME "dsPICDEM MCLV + dsPIC33FJ32MC204"

/* ------------------------------------------------------------ clock -- */
/* 8 MHz crystal (XT) on the board, PLL: Fosc = Fin x M / (N1 x N2) =
 * 8 MHz x 40 / (2 x 2) = 80 MHz, Fcy = Fosc / 2 = 40 MIPS.
 * PLLPRE = N1 - 2, PLLFBD = M - 2, PLLPOST: 0 for N2 = 2. */
#define BOARD_XTAL_HZ 8000000uL
#define BOARD_PLL_N1 2u
#define BOARD_PLL_M 40u
#define BOARD_PLL_N2 2u
#define BOARD_FOSC_HZ (BOARD_XTAL_HZ * BOARD_PLL_M / (BOARD_PLL_N1 * BOARD_PLL_N2))
#define BOARD_FCY_HZ (BOARD_FOSC_HZ / 2u)

/* PLL limits of the dsPIC33FJ32MC204 data sheet: 0.8..8 MHz at the phase
 * detector, 100..200 MHz VCO, Fcy at most 40 MIPS. */
FOC_STATIC_ASSERT(BOARD_XTAL_HZ / BOARD_PLL_N1 >= 800000uL &&
                  BOARD_XTAL_HZ / BOARD_PLL_N1 <= 8000000uL,
                  "BOARD_PLL_N1: PLL input must be 0.8..8 MHz");
FOC_STATIC_ASSERT(BOARD_XTAL_HZ / BOARD_PLL_N1 * BOARD_PLL_M >= 100000000uL &&
                  BOARD_XTAL_HZ / BOARD_PLL_N1 * BOARD_PLL_M <= 200000000uL,
                  "BOARD_PLL_M: VCO must be 100..200 MHz");
FOC_STATIC_ASSERT(BOARD_FCY_HZ <= 40000000uL, "BOARD_FCY_HZ above 40 MIPS");
FOC_STATIC_ASSERT(BOARD_PLL_N2 == 2u, "main.c sets PLLPOST for N2 = 2 only");

/* ------------------------------------------------------------- PWM -- */
/* MCPWM1, centre-aligned (continuous up/down), complementary pairs
 * PWM1H1/L1 (RB14/RB15) phase A, H2/L2 (RB12/RB13) B, H3/L3 (RB10/RB11)
 * C, active high on both sides (FPOR HPOL/LPOL).  PTPER = Fcy/(2 Fpwm) - 1
 * (999 at 40 MIPS, 20 kHz); 100 % duty = PDC 2 (PTPER + 1) = 2000. */
#define BOARD_PWM_HZ ((uint32_t)(PWM_FREQUENCY_HZ + 0.5))
#define BOARD_PTPER ((uint16_t)(BOARD_FCY_HZ / (2u * BOARD_PWM_HZ) - 1u))
#define BOARD_DEADTIME_TCY ((uint16_t)(PWM_DEADTIME_S * (double)BOARD_FCY_HZ + 0.5))

/* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
FOC_STATIC_ASSERT(BOARD_FCY_HZ % (2u * BOARD_PWM_HZ) == 0u,
                  "PWM_FREQUENCY_HZ: Fcy / (2 Fpwm) must be a whole number "
                  "of instruction cycles");
/* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
FOC_STATIC_ASSERT(BOARD_FCY_HZ / (2u * BOARD_PWM_HZ) >= 3u &&
                  BOARD_FCY_HZ / (2u * BOARD_PWM_HZ) <= 0x7FFFu,
                  "PWM_FREQUENCY_HZ out of the MCPWM period range");
/* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
FOC_STATIC_ASSERT(PWM_DEADTIME_S * (double)BOARD_FCY_HZ <= 504.0,
                  "PWM_DEADTIME_S above 63 x 8 Tcy");

/* ADC trigger: the special event comparator at PTMR = PTPER - offset while
 * counting up, i.e. just before the centre of the low-side pulses, where
 * the shunt currents are read. */
#define BOARD_ADC_TRIGGER_OFFSET_TCY 1u

/* Fault A: the board's over-current comparator, active low, on RP8 (RB8,
 * pin 44), routed to FLTA1 by peripheral pin select. */
#define BOARD_FLTA_RP 8u
#define BOARD_FLTA_PORTB_MASK ((uint16_t)1u << 8)

/* ------------------------------------------------------------- ADC -- */
/* Simultaneous sampling of CH0..CH3, 10-bit, signed fractional:
 * CH0 = AN8 potentiometer (RC2), CH1 = AN0 phase A current (RA0),
 * CH2 = AN1 phase B current (RA1), CH3 = AN2 bus voltage (RB0).
 * Results: ADC1BUF0 = CH0 .. ADC1BUF3 = CH3. */
#define BOARD_ADC_CH0_AN 8u
#define BOARD_ADC_ANALOG_PINS ((1u << 0) | (1u << 1) | (1u << 2) | ((uint16_t)1u << 8))
#define BOARD_ADC_BUF_POT 0u
#define BOARD_ADC_BUF_IA 1u
#define BOARD_ADC_BUF_IB 2u
#define BOARD_ADC_BUF_VDC 3u
/* TAD = (ADCS + 1) Tcy = 100 ns at 40 MIPS (>= 76 ns for 10-bit); four
 * conversions of 12 TAD: 4.8 us after the trigger. */
#define BOARD_ADC_ADCS 3u
/* The current amplifiers' output falls as current flows into the motor
 * (AN1292's KCURRA = KCURRB = Q15(-0.5) carry the same minus sign). */
#define BOARD_CURRENT_INVERTED 1u

FOC_STATIC_ASSERT(BOARD_ADC_BITS == 10, "the dsPIC port runs the ADC in 10-bit mode");
FOC_STATIC_ASSERT((BOARD_ADC_ADCS + 1u) * 1000000000uL / BOARD_FCY_HZ >= 76u,
                  "BOARD_ADC_ADCS: TAD below 76 ns");

/* ------------------------------------------------------ time bases -- */
/* Timer2/3 as one free-running 32-bit timer at Fcy: foc_port_timestamp()
 * ticks of 25 ns, wrapping after 107 s. */
#define BOARD_TIMESTAMP_HZ BOARD_FCY_HZ
#define BOARD_TICKS_PER_MS (BOARD_TIMESTAMP_HZ / 1000u)

/* Interrupt priorities (7 highest; the main loop runs at 0).  The fault
 * input needs none: the MCPWM turns the outputs off by itself. */
#define BOARD_IPL_FAST 6u /* ADC1 end of conversion: foc_fast_step */
#define BOARD_IPL_SLOW 3u /* Timer1 vector, software-triggered: foc_slow_step */

/* Watchdog: LPRC 32 kHz / 32 (WDTPRE) / 64 (WDTPOST) = 64 ms. */
#define BOARD_WDT_MS 64u

/* ---------------------------------------------------------- UART1 -- */
/* RS-232 through the board's level shifter. */
#define BOARD_UART_BAUD 115200uL
#define BOARD_U1RX_RP 19u /* RC3 */
#define BOARD_U1TX_RP 20u /* RC4 */
#define BOARD_U1RX_TRISC_MASK (1u << 3)
#define BOARD_U1TX_TRISC_MASK (1u << 4)

/* ------------------------------------------------ buttons and LEDs -- */
/* Push buttons, active low (pressed = 0): S2 on RA8, S3 on RB4. */
#define BOARD_S2_PORTA_MASK ((uint16_t)1u << 8)
#define BOARD_S3_PORTB_MASK (1u << 4)
/* LEDs, active high: "run" on RA10, "field-weakening range" on RA7. */
#define BOARD_LED_RUN_LATA_MASK ((uint16_t)1u << 10)
#define BOARD_LED_FW_LATA_MASK (1u << 7)

/* ---------------------------------------------------- speed command -- */
/* The potentiometer sets the speed from BOARD_POT_MIN_RPM (sensorless
 * estimation needs some speed) to the motor's nominal speed, or to its
 * maximum in the field-weakening range that S3 toggles. */
#define BOARD_POT_MIN_RPM 500L
#define BOARD_POT_MAX_RPM ((int32_t)(MOTOR_NOMINAL_SPEED_RPM + 0.5))
#define BOARD_POT_MAX_FW_RPM ((int32_t)(MOTOR_MAX_SPEED_RPM + 0.5))
#define BOARD_SPEED_BASE_RPM ((int32_t)(SPEED_BASE_RPM + 0.5))

FOC_STATIC_ASSERT(SPEED_BASE_RPM >= 1.0 && SPEED_BASE_RPM <= 65535.0,
                  "the monitor converts rpm with SPEED_BASE_RPM in 1..65535");
/* cppcheck-suppress misra-c2012-10.8 ; D2 compile-time constant */
FOC_STATIC_ASSERT(BOARD_POT_MIN_RPM <= BOARD_POT_MAX_RPM &&
                  BOARD_POT_MAX_RPM <= BOARD_POT_MAX_FW_RPM,
                  "BOARD_POT_MIN_RPM must not exceed MOTOR_NOMINAL_SPEED_RPM");

#endif /* BOARD_H */
