/*
 * Independent watchdog (LSI, nominally 40 kHz, 30..60 kHz over parts and
 * temperature).  Once started it cannot be stopped; the port refreshes it
 * from the slow tick only while the control interrupt keeps running.
 */
#ifndef STM32_IWDG_H
#define STM32_IWDG_H

#include <stdint.h>

/* Starts the watchdog with about timeout_ms (4..3276 ms at 40 kHz). */
void stm32_iwdg_start(uint32_t timeout_ms);

void stm32_iwdg_refresh(void);

#endif /* STM32_IWDG_H */
