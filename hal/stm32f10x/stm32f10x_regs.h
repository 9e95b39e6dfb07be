/*
 * Minimal STM32F10x register map for the FOC port, written from the
 * reference manual RM0008 and the Cortex-M3 technical reference manual.
 *
 * Names, structure layouts and bit masks follow ST's CMSIS device header
 * (stm32f10x.h) and CMSIS-Core (core_cm3.h), so the port builds against
 * either: define FOC_STM32_VENDOR_CMSIS (and put ST's CMSIS device and core
 * include folders on the include path, with the density macro such as
 * STM32F10X_MD) to use ST's header instead of this one; for STM32Cube's
 * headers also define FOC_STM32_VENDOR_HEADER as "stm32f1xx.h" and the
 * device macro (STM32F103xB).  Only what the port uses is here; the port
 * uses nothing that ST's device header lacks.  CMSIS-Core 1.x (core_cm3.h
 * V1.30 of ST's standard peripheral library 3.5.0) leaves two things to the
 * application, supplied below: the DWT block (added in CMSIS-Core 2.0), and
 * __get_PRIMASK/__set_PRIMASK, which it declares extern for GCC and defines
 * in core_cm3.c, a file this project does not build.
 *
 * tests/ports/test_stm32_regs.c checks every address, register offset and
 * constant here against values written from RM0008; the same table can be
 * run against ST's headers (docs/porting.md).
 *
 * Register structures use ST's standard-peripheral layout (16-bit timer and
 * USART registers padded to 32 bits); the offsets are the same in ST's
 * STM32Cube headers, which declare them 32 bits wide.
 */
#ifndef STM32F10X_REGS_H
#define STM32F10X_REGS_H

#ifdef FOC_STM32_VENDOR_CMSIS
#ifndef FOC_STM32_VENDOR_HEADER
#define FOC_STM32_VENDOR_HEADER "stm32f10x.h"
#endif
#include FOC_STM32_VENDOR_HEADER

/* DWT cycle counter (ARMv7-M ARM C1.8), which CMSIS-Core 1.x lacks. */
#ifndef DWT
typedef struct {
    __IO uint32_t CTRL;
    __IO uint32_t CYCCNT;
} foc_stm32_dwt_t;
#define DWT ((foc_stm32_dwt_t *)0xE0001000u)
#endif
#ifndef DWT_CTRL_CYCCNTENA_Msk
#define DWT_CTRL_CYCCNTENA_Msk (1ul << 0)
#endif

#else

#include <stdint.h>

/* cppcheck-suppress misra-c2012-21.1 ; D5 toolchain name */
#define __IO volatile
/* cppcheck-suppress misra-c2012-21.1 ; D5 toolchain name */
#define __NVIC_PRIO_BITS 4u

/* ------------------------------------------------------ interrupt numbers */
/* (no HardFault_IRQn: the port does not use it and CMSIS 1.x device
 * headers, ST's StdPeriph 3.5.0 among them, do not define it) */
typedef enum {
    NonMaskableInt_IRQn = -14,
    SysTick_IRQn = -1,
    ADC1_2_IRQn = 18,
    TIM1_BRK_IRQn = 24,
    TIM1_UP_IRQn = 25
} IRQn_Type;

/* ------------------------------------------------------------ peripherals */
typedef struct {
    __IO uint16_t CR1;   uint16_t RESERVED0;
    __IO uint16_t CR2;   uint16_t RESERVED1;
    __IO uint16_t SMCR;  uint16_t RESERVED2;
    __IO uint16_t DIER;  uint16_t RESERVED3;
    __IO uint16_t SR;    uint16_t RESERVED4;
    __IO uint16_t EGR;   uint16_t RESERVED5;
    __IO uint16_t CCMR1; uint16_t RESERVED6;
    __IO uint16_t CCMR2; uint16_t RESERVED7;
    __IO uint16_t CCER;  uint16_t RESERVED8;
    __IO uint16_t CNT;   uint16_t RESERVED9;
    __IO uint16_t PSC;   uint16_t RESERVED10;
    __IO uint16_t ARR;   uint16_t RESERVED11;
    __IO uint16_t RCR;   uint16_t RESERVED12;
    __IO uint16_t CCR1;  uint16_t RESERVED13;
    __IO uint16_t CCR2;  uint16_t RESERVED14;
    __IO uint16_t CCR3;  uint16_t RESERVED15;
    __IO uint16_t CCR4;  uint16_t RESERVED16;
    __IO uint16_t BDTR;  uint16_t RESERVED17;
    __IO uint16_t DCR;   uint16_t RESERVED18;
    __IO uint16_t DMAR;  uint16_t RESERVED19;
} TIM_TypeDef;

