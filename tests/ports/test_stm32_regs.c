/*
 * STM32F10x port: the register map (hal/stm32f10x/stm32f10x_regs.h) against
 * a table of expected values written from the manuals:
 *   RM0008  STM32F101/102/103/105/107 reference manual (rev. 21): memory
 *           map, peripheral registers and their bits, interrupt numbers;
 *   PM0056  STM32F10xxx Cortex-M3 programming manual: NVIC, SCB, SysTick;
 *   PM0075  STM32F10xxx Flash programming manual: the Flash interface
 *           registers after FLASH_ACR;
 *   ARMv7-M Architecture Reference Manual (DDI 0403E): debug (DEMCR) and
 *           DWT registers.
 * Bits are written as RM0008 numbers them (bit n, field [hi:lo] = value).
 *
 * The table holds every peripheral address, named register and constant
 * that stm32f10x_regs.h defines (the port's registers and constants are all
 * among them; tests/ports/stm32_regs_coverage.py keeps it complete).  Each
 * register's offset is taken with offsetof on the structure of the
 * peripheral pointer the port uses (TIM1->CCR1), so it also holds for ST's
 * headers, whatever they name the types.
 *
 * Compiled with -DFOC_STM32_VENDOR_CMSIS and ST's CMSIS include folders the
 * same table checks ST's stm32f10x.h instead (a local check: ST's headers
 * are not part of the project; `make stm32-regs STM32_CMSIS="<dirs>"`,
 * docs/porting.md).
 */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "stm32f10x_regs.h"
#include "testkit.h"

#ifdef FOC_STM32_VENDOR_CMSIS
#define HEADER_USED "vendor header " FOC_STM32_VENDOR_HEADER
#else
#define HEADER_USED "stm32f10x_regs.h"
#endif

typedef struct {
    const char *name;   /* as the port writes it */
    long long expected; /* from the manuals */
    long long actual;   /* from the header in use */
} row_t;

/* A peripheral's base address. */
#define BASE(p, addr) { #p, (long long)(addr), (long long)(uintptr_t)(p) }
/* A register's offset in the peripheral p points to (REGN: p's name given
 * as a string, for the macros that expand p before REG would see it). */
#define REGN(name, p, r, off)                                                  \
    { name "->" #r, (long long)(off), (long long)offsetof(__typeof__(*(p)), r) }
#define REG(p, r, off) REGN(#p, p, r, off)
/* A constant: bit mask, field value, interrupt number. */
#define VAL(c, v) { #c, (long long)(v), (long long)(c) }

#define COUNT(a) (sizeof(a) / sizeof((a)[0]))

static void check_rows(const char *what, const row_t *rows, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        TK_CHECK(rows[i].actual == rows[i].expected, "%s %s: %s has 0x%llX, expected 0x%llX",
                 what, rows[i].name, HEADER_USED, (unsigned long long)rows[i].actual,
                 (unsigned long long)rows[i].expected);
    }
    printf("%s: %zu %s checked against %s\n", what, n, n == 1 ? "value" : "values", HEADER_USED);
}

