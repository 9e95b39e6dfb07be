/*
 * Exception and interrupt handlers named in the vector table
 * (startup_stm32f10x.c); the ones the port uses are defined in
 * stm32_port.c, the others default to a handler that turns the bridge off.
 */
#ifndef STM32_VECTORS_H
#define STM32_VECTORS_H

void Reset_Handler(void);
void NMI_Handler(void);
void HardFault_Handler(void);
void Default_Handler(void);
void SysTick_Handler(void);
void ADC1_2_IRQHandler(void);
void TIM1_BRK_IRQHandler(void);
void TIM1_UP_IRQHandler(void);

int main(void);

#endif /* STM32_VECTORS_H */