typedef struct {
    __IO uint32_t SR;
    __IO uint32_t CR1;
    __IO uint32_t CR2;
    __IO uint32_t SMPR1;
    __IO uint32_t SMPR2;
    __IO uint32_t JOFR1;
    __IO uint32_t JOFR2;
    __IO uint32_t JOFR3;
    __IO uint32_t JOFR4;
    __IO uint32_t HTR;
    __IO uint32_t LTR;
    __IO uint32_t SQR1;
    __IO uint32_t SQR2;
    __IO uint32_t SQR3;
    __IO uint32_t JSQR;
    __IO uint32_t JDR1;
    __IO uint32_t JDR2;
    __IO uint32_t JDR3;
    __IO uint32_t JDR4;
    __IO uint32_t DR;
} ADC_TypeDef;

typedef struct {
    __IO uint32_t CR;
    __IO uint32_t CFGR;
    __IO uint32_t CIR;
    __IO uint32_t APB2RSTR;
    __IO uint32_t APB1RSTR;
    __IO uint32_t AHBENR;
    __IO uint32_t APB2ENR;
    __IO uint32_t APB1ENR;
    __IO uint32_t BDCR;
    __IO uint32_t CSR;
} RCC_TypeDef;

typedef struct {
    __IO uint32_t ACR;
    __IO uint32_t KEYR;
    __IO uint32_t OPTKEYR;
    __IO uint32_t SR;
    __IO uint32_t CR;
    __IO uint32_t AR;
    __IO uint32_t RESERVED;
    __IO uint32_t OBR;
    __IO uint32_t WRPR;
} FLASH_TypeDef;

typedef struct {
    __IO uint32_t CRL;
    __IO uint32_t CRH;
    __IO uint32_t IDR;
    __IO uint32_t ODR;
    __IO uint32_t BSRR;
    __IO uint32_t BRR;
    __IO uint32_t LCKR;
} GPIO_TypeDef;

typedef struct {
    __IO uint32_t EVCR;
    __IO uint32_t MAPR;
    __IO uint32_t EXTICR[4];
    uint32_t RESERVED0;
    __IO uint32_t MAPR2;
} AFIO_TypeDef;

typedef struct {
    __IO uint16_t SR;   uint16_t RESERVED0;
    __IO uint16_t DR;   uint16_t RESERVED1;
    __IO uint16_t BRR;  uint16_t RESERVED2;
    __IO uint16_t CR1;  uint16_t RESERVED3;
    __IO uint16_t CR2;  uint16_t RESERVED4;
    __IO uint16_t CR3;  uint16_t RESERVED5;
    __IO uint16_t GTPR; uint16_t RESERVED6;
} USART_TypeDef;

typedef struct {
    __IO uint32_t KR;
    __IO uint32_t PR;
    __IO uint32_t RLR;
    __IO uint32_t SR;
} IWDG_TypeDef;

#define PERIPH_BASE     0x40000000u
#define APB1PERIPH_BASE PERIPH_BASE
#define APB2PERIPH_BASE (PERIPH_BASE + 0x10000u)
#define AHBPERIPH_BASE  (PERIPH_BASE + 0x20000u)

#define TIM3   ((TIM_TypeDef *)(APB1PERIPH_BASE + 0x0400u))
#define IWDG   ((IWDG_TypeDef *)(APB1PERIPH_BASE + 0x3000u))
#define AFIO   ((AFIO_TypeDef *)(APB2PERIPH_BASE + 0x0000u))
#define GPIOA  ((GPIO_TypeDef *)(APB2PERIPH_BASE + 0x0800u))
#define GPIOB  ((GPIO_TypeDef *)(APB2PERIPH_BASE + 0x0C00u))
#define GPIOC  ((GPIO_TypeDef *)(APB2PERIPH_BASE + 0x1000u))
#define GPIOD  ((GPIO_TypeDef *)(APB2PERIPH_BASE + 0x1400u))
#define GPIOE  ((GPIO_TypeDef *)(APB2PERIPH_BASE + 0x1800u))
#define ADC1   ((ADC_TypeDef *)(APB2PERIPH_BASE + 0x2400u))
#define ADC2   ((ADC_TypeDef *)(APB2PERIPH_BASE + 0x2800u))
#define TIM1   ((TIM_TypeDef *)(APB2PERIPH_BASE + 0x2C00u))
#define USART1 ((USART_TypeDef *)(APB2PERIPH_BASE + 0x3800u))
#define RCC    ((RCC_TypeDef *)(AHBPERIPH_BASE + 0x1000u))
#define FLASH  ((FLASH_TypeDef *)(AHBPERIPH_BASE + 0x2000u))

