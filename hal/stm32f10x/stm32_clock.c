#include "stm32_clock.h"
#include "board.h"
#include "stm32f10x_regs.h"

#define HSI_HZ 8000000u
/* Polling loops of a few cycles each at 8 MHz: about 100 ms, against a
 * typical crystal start-up of a few milliseconds. */
#define START_TIMEOUT_LOOPS 200000u
#define PLL_MULTIPLIER (BOARD_SYSCLK_HZ / BOARD_HSE_HZ)
#define FLASH_WAIT_STATES 2u /* 48 MHz < SYSCLK <= 72 MHz (RM0008 FLASH_ACR) */

#if PLL_MULTIPLIER * BOARD_HSE_HZ != BOARD_SYSCLK_HZ || PLL_MULTIPLIER != 9u
#error "stm32_clock.c sets the PLL to x9: BOARD_SYSCLK_HZ must be 9 x BOARD_HSE_HZ"
#endif

static uint32_t clock_hz = HSI_HZ;

static uint8_t wait_set(const volatile uint32_t *reg, uint32_t mask, uint32_t value)
{
    for (uint32_t n = 0; n < START_TIMEOUT_LOOPS; n++) {
        if ((*reg & mask) == value) {
            return 1u;
        }
    }
    return 0u;
}

/* Back to the reset state: HSI, PLL and HSE off, no wait states. */
static uint8_t fall_back(void)
{
    RCC->CFGR &= ~RCC_CFGR_SW;
    (void)wait_set(&RCC->CFGR, RCC_CFGR_SWS, 0u);
    RCC->CR &= ~(RCC_CR_PLLON | RCC_CR_HSEON);
    FLASH->ACR = 0u;
    clock_hz = HSI_HZ;
    return 0u;
}

uint8_t stm32_clock_init(void)
{
    RCC->CR |= RCC_CR_HSEON;
    if (!wait_set(&RCC->CR, RCC_CR_HSERDY, RCC_CR_HSERDY)) {
        return fall_back();
    }
    FLASH->ACR = FLASH_ACR_PRFTBE | FLASH_WAIT_STATES;
    /* HPRE = PPRE2 = 1, PPRE1 = 2 (APB1 <= 36 MHz), ADC = PCLK2 / 6. */
    RCC->CFGR = RCC_CFGR_PPRE1_DIV2 | RCC_CFGR_ADCPRE_DIV6 | RCC_CFGR_PLLSRC |
                RCC_CFGR_PLLMULL9;
    RCC->CR |= RCC_CR_PLLON;
    if (!wait_set(&RCC->CR, RCC_CR_PLLRDY, RCC_CR_PLLRDY)) {
        return fall_back();
    }
    RCC->CFGR = (RCC->CFGR & ~RCC_CFGR_SW) | RCC_CFGR_SW_PLL;
    if (!wait_set(&RCC->CFGR, RCC_CFGR_SWS, RCC_CFGR_SWS_PLL)) {
        return fall_back();
    }
    RCC->CR |= RCC_CR_CSSON;
    clock_hz = BOARD_SYSCLK_HZ;
    return 1u;
}

uint32_t stm32_clock_hz(void)
{
    return clock_hz;
}