/* ------------------------------------------------ memory map -- */
static void case_base_addresses(void)
{
#ifdef __CM3_CMSIS_VERSION_MAIN
    printf("%s with CMSIS-Core version macros main 0x%X, sub 0x%X\n", HEADER_USED,
           (unsigned)__CM3_CMSIS_VERSION_MAIN, (unsigned)__CM3_CMSIS_VERSION_SUB);
#endif
    const row_t rows[] = {
        /* RM0008 §3.3, table 3 (register boundary addresses) */
        VAL(PERIPH_BASE, 0x40000000u),     /* peripherals start (APB1) */
        VAL(APB1PERIPH_BASE, 0x40000000u), /* TIM2, the first APB1 block */
        VAL(APB2PERIPH_BASE, 0x40010000u), /* AFIO, the first APB2 block */
        VAL(AHBPERIPH_BASE, 0x40020000u),  /* DMA1 (ST's AHB group base) */
        BASE(TIM3, 0x40000400u),           /* TIM3 */
        BASE(IWDG, 0x40003000u),           /* IWDG */
        BASE(AFIO, 0x40010000u),           /* AFIO */
        BASE(GPIOA, 0x40010800u),          /* GPIO port A */
        BASE(GPIOB, 0x40010C00u),          /* GPIO port B */
        BASE(GPIOC, 0x40011000u),          /* GPIO port C */
        BASE(GPIOD, 0x40011400u),          /* GPIO port D */
        BASE(GPIOE, 0x40011800u),          /* GPIO port E */
        BASE(ADC1, 0x40012400u),           /* ADC1 */
        BASE(ADC2, 0x40012800u),           /* ADC2 */
        BASE(TIM1, 0x40012C00u),           /* TIM1 */
        BASE(USART1, 0x40013800u),         /* USART1 */
        BASE(RCC, 0x40021000u),            /* reset and clock control */
        BASE(FLASH, 0x40022000u),          /* Flash memory interface */
        /* PM0056 §4.1, table "core peripheral register regions" */
        BASE(SysTick, 0xE000E010u), /* §4.5 SysTick timer */
        BASE(NVIC, 0xE000E100u),    /* §4.3 NVIC */
        BASE(SCB, 0xE000ED00u),     /* §4.4 system control block */
        /* ARMv7-M ARM */
        BASE(CoreDebug, 0xE000EDF0u), /* §C1.6 debug registers (DHCSR) */
        BASE(DWT, 0xE0001000u),       /* §C1.8 DWT (DWT_CTRL) */
    };
    check_rows("base addresses", rows, COUNT(rows));
}

