#include "stm32_iwdg.h"
#include "stm32f10x_regs.h"

#define KEY_START  0xCCCCu
#define KEY_ACCESS 0x5555u
#define KEY_RELOAD 0xAAAAu
#define PRESCALER_DIV32 3u /* 40 kHz / 32 = 1.25 kHz */

void stm32_iwdg_start(uint32_t timeout_ms)
{
    uint32_t reload = timeout_ms * 5u / 4u;
    if (reload < 1u) {
        reload = 1u;
    }
    if (reload > 0xFFFu) {
        reload = 0xFFFu;
    }
    IWDG->KR = KEY_START;
    IWDG->KR = KEY_ACCESS;
    IWDG->PR = PRESCALER_DIV32;
    IWDG->RLR = reload;
    while (IWDG->SR != 0u) { /* prescaler and reload updates done */
    }
    IWDG->KR = KEY_RELOAD;
}

void stm32_iwdg_refresh(void)
{
    IWDG->KR = KEY_RELOAD;
}