/* ------------------------------------------------------------ bit masks */
/* RCC */
#define RCC_CR_HSION              ((uint32_t)0x00000001)
#define RCC_CR_HSIRDY             ((uint32_t)0x00000002)
#define RCC_CR_HSEON              ((uint32_t)0x00010000)
#define RCC_CR_HSERDY             ((uint32_t)0x00020000)
#define RCC_CR_CSSON              ((uint32_t)0x00080000)
#define RCC_CR_PLLON              ((uint32_t)0x01000000)
#define RCC_CR_PLLRDY             ((uint32_t)0x02000000)
#define RCC_CFGR_SW               ((uint32_t)0x00000003)
#define RCC_CFGR_SW_PLL           ((uint32_t)0x00000002)
#define RCC_CFGR_SWS              ((uint32_t)0x0000000C)
#define RCC_CFGR_SWS_PLL          ((uint32_t)0x00000008)
#define RCC_CFGR_PPRE1_DIV2       ((uint32_t)0x00000400)
#define RCC_CFGR_ADCPRE_DIV6      ((uint32_t)0x00008000)
#define RCC_CFGR_PLLSRC           ((uint32_t)0x00010000)
#define RCC_CFGR_PLLMULL          ((uint32_t)0x003C0000)
#define RCC_CFGR_PLLMULL9         ((uint32_t)0x001C0000)
#define RCC_CIR_CSSC              ((uint32_t)0x00800000)
#define RCC_APB2ENR_AFIOEN        ((uint32_t)0x00000001)
#define RCC_APB2ENR_IOPAEN        ((uint32_t)0x00000004)
#define RCC_APB2ENR_IOPBEN        ((uint32_t)0x00000008)
#define RCC_APB2ENR_IOPCEN        ((uint32_t)0x00000010)
#define RCC_APB2ENR_IOPDEN        ((uint32_t)0x00000020)
#define RCC_APB2ENR_IOPEEN        ((uint32_t)0x00000040)
#define RCC_APB2ENR_ADC1EN        ((uint32_t)0x00000200)
#define RCC_APB2ENR_ADC2EN        ((uint32_t)0x00000400)
#define RCC_APB2ENR_TIM1EN        ((uint32_t)0x00000800)
#define RCC_APB2ENR_USART1EN      ((uint32_t)0x00004000)
#define RCC_APB1ENR_TIM3EN        ((uint32_t)0x00000002)

/* FLASH (the wait-state field LATENCY[2:0] is written as a number, see
 * stm32_clock.c; no mask for it here: RM0008's would be 0x7, ST's
 * StdPeriph 3.5.0 header defines FLASH_ACR_LATENCY as 0x03) */
#define FLASH_ACR_PRFTBE          ((uint8_t)0x10)

/* AFIO */
#define AFIO_MAPR_TIM1_REMAP_FULLREMAP ((uint32_t)0x000000C0)
#define AFIO_MAPR_SWJ_CFG              ((uint32_t)0x07000000)

