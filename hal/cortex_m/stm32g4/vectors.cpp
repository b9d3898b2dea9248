/// The STM32G431's device interrupt vectors (RM0440 §14.3, Table 97: positions 0..101 of the
/// G4 family; the positions of peripherals the G431 does not have are reserved, 0). Placed in
/// `.isr_vector.irq`, right after the 16 core vectors of hal/cortex_m/startup.cpp. Every
/// handler is a weak alias of one that forwards to Default_Handler (a fatal fault: an enabled
/// interrupt nobody handles); a driver overrides it with a strong definition (adc_tick.cpp:
/// ADC1_2_IRQHandler). The linker keeps the table (cmake: --undefined=g_irq_vectors).
#include <cstdint>

#include "hal/cortex_m/stm32g4/memory_map.hpp"

extern "C" {
void Default_Handler();  // hal/cortex_m/startup.cpp

// GCC aliases only to a function of the same translation unit: this one forwards.
void Unhandled_IRQHandler() {
  Default_Handler();
}

#define IMD_G4_IRQ(name) void name() __attribute__((weak, alias("Unhandled_IRQHandler")));
IMD_G4_IRQ(WWDG_IRQHandler)
IMD_G4_IRQ(PVD_PVM_IRQHandler)
IMD_G4_IRQ(RTC_TAMP_LSECSS_IRQHandler)
IMD_G4_IRQ(RTC_WKUP_IRQHandler)
IMD_G4_IRQ(FLASH_IRQHandler)
IMD_G4_IRQ(RCC_IRQHandler)
IMD_G4_IRQ(EXTI0_IRQHandler)
IMD_G4_IRQ(EXTI1_IRQHandler)
IMD_G4_IRQ(EXTI2_IRQHandler)
IMD_G4_IRQ(EXTI3_IRQHandler)
IMD_G4_IRQ(EXTI4_IRQHandler)
IMD_G4_IRQ(DMA1_Channel1_IRQHandler)
IMD_G4_IRQ(DMA1_Channel2_IRQHandler)
IMD_G4_IRQ(DMA1_Channel3_IRQHandler)
IMD_G4_IRQ(DMA1_Channel4_IRQHandler)
IMD_G4_IRQ(DMA1_Channel5_IRQHandler)
IMD_G4_IRQ(DMA1_Channel6_IRQHandler)
IMD_G4_IRQ(ADC1_2_IRQHandler)
IMD_G4_IRQ(USB_HP_IRQHandler)
IMD_G4_IRQ(USB_LP_IRQHandler)
IMD_G4_IRQ(FDCAN1_IT0_IRQHandler)
IMD_G4_IRQ(FDCAN1_IT1_IRQHandler)
IMD_G4_IRQ(EXTI9_5_IRQHandler)
IMD_G4_IRQ(TIM1_BRK_TIM15_IRQHandler)
IMD_G4_IRQ(TIM1_UP_TIM16_IRQHandler)
IMD_G4_IRQ(TIM1_TRG_COM_TIM17_IRQHandler)
IMD_G4_IRQ(TIM1_CC_IRQHandler)
IMD_G4_IRQ(TIM2_IRQHandler)
IMD_G4_IRQ(TIM3_IRQHandler)
IMD_G4_IRQ(TIM4_IRQHandler)
IMD_G4_IRQ(I2C1_EV_IRQHandler)
IMD_G4_IRQ(I2C1_ER_IRQHandler)
IMD_G4_IRQ(I2C2_EV_IRQHandler)
IMD_G4_IRQ(I2C2_ER_IRQHandler)
IMD_G4_IRQ(SPI1_IRQHandler)
IMD_G4_IRQ(SPI2_IRQHandler)
IMD_G4_IRQ(USART1_IRQHandler)
IMD_G4_IRQ(USART2_IRQHandler)
IMD_G4_IRQ(USART3_IRQHandler)
IMD_G4_IRQ(EXTI15_10_IRQHandler)
IMD_G4_IRQ(RTC_Alarm_IRQHandler)
IMD_G4_IRQ(USBWakeUp_IRQHandler)
IMD_G4_IRQ(TIM8_BRK_IRQHandler)
IMD_G4_IRQ(TIM8_UP_IRQHandler)
IMD_G4_IRQ(TIM8_TRG_COM_IRQHandler)
IMD_G4_IRQ(TIM8_CC_IRQHandler)
IMD_G4_IRQ(LPTIM1_IRQHandler)
IMD_G4_IRQ(SPI3_IRQHandler)
IMD_G4_IRQ(UART4_IRQHandler)
IMD_G4_IRQ(TIM6_DAC_IRQHandler)
IMD_G4_IRQ(TIM7_IRQHandler)
IMD_G4_IRQ(DMA2_Channel1_IRQHandler)
IMD_G4_IRQ(DMA2_Channel2_IRQHandler)
IMD_G4_IRQ(DMA2_Channel3_IRQHandler)
IMD_G4_IRQ(DMA2_Channel4_IRQHandler)
IMD_G4_IRQ(DMA2_Channel5_IRQHandler)
IMD_G4_IRQ(UCPD1_IRQHandler)
IMD_G4_IRQ(COMP1_2_3_IRQHandler)
IMD_G4_IRQ(COMP4_IRQHandler)
IMD_G4_IRQ(CRS_IRQHandler)
IMD_G4_IRQ(SAI1_IRQHandler)
IMD_G4_IRQ(FPU_IRQHandler)
IMD_G4_IRQ(RNG_IRQHandler)
IMD_G4_IRQ(LPUART1_IRQHandler)
IMD_G4_IRQ(I2C3_EV_IRQHandler)
IMD_G4_IRQ(I2C3_ER_IRQHandler)
IMD_G4_IRQ(DMAMUX_OVR_IRQHandler)
IMD_G4_IRQ(DMA2_Channel6_IRQHandler)
IMD_G4_IRQ(CORDIC_IRQHandler)
IMD_G4_IRQ(FMAC_IRQHandler)
#undef IMD_G4_IRQ
}

