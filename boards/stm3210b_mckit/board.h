/*
 * Board facts of ST's STM3210B-MCKIT: the STM3210B-EVAL board (STM32F103VB,
 * 8 MHz crystal) with the MB459 three-shunt inverter on its motor-control
 * connector.  The analog scaling the core needs (current and bus full
 * scale, temperature sensor) is in userparms.h; this file holds what only
 * the port and main.c use.  Sources are in docs/boards/stm3210b_mckit.md.
 */
#ifndef BOARD_H
#define BOARD_H

/* ------------------------------------------------------------- clocks -- */
#define BOARD_HSE_HZ            8000000u  /* X1 crystal */
#define BOARD_SYSCLK_HZ         72000000u /* HSE x 9 */

/* -------------------------------------------------- inverter (TIM1) -- */
/* TIM1 full remap: CH1/1N/2/2N/3/3N on PE9/PE8/PE11/PE10/PE13/PE12, BKIN on
 * PE15 (active low, MB459 over-current / emergency stop).  CH4 is used
 * internally as the ADC trigger; its pin (PE14) is left an input. */
#define BOARD_BKIN_PORT         GPIOE
#define BOARD_BKIN_PIN          15u

/* Shunt reading: time from a switching edge until the amplifier output is
 * usable, besides the dead time (ST's power-stage figure for this board,
 * TRISE/TNOISE 2550 ns), and the ADC sampling time per conversion. */
#define BOARD_CURRENT_SETTLE_S  2.55e-6
#define BOARD_ADC_SAMPLE_CYCLES 7.5       /* SMPx = 001 at 12 MHz */
#define BOARD_ADC_SMP_CODE      1u
#define BOARD_ADC_CLOCK_HZ      12000000u /* PCLK2 / 6 */
/* Trigger-to-sampling latency of an injected conversion, ADC clocks. */
#define BOARD_ADC_LATENCY_CYCLES 3.0

/* ------------------------------------------------- analog inputs (ADC) -- */
#define BOARD_ADC_CH_IA         11u       /* PC1: phase A shunt amplifier */
#define BOARD_ADC_CH_IB         12u       /* PC2: phase B */
#define BOARD_ADC_CH_IC         13u       /* PC3: phase C */
#define BOARD_ADC_CH_VBUS       3u        /* PA3: bus voltage divider */
#define BOARD_ADC_CH_TEMP       10u       /* PC0: heatsink NTC */
#define BOARD_ADC_CH_POT        14u       /* PC4: EVAL board potentiometer */
/* The shunt amplifiers' output falls for current into the motor (ST's
 * library computes I = offset - reading). */
#define BOARD_CURRENT_INVERTED  1u

/* ---------------------------------------------------- "DAC" (TIM3) -- */
/* TIM3 CH3 on PB0, CH4 on PB1; 72 MHz / 1024 = 70 kHz PWM, filter it with
 * an RC of about 10 kOhm / 10 nF for the oscilloscope. */
#define BOARD_DAC_ARR           1023u

/* --------------------------------------------------- digital I/O -- */
#define BOARD_BRAKE_PORT        GPIOD     /* brake resistor switch, */
#define BOARD_BRAKE_PIN         13u       /* active high (MB459) */
#define BOARD_LED_PORT          GPIOC     /* LD1..LD4 on PC6..PC9, */
#define BOARD_LED_RUN           6u        /* active high */
#define BOARD_LED_FAULT         7u
#define BOARD_LED_CALIB         8u
#define BOARD_LED_CLOCK         9u
#define BOARD_KEY_PORT          GPIOB     /* "Key" push-button: start/stop */
#define BOARD_KEY_PIN           9u        /* low when pressed */
#define BOARD_SEL_PORT          GPIOD     /* joystick select: acknowledge */
#define BOARD_SEL_PIN           12u       /* low when pressed */

/* ------------------------------------------------------- monitor -- */
#define BOARD_USART_BAUD        115200u   /* USART1, PA9 TX / PA10 RX (CN6) */

/* ------------------------------------------------------- watchdog -- */
#define BOARD_IWDG_TIMEOUT_MS   100u      /* at the nominal 40 kHz LSI */

#endif /* BOARD_H */