/* ------------------------------------------------ register offsets -- */
/* ADCx (RM0008 §11.12, register map §11.12.15) */
#define ADC_ROWS(a)                                                            \
    REGN(#a, a, SR, 0x00),    /* §11.12.1  ADC_SR */                           \
    REGN(#a, a, CR1, 0x04),   /* §11.12.2  ADC_CR1 */                          \
    REGN(#a, a, CR2, 0x08),   /* §11.12.3  ADC_CR2 */                          \
    REGN(#a, a, SMPR1, 0x0C), /* §11.12.4  ADC_SMPR1 */                        \
    REGN(#a, a, SMPR2, 0x10), /* §11.12.5  ADC_SMPR2 */                        \
    REGN(#a, a, JOFR1, 0x14), /* §11.12.6  ADC_JOFR1 */                        \
    REGN(#a, a, JOFR2, 0x18), /* §11.12.6  ADC_JOFR2 */                        \
    REGN(#a, a, JOFR3, 0x1C), /* §11.12.6  ADC_JOFR3 */                        \
    REGN(#a, a, JOFR4, 0x20), /* §11.12.6  ADC_JOFR4 */                        \
    REGN(#a, a, HTR, 0x24),   /* §11.12.7  ADC_HTR */                          \
    REGN(#a, a, LTR, 0x28),   /* §11.12.8  ADC_LTR */                          \
    REGN(#a, a, SQR1, 0x2C),  /* §11.12.9  ADC_SQR1 */                         \
    REGN(#a, a, SQR2, 0x30),  /* §11.12.10 ADC_SQR2 */                         \
    REGN(#a, a, SQR3, 0x34),  /* §11.12.11 ADC_SQR3 */                         \
    REGN(#a, a, JSQR, 0x38),  /* §11.12.12 ADC_JSQR */                         \
    REGN(#a, a, JDR1, 0x3C),  /* §11.12.13 ADC_JDR1 */                         \
    REGN(#a, a, JDR2, 0x40),  /* §11.12.13 ADC_JDR2 */                         \
    REGN(#a, a, JDR3, 0x44),  /* §11.12.13 ADC_JDR3 */                         \
    REGN(#a, a, JDR4, 0x48),  /* §11.12.13 ADC_JDR4 */                         \
    REGN(#a, a, DR, 0x4C)     /* §11.12.14 ADC_DR */

/* GPIOx (RM0008 §9.2, register map §9.5) */
#define GPIO_ROWS(g)                                                           \
    REGN(#g, g, CRL, 0x00),  /* §9.2.1 GPIOx_CRL */                            \
    REGN(#g, g, CRH, 0x04),  /* §9.2.2 GPIOx_CRH */                            \
    REGN(#g, g, IDR, 0x08),  /* §9.2.3 GPIOx_IDR */                            \
    REGN(#g, g, ODR, 0x0C),  /* §9.2.4 GPIOx_ODR */                            \
    REGN(#g, g, BSRR, 0x10), /* §9.2.5 GPIOx_BSRR */                           \
    REGN(#g, g, BRR, 0x14),  /* §9.2.6 GPIOx_BRR */                            \
    REGN(#g, g, LCKR, 0x18)  /* §9.2.7 GPIOx_LCKR */

static void case_register_offsets(void)
{
    const row_t rows[] = {
        /* TIM1 (RM0008 §14.4, register map §14.4.21) */
        REG(TIM1, CR1, 0x00),   /* §14.4.1  TIMx_CR1 */
        REG(TIM1, CR2, 0x04),   /* §14.4.2  TIMx_CR2 */
        REG(TIM1, SMCR, 0x08),  /* §14.4.3  TIMx_SMCR */
        REG(TIM1, DIER, 0x0C),  /* §14.4.4  TIMx_DIER */
        REG(TIM1, SR, 0x10),    /* §14.4.5  TIMx_SR */
        REG(TIM1, EGR, 0x14),   /* §14.4.6  TIMx_EGR */
        REG(TIM1, CCMR1, 0x18), /* §14.4.7  TIMx_CCMR1 */
        REG(TIM1, CCMR2, 0x1C), /* §14.4.8  TIMx_CCMR2 */
        REG(TIM1, CCER, 0x20),  /* §14.4.9  TIMx_CCER */
        REG(TIM1, CNT, 0x24),   /* §14.4.10 TIMx_CNT */
        REG(TIM1, PSC, 0x28),   /* §14.4.11 TIMx_PSC */
        REG(TIM1, ARR, 0x2C),   /* §14.4.12 TIMx_ARR */
        REG(TIM1, RCR, 0x30),   /* §14.4.13 TIMx_RCR */
        REG(TIM1, CCR1, 0x34),  /* §14.4.14 TIMx_CCR1 */
        REG(TIM1, CCR2, 0x38),  /* §14.4.15 TIMx_CCR2 */
        REG(TIM1, CCR3, 0x3C),  /* §14.4.16 TIMx_CCR3 */
        REG(TIM1, CCR4, 0x40),  /* §14.4.17 TIMx_CCR4 */
        REG(TIM1, BDTR, 0x44),  /* §14.4.18 TIMx_BDTR */
        REG(TIM1, DCR, 0x48),   /* §14.4.19 TIMx_DCR */
        REG(TIM1, DMAR, 0x4C),  /* §14.4.20 TIMx_DMAR */
        /* TIM3, a general-purpose timer (RM0008 §15.4, register map
         * §15.4.19; no RCR, no BDTR) */
        REG(TIM3, CR1, 0x00),   /* §15.4.1  TIMx_CR1 */
        REG(TIM3, CR2, 0x04),   /* §15.4.2  TIMx_CR2 */
        REG(TIM3, SMCR, 0x08),  /* §15.4.3  TIMx_SMCR */
        REG(TIM3, DIER, 0x0C),  /* §15.4.4  TIMx_DIER */
        REG(TIM3, SR, 0x10),    /* §15.4.5  TIMx_SR */
        REG(TIM3, EGR, 0x14),   /* §15.4.6  TIMx_EGR */
        REG(TIM3, CCMR1, 0x18), /* §15.4.7  TIMx_CCMR1 */
        REG(TIM3, CCMR2, 0x1C), /* §15.4.8  TIMx_CCMR2 */
        REG(TIM3, CCER, 0x20),  /* §15.4.9  TIMx_CCER */
        REG(TIM3, CNT, 0x24),   /* §15.4.10 TIMx_CNT */
        REG(TIM3, PSC, 0x28),   /* §15.4.11 TIMx_PSC */
        REG(TIM3, ARR, 0x2C),   /* §15.4.12 TIMx_ARR */
        REG(TIM3, CCR1, 0x34),  /* §15.4.13 TIMx_CCR1 */
        REG(TIM3, CCR2, 0x38),  /* §15.4.14 TIMx_CCR2 */
        REG(TIM3, CCR3, 0x3C),  /* §15.4.15 TIMx_CCR3 */
        REG(TIM3, CCR4, 0x40),  /* §15.4.16 TIMx_CCR4 */
        REG(TIM3, DCR, 0x48),   /* §15.4.17 TIMx_DCR */
        REG(TIM3, DMAR, 0x4C),  /* §15.4.18 TIMx_DMAR */
        ADC_ROWS(ADC1),
        ADC_ROWS(ADC2),
        GPIO_ROWS(GPIOA),
        GPIO_ROWS(GPIOB),
        GPIO_ROWS(GPIOC),
        GPIO_ROWS(GPIOD),
        GPIO_ROWS(GPIOE),
        /* AFIO (RM0008 §9.4, register map §9.5) */
        REG(AFIO, EVCR, 0x00),      /* §9.4.1 AFIO_EVCR */
        REG(AFIO, MAPR, 0x04),      /* §9.4.2 AFIO_MAPR */
        REG(AFIO, EXTICR[0], 0x08), /* §9.4.3 AFIO_EXTICR1 */
        REG(AFIO, EXTICR[1], 0x0C), /* §9.4.4 AFIO_EXTICR2 */
        REG(AFIO, EXTICR[2], 0x10), /* §9.4.5 AFIO_EXTICR3 */
        REG(AFIO, EXTICR[3], 0x14), /* §9.4.6 AFIO_EXTICR4 */
        REG(AFIO, MAPR2, 0x1C),     /* §9.4.7 AFIO_MAPR2 */
        /* RCC (RM0008 §7.3, register map §7.3.11) */
        REG(RCC, CR, 0x00),       /* §7.3.1  RCC_CR */
        REG(RCC, CFGR, 0x04),     /* §7.3.2  RCC_CFGR */
        REG(RCC, CIR, 0x08),      /* §7.3.3  RCC_CIR */
        REG(RCC, APB2RSTR, 0x0C), /* §7.3.4  RCC_APB2RSTR */
        REG(RCC, APB1RSTR, 0x10), /* §7.3.5  RCC_APB1RSTR */
        REG(RCC, AHBENR, 0x14),   /* §7.3.6  RCC_AHBENR */
        REG(RCC, APB2ENR, 0x18),  /* §7.3.7  RCC_APB2ENR */
        REG(RCC, APB1ENR, 0x1C),  /* §7.3.8  RCC_APB1ENR */
        REG(RCC, BDCR, 0x20),     /* §7.3.9  RCC_BDCR */
        REG(RCC, CSR, 0x24),      /* §7.3.10 RCC_CSR */
        /* Flash interface: FLASH_ACR in RM0008 §3.3.3, the others in
         * PM0075's register map */
        REG(FLASH, ACR, 0x00),     /* RM0008 §3.3.3 FLASH_ACR */
        REG(FLASH, KEYR, 0x04),    /* PM0075 FLASH_KEYR */
        REG(FLASH, OPTKEYR, 0x08), /* PM0075 FLASH_OPTKEYR */
        REG(FLASH, SR, 0x0C),      /* PM0075 FLASH_SR */
        REG(FLASH, CR, 0x10),      /* PM0075 FLASH_CR */
        REG(FLASH, AR, 0x14),      /* PM0075 FLASH_AR */
        REG(FLASH, OBR, 0x1C),     /* PM0075 FLASH_OBR (0x18 reserved) */
        REG(FLASH, WRPR, 0x20),    /* PM0075 FLASH_WRPR */
        /* USART1 (RM0008 §27.6, register map §27.6.8) */
        REG(USART1, SR, 0x00),   /* §27.6.1 USART_SR */
        REG(USART1, DR, 0x04),   /* §27.6.2 USART_DR */
        REG(USART1, BRR, 0x08),  /* §27.6.3 USART_BRR */
        REG(USART1, CR1, 0x0C),  /* §27.6.4 USART_CR1 */
        REG(USART1, CR2, 0x10),  /* §27.6.5 USART_CR2 */
        REG(USART1, CR3, 0x14),  /* §27.6.6 USART_CR3 */
        REG(USART1, GTPR, 0x18), /* §27.6.7 USART_GTPR */
        /* IWDG (RM0008 §19.4, register map §19.4.5) */
        REG(IWDG, KR, 0x00),  /* §19.4.1 IWDG_KR */
        REG(IWDG, PR, 0x04),  /* §19.4.2 IWDG_PR */
        REG(IWDG, RLR, 0x08), /* §19.4.3 IWDG_RLR */
        REG(IWDG, SR, 0x0C),  /* §19.4.4 IWDG_SR */
        /* SysTick (PM0056 §4.5) */
        REG(SysTick, CTRL, 0x0),  /* STK_CTRL */
        REG(SysTick, LOAD, 0x4),  /* STK_LOAD */
        REG(SysTick, VAL, 0x8),   /* STK_VAL */
        REG(SysTick, CALIB, 0xC), /* STK_CALIB */
        /* NVIC (PM0056 §4.3): register blocks, and the bytes of IPR the
         * port's interrupts use (RM0008 §10.1.2 positions 18, 24, 25) */
        REG(NVIC, ISER, 0x000),   /* NVIC_ISER0 */
        REG(NVIC, ICER, 0x080),   /* NVIC_ICER0 */
        REG(NVIC, ISPR, 0x100),   /* NVIC_ISPR0 */
        REG(NVIC, ICPR, 0x180),   /* NVIC_ICPR0 */
        REG(NVIC, IABR, 0x200),   /* NVIC_IABR0 */
        REG(NVIC, IP, 0x300),     /* NVIC_IPR0 */
        REG(NVIC, IP[18], 0x312), /* ADC1_2 priority byte (IPR4) */
        REG(NVIC, IP[24], 0x318), /* TIM1_BRK priority byte (IPR6) */
        REG(NVIC, IP[25], 0x319), /* TIM1_UP priority byte (IPR6) */
        REG(NVIC, STIR, 0xE00),   /* NVIC_STIR */
        /* SCB (PM0056 §4.4; DFSR and AFSR: ARMv7-M ARM §B3.2) */
        REG(SCB, CPUID, 0x00),  /* CPUID */
        REG(SCB, ICSR, 0x04),   /* ICSR */
        REG(SCB, VTOR, 0x08),   /* VTOR */
        REG(SCB, AIRCR, 0x0C),  /* AIRCR */
        REG(SCB, SCR, 0x10),    /* SCR */
        REG(SCB, CCR, 0x14),    /* CCR */
        REG(SCB, SHP, 0x18),    /* SHPR1, byte 0: exception 4 */
        REG(SCB, SHP[11], 0x23), /* SHPR3 PRI_15: SysTick's priority */
        REG(SCB, SHCSR, 0x24),  /* SHCSR */
        REG(SCB, CFSR, 0x28),   /* CFSR */
        REG(SCB, HFSR, 0x2C),   /* HFSR */
        REG(SCB, DFSR, 0x30),   /* DFSR */
        REG(SCB, MMFAR, 0x34),  /* MMFAR */
        REG(SCB, BFAR, 0x38),   /* BFAR */
        REG(SCB, AFSR, 0x3C),   /* AFSR */
        /* debug (ARMv7-M ARM §C1.6) */
        REG(CoreDebug, DHCSR, 0x0), /* DHCSR */
        REG(CoreDebug, DCRSR, 0x4), /* DCRSR */
        REG(CoreDebug, DCRDR, 0x8), /* DCRDR */
        REG(CoreDebug, DEMCR, 0xC), /* DEMCR */
        /* DWT (ARMv7-M ARM §C1.8) */
        REG(DWT, CTRL, 0x0),   /* DWT_CTRL */
        REG(DWT, CYCCNT, 0x4), /* DWT_CYCCNT */
    };
    check_rows("register offsets", rows, COUNT(rows));
}

/* ------------------------------------------------ bits and fields -- */
static void case_bit_fields(void)
{
    const row_t rows[] = {
        /* RCC_CR (RM0008 §7.3.1) */
        VAL(RCC_CR_HSION, 1u << 0),   /* bit 0 HSION */
        VAL(RCC_CR_HSIRDY, 1u << 1),  /* bit 1 HSIRDY */
        VAL(RCC_CR_HSEON, 1u << 16),  /* bit 16 HSEON */
        VAL(RCC_CR_HSERDY, 1u << 17), /* bit 17 HSERDY */
        VAL(RCC_CR_CSSON, 1u << 19),  /* bit 19 CSSON */
        VAL(RCC_CR_PLLON, 1u << 24),  /* bit 24 PLLON */
        VAL(RCC_CR_PLLRDY, 1u << 25), /* bit 25 PLLRDY */
        /* RCC_CFGR (RM0008 §7.3.2) */
        VAL(RCC_CFGR_SW, 3u << 0),          /* SW[1:0] */
        VAL(RCC_CFGR_SW_PLL, 2u << 0),      /* SW = 10: PLL */
        VAL(RCC_CFGR_SWS, 3u << 2),         /* SWS[3:2] */
        VAL(RCC_CFGR_SWS_PLL, 2u << 2),     /* SWS = 10: PLL */
        VAL(RCC_CFGR_PPRE1_DIV2, 4u << 8),  /* PPRE1[10:8] = 100: HCLK/2 */
        VAL(RCC_CFGR_ADCPRE_DIV6, 2u << 14), /* ADCPRE[15:14] = 10: PCLK2/6 */
        VAL(RCC_CFGR_PLLSRC, 1u << 16),     /* bit 16 PLLSRC */
        VAL(RCC_CFGR_PLLMULL, 15u << 18),   /* PLLMUL[21:18] */
        VAL(RCC_CFGR_PLLMULL9, 7u << 18),   /* PLLMUL = 0111: x9 */
        /* RCC_CIR (RM0008 §7.3.3) */
        VAL(RCC_CIR_CSSC, 1u << 23), /* bit 23 CSSC */
        /* RCC_APB2ENR (RM0008 §7.3.7) */
        VAL(RCC_APB2ENR_AFIOEN, 1u << 0),    /* bit 0 AFIOEN */
        VAL(RCC_APB2ENR_IOPAEN, 1u << 2),    /* bit 2 IOPAEN */
        VAL(RCC_APB2ENR_IOPBEN, 1u << 3),    /* bit 3 IOPBEN */
        VAL(RCC_APB2ENR_IOPCEN, 1u << 4),    /* bit 4 IOPCEN */
        VAL(RCC_APB2ENR_IOPDEN, 1u << 5),    /* bit 5 IOPDEN */
        VAL(RCC_APB2ENR_IOPEEN, 1u << 6),    /* bit 6 IOPEEN */
        VAL(RCC_APB2ENR_ADC1EN, 1u << 9),    /* bit 9 ADC1EN */
        VAL(RCC_APB2ENR_ADC2EN, 1u << 10),   /* bit 10 ADC2EN */
        VAL(RCC_APB2ENR_TIM1EN, 1u << 11),   /* bit 11 TIM1EN */
        VAL(RCC_APB2ENR_USART1EN, 1u << 14), /* bit 14 USART1EN */
        /* RCC_APB1ENR (RM0008 §7.3.8) */
        VAL(RCC_APB1ENR_TIM3EN, 1u << 1), /* bit 1 TIM3EN */
        /* FLASH_ACR (RM0008 §3.3.3) */
        VAL(FLASH_ACR_PRFTBE, 1u << 4), /* bit 4 PRFTBE */
        /* AFIO_MAPR (RM0008 §9.4.2) */
        VAL(AFIO_MAPR_TIM1_REMAP_FULLREMAP, 3u << 6), /* TIM1_REMAP[7:6] = 11 */
        VAL(AFIO_MAPR_SWJ_CFG, 7u << 24),             /* SWJ_CFG[26:24] */
        /* TIMx_CR1 (RM0008 §14.4.1) */
        VAL(TIM_CR1_CEN, 1u << 0),   /* bit 0 CEN */
        VAL(TIM_CR1_DIR, 1u << 4),   /* bit 4 DIR */
        VAL(TIM_CR1_CMS_0, 1u << 5), /* CMS[6:5], bit 5 */
        VAL(TIM_CR1_CMS_1, 1u << 6), /* CMS[6:5], bit 6 */
        VAL(TIM_CR1_ARPE, 1u << 7),  /* bit 7 ARPE */
        /* TIMx_CR2 (RM0008 §14.4.2) */
        VAL(TIM_CR2_MMS_1, 1u << 5), /* MMS[6:4], bit 5 */
        /* TIMx_DIER (RM0008 §14.4.4) */
        VAL(TIM_DIER_UIE, 1u << 0), /* bit 0 UIE */
        VAL(TIM_DIER_BIE, 1u << 7), /* bit 7 BIE */
        /* TIMx_SR (RM0008 §14.4.5) */
        VAL(TIM_SR_UIF, 1u << 0), /* bit 0 UIF */
        VAL(TIM_SR_BIF, 1u << 7), /* bit 7 BIF */
        /* TIMx_EGR (RM0008 §14.4.6) */
        VAL(TIM_EGR_UG, 1u << 0), /* bit 0 UG */
        /* TIMx_CCMR1, output compare mode (RM0008 §14.4.7) */
        VAL(TIM_CCMR1_OC1PE, 1u << 3),   /* bit 3 OC1PE */
        VAL(TIM_CCMR1_OC1M, 7u << 4),    /* OC1M[6:4] */
        VAL(TIM_CCMR1_OC1M_0, 1u << 4),  /* OC1M bit 4 */
        VAL(TIM_CCMR1_OC1M_1, 1u << 5),  /* OC1M bit 5 */
        VAL(TIM_CCMR1_OC1M_2, 1u << 6),  /* OC1M bit 6 */
        VAL(TIM_CCMR1_OC2PE, 1u << 11),  /* bit 11 OC2PE */
        VAL(TIM_CCMR1_OC2M, 7u << 12),   /* OC2M[14:12] */
        VAL(TIM_CCMR1_OC2M_0, 1u << 12), /* OC2M bit 12 */
        VAL(TIM_CCMR1_OC2M_1, 1u << 13), /* OC2M bit 13 */
        VAL(TIM_CCMR1_OC2M_2, 1u << 14), /* OC2M bit 14 */
        /* TIMx_CCMR2, output compare mode (RM0008 §14.4.8) */
        VAL(TIM_CCMR2_OC3PE, 1u << 3),   /* bit 3 OC3PE */
        VAL(TIM_CCMR2_OC3M, 7u << 4),    /* OC3M[6:4] */
        VAL(TIM_CCMR2_OC3M_0, 1u << 4),  /* OC3M bit 4 */
        VAL(TIM_CCMR2_OC3M_1, 1u << 5),  /* OC3M bit 5 */
        VAL(TIM_CCMR2_OC3M_2, 1u << 6),  /* OC3M bit 6 */
        VAL(TIM_CCMR2_OC4PE, 1u << 11),  /* bit 11 OC4PE */
        VAL(TIM_CCMR2_OC4M, 7u << 12),   /* OC4M[14:12] */
        VAL(TIM_CCMR2_OC4M_0, 1u << 12), /* OC4M bit 12 */
        VAL(TIM_CCMR2_OC4M_1, 1u << 13), /* OC4M bit 13 */
        VAL(TIM_CCMR2_OC4M_2, 1u << 14), /* OC4M bit 14 */
        /* TIMx_CCER (RM0008 §14.4.9) */
        VAL(TIM_CCER_CC1E, 1u << 0),   /* bit 0 CC1E */
        VAL(TIM_CCER_CC1NE, 1u << 2),  /* bit 2 CC1NE */
        VAL(TIM_CCER_CC2E, 1u << 4),   /* bit 4 CC2E */
        VAL(TIM_CCER_CC2NE, 1u << 6),  /* bit 6 CC2NE */
        VAL(TIM_CCER_CC3E, 1u << 8),   /* bit 8 CC3E */
        VAL(TIM_CCER_CC3NE, 1u << 10), /* bit 10 CC3NE */
        VAL(TIM_CCER_CC4E, 1u << 12),  /* bit 12 CC4E */
        VAL(TIM_CCER_CC4P, 1u << 13),  /* bit 13 CC4P */
        /* TIMx_BDTR (RM0008 §14.4.18) */
        VAL(TIM_BDTR_DTG, 0xFFu << 0), /* DTG[7:0] */
        VAL(TIM_BDTR_LOCK_0, 1u << 8), /* LOCK[9:8], bit 8 */
        VAL(TIM_BDTR_OSSI, 1u << 10),  /* bit 10 OSSI */
        VAL(TIM_BDTR_OSSR, 1u << 11),  /* bit 11 OSSR */
        VAL(TIM_BDTR_BKE, 1u << 12),   /* bit 12 BKE */
        VAL(TIM_BDTR_BKP, 1u << 13),   /* bit 13 BKP */
        VAL(TIM_BDTR_MOE, 1u << 15),   /* bit 15 MOE */
        /* ADC_SR (RM0008 §11.12.1) */
        VAL(ADC_SR_JEOC, 1u << 2), /* bit 2 JEOC */
        /* ADC_CR1 (RM0008 §11.12.2) */
        VAL(ADC_CR1_JEOCIE, 1u << 7),     /* bit 7 JEOCIE */
        VAL(ADC_CR1_SCAN, 1u << 8),       /* bit 8 SCAN */
        VAL(ADC_CR1_DUALMOD_0, 1u << 16), /* DUALMOD[19:16], bit 16 */
        VAL(ADC_CR1_DUALMOD_2, 1u << 18), /* DUALMOD[19:16], bit 18 */
        /* ADC_CR2 (RM0008 §11.12.3) */
        VAL(ADC_CR2_ADON, 1u << 0),       /* bit 0 ADON */
        VAL(ADC_CR2_CAL, 1u << 2),        /* bit 2 CAL */
        VAL(ADC_CR2_RSTCAL, 1u << 3),     /* bit 3 RSTCAL */
        VAL(ADC_CR2_ALIGN, 1u << 11),     /* bit 11 ALIGN */
        VAL(ADC_CR2_JEXTSEL, 7u << 12),   /* JEXTSEL[14:12] */
        VAL(ADC_CR2_JEXTSEL_0, 1u << 12), /* JEXTSEL bit 12 */
        VAL(ADC_CR2_JEXTTRIG, 1u << 15),  /* bit 15 JEXTTRIG */
        /* USART_SR (RM0008 §27.6.1) */
        VAL(USART_SR_ORE, 1u << 3),  /* bit 3 ORE */
        VAL(USART_SR_RXNE, 1u << 5), /* bit 5 RXNE */
        VAL(USART_SR_TXE, 1u << 7),  /* bit 7 TXE */
        /* USART_CR1 (RM0008 §27.6.4) */
        VAL(USART_CR1_RE, 1u << 2),  /* bit 2 RE */
        VAL(USART_CR1_TE, 1u << 3),  /* bit 3 TE */
        VAL(USART_CR1_UE, 1u << 13), /* bit 13 UE */
        /* STK_CTRL (PM0056 §4.5.1) */
        VAL(SysTick_CTRL_ENABLE_Msk, 1u << 0),    /* bit 0 ENABLE */
        VAL(SysTick_CTRL_TICKINT_Msk, 1u << 1),   /* bit 1 TICKINT */
        VAL(SysTick_CTRL_CLKSOURCE_Msk, 1u << 2), /* bit 2 CLKSOURCE */
        /* DEMCR (ARMv7-M ARM §C1.6) */
        VAL(CoreDebug_DEMCR_TRCENA_Msk, 1u << 24), /* bit 24 TRCENA */
        /* DWT_CTRL (ARMv7-M ARM §C1.8) */
        VAL(DWT_CTRL_CYCCNTENA_Msk, 1u << 0), /* bit 0 CYCCNTENA */
    };
    check_rows("bits and fields", rows, COUNT(rows));
}

/* ------------------------------------------------ interrupts -- */
static void case_interrupts(void)
{
    const row_t rows[] = {
        /* CMSIS numbers: position in RM0008 §10.1.2's vector table for
         * interrupts, the exception number - 16 for the system exceptions */
        VAL(NonMaskableInt_IRQn, -14), /* NMI, exception 2 */
        VAL(SysTick_IRQn, -1),         /* SysTick, exception 15 */
        VAL(ADC1_2_IRQn, 18),          /* position 18 ADC1_2 */
        VAL(TIM1_BRK_IRQn, 24),        /* position 24 TIM1_BRK */
        VAL(TIM1_UP_IRQn, 25),         /* position 25 TIM1_UP */
        /* RM0008 §10.1.1: 16 priority levels, 4 bits of priority */
        VAL(__NVIC_PRIO_BITS, 4),
    };
    check_rows("interrupts", rows, COUNT(rows));
}

TK_CASES(TK_CASE(case_base_addresses), TK_CASE(case_register_offsets),
         TK_CASE(case_bit_fields), TK_CASE(case_interrupts))
