/*
 * Vector table and reset handler for arm-none-eabi-gcc (no assembler, no
 * C library start-up).  The table is placed first in flash by
 * stm32f10x.ld; its length follows the device density macro (ST's names:
 * STM32F10X_LD/MD: 43 interrupts, HD/XL: 60, CL: 68).  Handlers the port
 * does not define turn the bridge off and wait for the watchdog.
 */
#include <stdint.h>

#include "stm32_vectors.h"
#include "stm32f10x_regs.h"

#if defined(STM32F10X_CL)
#define IRQ_COUNT 68
#elif defined(STM32F10X_HD) || defined(STM32F10X_XL)
#define IRQ_COUNT 60
#else
#define IRQ_COUNT 43
#endif

/* Linker script symbols. */
extern uint32_t _estack;
extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss;

typedef union {
    void (*handler)(void);
    const void *stack_top;
} vector_t;

#define DEF { Default_Handler }

extern const vector_t vector_table[16 + IRQ_COUNT]; /* declared before its definition (8.4) */
__attribute__((section(".isr_vector"), used))
const vector_t vector_table[16 + IRQ_COUNT] = {
    { .stack_top = &_estack },
    { Reset_Handler },
    { NMI_Handler },
    { HardFault_Handler },
    DEF, DEF, DEF,            /* MemManage, BusFault, UsageFault */
    { 0 }, { 0 }, { 0 }, { 0 },
    DEF, DEF,                 /* SVCall, DebugMonitor */
    { 0 },
    DEF,                      /* PendSV */
    { SysTick_Handler },
    /* IRQ 0..17: WWDG, PVD, TAMPER, RTC, FLASH, RCC, EXTI0..4, DMA1 1..7 */
    DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF,
    DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF,
    { ADC1_2_IRQHandler },    /* 18 */
    DEF, DEF, DEF, DEF, DEF,  /* 19..23: USB/CAN TX, RX0, RX1, SCE, EXTI9_5 */
    { TIM1_BRK_IRQHandler },  /* 24 */
    { TIM1_UP_IRQHandler },   /* 25 */
    /* 26..42: TIM1 TRG/COM, TIM1 CC, TIM2..4, I2C1/2, SPI1/2, USART1..3,
     * EXTI15_10, RTC alarm, USB wake-up */
    DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF,
    DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF,
#if IRQ_COUNT > 43
    /* 43..59: TIM8, ADC3, FSMC, SDIO, TIM5, SPI3, UART4/5, TIM6/7, DMA2 */
    DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF,
    DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF,
#endif
#if IRQ_COUNT > 60
    /* 60..67: DMA2 ch4/5, ETH, ETH wake-up, CAN2, OTG FS (connectivity) */
    DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF,
#endif
};

static void bridge_off(void)
{
    TIM1->BDTR = (uint16_t)(TIM1->BDTR & (uint16_t)~TIM_BDTR_MOE);
}

/* The loops stay loops: no memcpy/memset call before .data and .bss
 * exist, and no library copy routine linked for them alone. */
__attribute__((optimize("no-tree-loop-distribute-patterns")))
void Reset_Handler(void)
{
    const uint32_t *src = &_sidata;
    uint32_t *dst = &_sdata;
    while (dst < &_edata) {
        *dst++ = *src++;
    }
    dst = &_sbss;
    while (dst < &_ebss) {
        *dst++ = 0u;
    }
    SCB->VTOR = (uint32_t)(uintptr_t)vector_table;
    (void)main();
    for (;;) {
    }
}

/* Clock security system: the crystal failed, the hardware switched to the
 * internal oscillator, every rate is now wrong: stop for good. */
void NMI_Handler(void)
{
    bridge_off();
    RCC->CIR = RCC_CIR_CSSC;
    for (;;) {
    }
}

void HardFault_Handler(void)
{
    bridge_off();
    for (;;) {
    }
}

void Default_Handler(void)
{
    bridge_off();
    for (;;) {
    }
}