/* TIM */
#define TIM_CR1_CEN               ((uint16_t)0x0001)
#define TIM_CR1_DIR               ((uint16_t)0x0010)
#define TIM_CR1_CMS_0             ((uint16_t)0x0020)
#define TIM_CR1_CMS_1             ((uint16_t)0x0040)
#define TIM_CR1_ARPE              ((uint16_t)0x0080)
#define TIM_CR2_MMS_1             ((uint16_t)0x0020)
#define TIM_DIER_UIE              ((uint16_t)0x0001)
#define TIM_DIER_BIE              ((uint16_t)0x0080)
#define TIM_SR_UIF                ((uint16_t)0x0001)
#define TIM_SR_BIF                ((uint16_t)0x0080)
#define TIM_EGR_UG                ((uint8_t)0x01)
#define TIM_CCMR1_OC1PE           ((uint16_t)0x0008)
#define TIM_CCMR1_OC1M            ((uint16_t)0x0070)
#define TIM_CCMR1_OC1M_0          ((uint16_t)0x0010)
#define TIM_CCMR1_OC1M_1          ((uint16_t)0x0020)
#define TIM_CCMR1_OC1M_2          ((uint16_t)0x0040)
#define TIM_CCMR1_OC2PE           ((uint16_t)0x0800)
#define TIM_CCMR1_OC2M            ((uint16_t)0x7000)
#define TIM_CCMR1_OC2M_0          ((uint16_t)0x1000)
#define TIM_CCMR1_OC2M_1          ((uint16_t)0x2000)
#define TIM_CCMR1_OC2M_2          ((uint16_t)0x4000)
#define TIM_CCMR2_OC3PE           ((uint16_t)0x0008)
#define TIM_CCMR2_OC3M            ((uint16_t)0x0070)
#define TIM_CCMR2_OC3M_0          ((uint16_t)0x0010)
#define TIM_CCMR2_OC3M_1          ((uint16_t)0x0020)
#define TIM_CCMR2_OC3M_2          ((uint16_t)0x0040)
#define TIM_CCMR2_OC4PE           ((uint16_t)0x0800)
#define TIM_CCMR2_OC4M            ((uint16_t)0x7000)
#define TIM_CCMR2_OC4M_0          ((uint16_t)0x1000)
#define TIM_CCMR2_OC4M_1          ((uint16_t)0x2000)
#define TIM_CCMR2_OC4M_2          ((uint16_t)0x4000)
#define TIM_CCER_CC1E             ((uint16_t)0x0001)
#define TIM_CCER_CC1NE            ((uint16_t)0x0004)
#define TIM_CCER_CC2E             ((uint16_t)0x0010)
#define TIM_CCER_CC2NE            ((uint16_t)0x0040)
#define TIM_CCER_CC3E             ((uint16_t)0x0100)
#define TIM_CCER_CC3NE            ((uint16_t)0x0400)
#define TIM_CCER_CC4E             ((uint16_t)0x1000)
#define TIM_CCER_CC4P             ((uint16_t)0x2000)
#define TIM_BDTR_DTG              ((uint16_t)0x00FF)
#define TIM_BDTR_LOCK_0           ((uint16_t)0x0100)
#define TIM_BDTR_OSSI             ((uint16_t)0x0400)
#define TIM_BDTR_OSSR             ((uint16_t)0x0800)
#define TIM_BDTR_BKE              ((uint16_t)0x1000)
#define TIM_BDTR_BKP              ((uint16_t)0x2000)
#define TIM_BDTR_MOE              ((uint16_t)0x8000)

/* ADC */
#define ADC_SR_JEOC               ((uint8_t)0x04)
#define ADC_CR1_JEOCIE            ((uint32_t)0x00000080)
#define ADC_CR1_SCAN              ((uint32_t)0x00000100)
#define ADC_CR1_DUALMOD_0         ((uint32_t)0x00010000)
#define ADC_CR1_DUALMOD_2         ((uint32_t)0x00040000)
#define ADC_CR2_ADON              ((uint32_t)0x00000001)
#define ADC_CR2_CAL               ((uint32_t)0x00000004)
#define ADC_CR2_RSTCAL            ((uint32_t)0x00000008)
#define ADC_CR2_ALIGN             ((uint32_t)0x00000800)
#define ADC_CR2_JEXTSEL           ((uint32_t)0x00007000)
#define ADC_CR2_JEXTSEL_0         ((uint32_t)0x00001000)
#define ADC_CR2_JEXTTRIG          ((uint32_t)0x00008000)

/* USART */
#define USART_SR_ORE              ((uint16_t)0x0008)
#define USART_SR_RXNE             ((uint16_t)0x0020)
#define USART_SR_TXE              ((uint16_t)0x0080)
#define USART_CR1_RE              ((uint16_t)0x0004)
#define USART_CR1_TE              ((uint16_t)0x0008)
#define USART_CR1_UE              ((uint16_t)0x2000)

/* ------------------------------------------------------ Cortex-M3 core */
typedef struct {
    __IO uint32_t CTRL;
    __IO uint32_t LOAD;
    __IO uint32_t VAL;
    __IO uint32_t CALIB;
} SysTick_Type;

