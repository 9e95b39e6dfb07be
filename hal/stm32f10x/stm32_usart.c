#include "stm32_usart.h"
#include "stm32_gpio.h"
#include "stm32f10x_regs.h"

void stm32_usart_init(uint32_t pclk_hz, uint32_t baud)
{
    RCC->APB2ENR |= RCC_APB2ENR_USART1EN | RCC_APB2ENR_IOPAEN;
    stm32_gpio_mode(GPIOA, 9u, STM32_GPIO_AF_PP_2MHZ);
    stm32_gpio_mode(GPIOA, 10u, STM32_GPIO_IN_FLOATING);
    /* 16x oversampling: BRR = f / baud with 4 fraction bits, which is the
     * rounded quotient itself. */
    USART1->BRR = (uint16_t)((pclk_hz + baud / 2u) / baud);
    USART1->CR1 = USART_CR1_UE | USART_CR1_TE | USART_CR1_RE;
}

void stm32_usart_write(const char *s)
{
    while (*s != '\0') {
        while ((USART1->SR & USART_SR_TXE) == 0u) {
        }
        USART1->DR = (uint16_t)(uint8_t)*s++;
    }
}

int stm32_usart_getc(void)
{
    const uint32_t sr = USART1->SR;
    if ((sr & (USART_SR_RXNE | USART_SR_ORE)) == 0u) {
        return -1;
    }
    /* Reading DR after SR also clears an overrun. */
    /* cppcheck-suppress misra-c2012-10.8 ; D4 value in range */
    return (int)(USART1->DR & 0xFFu);
}

uint8_t stm32_usart_tx_ready(void)
{
    return (uint8_t)(((USART1->SR & USART_SR_TXE) != 0u) ? 1u : 0u);
}

void stm32_usart_putc(uint8_t b)
{
    USART1->DR = (uint16_t)b;
}
