/*
 * GPIO pin configuration (RM0008 GPIOx_CRL/CRH: four bits per pin, MODE
 * and CNF) and output writes.  Configuration is read-modify-write: call it
 * before the interrupts that touch the same port are enabled.
 */
#ifndef STM32_GPIO_H
#define STM32_GPIO_H

#include <stdint.h>
#include "stm32f10x_regs.h"

#define STM32_GPIO_ANALOG        0x0u /* analog input */
#define STM32_GPIO_IN_FLOATING   0x4u /* input, no pull */
#define STM32_GPIO_OUT_PP_2MHZ   0x2u /* push-pull output */
#define STM32_GPIO_AF_PP_2MHZ    0xAu /* alternate function, push-pull */
#define STM32_GPIO_AF_PP_50MHZ   0xBu

static inline void stm32_gpio_mode(GPIO_TypeDef *g, uint32_t pin, uint32_t mode)
{
    __IO uint32_t *cr = (pin < 8u) ? &g->CRL : &g->CRH;
    const uint32_t shift = (pin & 7u) * 4u;
    *cr = (*cr & ~(0xFu << shift)) | (mode << shift);
}

static inline void stm32_gpio_write(GPIO_TypeDef *g, uint32_t pin, uint8_t high)
{
    /* BSRR sets, BRR resets: single atomic stores. */
    if (high != 0u) {
        g->BSRR = 1ul << pin;
    } else {
        g->BRR = 1ul << pin;
    }
}

static inline uint8_t stm32_gpio_read(const GPIO_TypeDef *g, uint32_t pin)
{
    return (uint8_t)((g->IDR >> pin) & 1u);
}

#endif /* STM32_GPIO_H */