namespace {
using Vector = void (*)();
}  // namespace

extern "C" __attribute__((section(".isr_vector.irq"), used))
const Vector g_irq_vectors[imd::hal::cortex_m::stm32g4::kIrqCount] = {
    WWDG_IRQHandler,                // 0
    PVD_PVM_IRQHandler,             // 1
    RTC_TAMP_LSECSS_IRQHandler,     // 2
    RTC_WKUP_IRQHandler,            // 3
    FLASH_IRQHandler,               // 4
    RCC_IRQHandler,                 // 5
    EXTI0_IRQHandler,               // 6
    EXTI1_IRQHandler,               // 7
    EXTI2_IRQHandler,               // 8
    EXTI3_IRQHandler,               // 9
    EXTI4_IRQHandler,               // 10
    DMA1_Channel1_IRQHandler,       // 11
    DMA1_Channel2_IRQHandler,       // 12
    DMA1_Channel3_IRQHandler,       // 13
    DMA1_Channel4_IRQHandler,       // 14
    DMA1_Channel5_IRQHandler,       // 15
    DMA1_Channel6_IRQHandler,       // 16
    nullptr,                        // 17 (DMA1 channel 7: not on the G431)
    ADC1_2_IRQHandler,              // 18: the tick's sample stage
    USB_HP_IRQHandler,              // 19
    USB_LP_IRQHandler,              // 20
    FDCAN1_IT0_IRQHandler,          // 21
    FDCAN1_IT1_IRQHandler,          // 22
    EXTI9_5_IRQHandler,             // 23
    TIM1_BRK_TIM15_IRQHandler,      // 24
    TIM1_UP_TIM16_IRQHandler,       // 25
    TIM1_TRG_COM_TIM17_IRQHandler,  // 26
    TIM1_CC_IRQHandler,             // 27
    TIM2_IRQHandler,                // 28
    TIM3_IRQHandler,                // 29
    TIM4_IRQHandler,                // 30
    I2C1_EV_IRQHandler,             // 31
    I2C1_ER_IRQHandler,             // 32
    I2C2_EV_IRQHandler,             // 33
    I2C2_ER_IRQHandler,             // 34
    SPI1_IRQHandler,                // 35
    SPI2_IRQHandler,                // 36
    USART1_IRQHandler,              // 37
    USART2_IRQHandler,              // 38
    USART3_IRQHandler,              // 39
    EXTI15_10_IRQHandler,           // 40
    RTC_Alarm_IRQHandler,           // 41
    USBWakeUp_IRQHandler,           // 42
    TIM8_BRK_IRQHandler,            // 43
    TIM8_UP_IRQHandler,             // 44
    TIM8_TRG_COM_IRQHandler,        // 45
    TIM8_CC_IRQHandler,             // 46
    nullptr,                        // 47 (ADC3)
    nullptr,                        // 48 (FMC)
    LPTIM1_IRQHandler,              // 49
    nullptr,                        // 50 (TIM5)
    SPI3_IRQHandler,                // 51
    UART4_IRQHandler,               // 52
    nullptr,                        // 53 (UART5)
    TIM6_DAC_IRQHandler,            // 54
    TIM7_IRQHandler,                // 55
    DMA2_Channel1_IRQHandler,       // 56
    DMA2_Channel2_IRQHandler,       // 57
    DMA2_Channel3_IRQHandler,       // 58
    DMA2_Channel4_IRQHandler,       // 59
    DMA2_Channel5_IRQHandler,       // 60
    nullptr,                        // 61 (ADC4)
    nullptr,                        // 62 (ADC5)
    UCPD1_IRQHandler,               // 63
    COMP1_2_3_IRQHandler,           // 64
    COMP4_IRQHandler,               // 65
    nullptr,                        // 66 (COMP5/6)
    nullptr,                        // 67 (COMP7)
    nullptr,                        // 68 (HRTIM master)
    nullptr,                        // 69 (HRTIM A)
    nullptr,                        // 70 (HRTIM B)
    nullptr,                        // 71 (HRTIM C)
    nullptr,                        // 72 (HRTIM D)
    nullptr,                        // 73 (HRTIM E)
    nullptr,                        // 74 (HRTIM fault)
    CRS_IRQHandler,                 // 75
    SAI1_IRQHandler,                // 76
    nullptr,                        // 77 (TIM20 break)
    nullptr,                        // 78 (TIM20 update)
    nullptr,                        // 79 (TIM20 trigger)
    nullptr,                        // 80 (TIM20 capture compare)
    FPU_IRQHandler,                 // 81
    nullptr,                        // 82 (I2C4 event)
    nullptr,                        // 83 (I2C4 error)
    nullptr,                        // 84 (SPI4)
    nullptr,                        // 85 (reserved)
    nullptr,                        // 86 (FDCAN2 IT0)
    nullptr,                        // 87 (FDCAN2 IT1)
    nullptr,                        // 88 (FDCAN3 IT0)
    nullptr,                        // 89 (FDCAN3 IT1)
    RNG_IRQHandler,                 // 90
    LPUART1_IRQHandler,             // 91
    I2C3_EV_IRQHandler,             // 92
    I2C3_ER_IRQHandler,             // 93
    DMAMUX_OVR_IRQHandler,          // 94
    nullptr,                        // 95 (QUADSPI)
    nullptr,                        // 96 (DMA1 channel 8)
    DMA2_Channel6_IRQHandler,       // 97
    nullptr,                        // 98 (DMA2 channel 7)
    nullptr,                        // 99 (DMA2 channel 8)
    CORDIC_IRQHandler,              // 100
    FMAC_IRQHandler,                // 101
};
