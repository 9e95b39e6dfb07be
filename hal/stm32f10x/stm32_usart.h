/*
 * USART1 (PA9 TX, PA10 RX), 8N1, polled: the monitor runs in the main
 * loop, so neither direction needs an interrupt.
 */
#ifndef STM32_USART_H
#define STM32_USART_H

#include <stdint.h>

void stm32_usart_init(uint32_t pclk_hz, uint32_t baud);

/* Sends a NUL-terminated string (waits for room in the transmitter). */
void stm32_usart_write(const char *s);

/* Received byte 0..255, or -1 if none is waiting. */
int stm32_usart_getc(void);

/* 1 when the transmitter can take a byte now (stm32_usart_putc will not
 * wait). */
uint8_t stm32_usart_tx_ready(void);

/* Sends one byte; call when stm32_usart_tx_ready() says so. */
void stm32_usart_putc(uint8_t b);

#endif /* STM32_USART_H */
