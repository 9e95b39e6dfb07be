/*
 * Clock tree: 72 MHz from the crystal (HSE x 9 through the PLL), AHB and
 * APB2 72 MHz, APB1 36 MHz, ADC 12 MHz, two flash wait states with the
 * prefetch buffer.  The clock security system is switched on: if the
 * crystal stops later, the hardware falls back to the internal oscillator
 * and raises the NMI (startup_stm32f10x.c turns the bridge off there).
 */
#ifndef STM32_CLOCK_H
#define STM32_CLOCK_H

#include <stdint.h>

/* Returns 1 with the system at 72 MHz.  Returns 0 if the crystal or the PLL
 * did not start within the timeout: the system then stays on the internal
 * 8 MHz oscillator, and the motor must not be run (the PWM and control
 * constants assume 72 MHz). */
uint8_t stm32_clock_init(void);

/* System (= AHB = APB2) clock in Hz as set by stm32_clock_init(). */
uint32_t stm32_clock_hz(void);

#endif /* STM32_CLOCK_H */