typedef struct {
    __IO uint32_t ISER[8];
    uint32_t RESERVED0[24];
    __IO uint32_t ICER[8];
    uint32_t RSERVED1[24];
    __IO uint32_t ISPR[8];
    uint32_t RESERVED2[24];
    __IO uint32_t ICPR[8];
    uint32_t RESERVED3[24];
    __IO uint32_t IABR[8];
    uint32_t RESERVED4[56];
    __IO uint8_t IP[240];
    uint32_t RESERVED5[644];
    __IO uint32_t STIR;
} NVIC_Type;

typedef struct {
    __IO uint32_t CPUID;
    __IO uint32_t ICSR;
    __IO uint32_t VTOR;
    __IO uint32_t AIRCR;
    __IO uint32_t SCR;
    __IO uint32_t CCR;
    __IO uint8_t SHP[12];
    __IO uint32_t SHCSR;
    __IO uint32_t CFSR;
    __IO uint32_t HFSR;
    __IO uint32_t DFSR;
    __IO uint32_t MMFAR;
    __IO uint32_t BFAR;
    __IO uint32_t AFSR;
} SCB_Type;

typedef struct {
    __IO uint32_t DHCSR;
    __IO uint32_t DCRSR;
    __IO uint32_t DCRDR;
    __IO uint32_t DEMCR;
} CoreDebug_Type;

typedef struct {
    __IO uint32_t CTRL;
    __IO uint32_t CYCCNT;
} DWT_Type;

#define SysTick   ((SysTick_Type *)0xE000E010u)
#define NVIC      ((NVIC_Type *)0xE000E100u)
#define SCB       ((SCB_Type *)0xE000ED00u)
#define CoreDebug ((CoreDebug_Type *)0xE000EDF0u)
#define DWT       ((DWT_Type *)0xE0001000u)

#define SysTick_CTRL_ENABLE_Msk    (1ul << 0)
#define SysTick_CTRL_TICKINT_Msk   (1ul << 1)
#define SysTick_CTRL_CLKSOURCE_Msk (1ul << 2)
#define CoreDebug_DEMCR_TRCENA_Msk (1ul << 24)
#define DWT_CTRL_CYCCNTENA_Msk     (1ul << 0)

/* CMSIS-Core functions the port uses, same names and behaviour (PRIMASK:
 * below). */
static inline void NVIC_EnableIRQ(IRQn_Type irq)
{
    NVIC->ISER[(uint32_t)irq >> 5] = (uint32_t)1u << ((uint32_t)irq & 0x1Fu);
}

static inline void NVIC_SetPriority(IRQn_Type irq, uint32_t priority)
{
    const uint8_t value = (uint8_t)((priority << (8u - __NVIC_PRIO_BITS)) & 0xFFu);
    if ((int32_t)irq < 0) {
        SCB->SHP[((uint32_t)irq & 0xFu) - 4u] = value;
    } else {
        NVIC->IP[(uint32_t)irq] = value;
    }
}

static inline void __disable_irq(void)
{
    __asm volatile("cpsid i" ::: "memory");
}

static inline void __enable_irq(void)
{
    __asm volatile("cpsie i" ::: "memory");
}

#endif /* FOC_STM32_VENDOR_CMSIS */

/* __get_PRIMASK/__set_PRIMASK, inline as in CMSIS-Core 2.0 and later: for
 * the port's own map, and with CMSIS-Core 1.x, whose core_cm3.h declares
 * them extern (so a static definition of those names cannot follow; the
 * names are macros over the port's functions in both cases). */
#if !defined(FOC_STM32_VENDOR_CMSIS) || \
    (defined(__CM3_CMSIS_VERSION_MAIN) && (__CM3_CMSIS_VERSION_MAIN < 2))
static inline uint32_t foc_stm32_get_primask(void)
{
    uint32_t r;
    __asm volatile("mrs %0, primask" : "=r"(r));
    return r;
}

static inline void foc_stm32_set_primask(uint32_t m)
{
    __asm volatile("msr primask, %0" : : "r"(m) : "memory");
}

/* cppcheck-suppress misra-c2012-21.1 ; D5 toolchain name */
#define __get_PRIMASK() foc_stm32_get_primask()
/* cppcheck-suppress misra-c2012-21.1 ; D5 toolchain name */
#define __set_PRIMASK(m) foc_stm32_set_primask(m)
#endif
#endif /* STM32F10X_REGS_H */
