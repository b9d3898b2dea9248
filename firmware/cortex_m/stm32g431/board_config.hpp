#pragma once
/// The STM32G431CB board image's configuration: the seed-000 motor on a 311 V mains inverter,
/// commanded over CAN. Pin-out as on ST's B-G431B-ESC1 for the PWM and CAN, with the current
/// and bus sensing of a mains power stage (docs/porting.md has the table and the reasons).
#include <array>
#include <cstdint>

#include "control/motor_parameters.hpp"
#include "control/real.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/image_features.hpp"
#include "firmware/protocol/messages.hpp"
#include "hal/cortex_m/stm32g4/adc_injected.hpp"
#include "hal/cortex_m/stm32g4/adc_tick.hpp"
#include "hal/cortex_m/stm32g4/clock.hpp"
#include "hal/cortex_m/stm32g4/fdcan_classic.hpp"
#include "hal/cortex_m/stm32g4/gpio.hpp"
#include "hal/cortex_m/stm32g4/memory_map.hpp"
#include "hal/cortex_m/stm32g4/tim1_pwm.hpp"
#include "hal/cortex_m/stm32g4/tim_encoder.hpp"

namespace imd::firmware::stm32g431 {

namespace g4 = hal::cortex_m::stm32g4;

// Power stage ratings (what the inverter board must provide, docs/porting.md).
inline constexpr Real kBusNominal_V = 311.0;  ///< rectified 220 V mains
inline constexpr Real kBusCapacitorRating_V = 450.0;
inline constexpr Real kCurrentRange_A = 10.0;  ///< +- full scale of the current sensing
inline constexpr Real kCurrentLimit_A = 6.0;   ///< motor and inverter limit the law plans for

// Carrier and control rate.
inline constexpr uint32_t kPwmFrequency_Hz = 10'000;
inline constexpr uint32_t kControlPeriod_ns = 1'000'000'000u / kPwmFrequency_Hz;
inline constexpr uint32_t kDeadTime_ns = 1'000;  ///< IGBT/MOSFET leg with isolated gate drivers
/// The independent watchdog's period: it must outlast the longest stall of a healthy tick, a
/// flash page erase (a parameter save), which on the single-bank G431 stalls every fetch from
/// flash, the tick's included, for up to 40 ms (datasheet t_ERASE). 100 ms; a shorter one
/// needs the erase (or the tick) run from RAM.
inline constexpr uint32_t kWatchdogTimeout_us = 100'000;

/// Analog front end: 10 mOhm shunts, x16.5 amplifiers biased at 1.65 V (+-10 A full scale),
/// DC-bus divider 1.5 MOhm / 10 kOhm (498 V full scale).
inline constexpr g4::AnalogFrontEnd kAnalog{.vref_V = 3.3f,
                                            .bits = 12,
                                            .shunt_Ohm = 0.010f,
                                            .amplifier_gain = 16.5f,
                                            .bus_divider_ratio = 10e3f / (1.5e6f + 10e3f)};

inline constexpr g4::Tim1PwmConfig kPwm{.timer_clock_Hz = g4::kSystemClock_Hz,
                                        .pwm_frequency_Hz = kPwmFrequency_Hz,
                                        .dead_time_ns = kDeadTime_ns,
                                        .adc_trigger_lead_counts = 30};
inline constexpr g4::AdcInjectedConfig kAdc{.phase_a_channel = 1,  // PA0
                                            .bus_channel = 3,      // PA2
                                            .phase_b_channel = 3,  // PA6
                                            .phase_c_channel = 4,  // PA7
                                            .sampling_time_code = 2,
                                            .scale = g4::adc_scale(kAnalog)};
inline constexpr g4::TimEncoderConfig kEncoder{.counts_per_rev = 8192};  // 2048 lines
// The protocol's one bit rate from the 170 MHz FDCAN kernel clock (PCLK1).
inline constexpr g4::FdcanConfig kCan =
    g4::fdcan_timing(g4::kSystemClock_Hz, protocol::kNominalBitrate_bit_s);
static_assert(g4::timing_is_exact(kCan) &&
                  g4::nominal_bit_rate(kCan) == protocol::kNominalBitrate_bit_s,
              "FDCAN1 must run at exactly the protocol's bit rate");
inline constexpr g4::AdcTickConfig kTick{.core_clock_Hz = g4::kSystemClock_Hz,
                                         .period_ns = kControlPeriod_ns};

// Board lines of hal::Gpio (indices of DriveConfig).
inline constexpr int kLineEnable = 0;  ///< PB5 in: safe-torque-off chain closed (high)
inline constexpr int kLineFault = 1;   ///< PC6 out: fault LED / relay, high while faulted
inline constexpr int kLineTiming = 2;  ///< PB7 out: high while the tick computes (scope)
inline constexpr std::array<g4::GpioLine, 3> kLines{{
    {g4::kGpioB, 5, false, false},
    {g4::kGpioC, 6, true, false},
    {g4::kGpioB, 7, true, false},
}};

/// Every pin the board uses. TIM1's pins are configured after TIM1 itself (idle level low).
/// PC13 is a backup-domain pin of limited drive: low speed, a gate-driver input only.
inline constexpr uint8_t kAfTim1 = 6, kAfTim1Alt = 4, kAfTim2 = 1, kAfFdcan1 = 9;
inline constexpr std::array<g4::PinConfig, 6> kPwmPins{{
    {g4::kGpioA, 8, g4::PinMode::alternate, kAfTim1, g4::Pull::none, g4::Speed::high},      // CH1
    {g4::kGpioA, 9, g4::PinMode::alternate, kAfTim1, g4::Pull::none, g4::Speed::high},      // CH2
    {g4::kGpioA, 10, g4::PinMode::alternate, kAfTim1, g4::Pull::none, g4::Speed::high},     // CH3
    {g4::kGpioC, 13, g4::PinMode::alternate, kAfTim1Alt, g4::Pull::none, g4::Speed::low},   // CH1N
    {g4::kGpioA, 12, g4::PinMode::alternate, kAfTim1, g4::Pull::none, g4::Speed::high},     // CH2N
    {g4::kGpioB, 15, g4::PinMode::alternate, kAfTim1Alt, g4::Pull::none, g4::Speed::high},  // CH3N
}};
inline constexpr std::array<g4::PinConfig, 11> kOtherPins{{
    {g4::kGpioA, 0, g4::PinMode::analog},                             // i_a  ADC12_IN1
    {g4::kGpioA, 2, g4::PinMode::analog},                             // v_bus ADC1_IN3
    {g4::kGpioA, 6, g4::PinMode::analog},                             // i_b  ADC2_IN3
    {g4::kGpioA, 7, g4::PinMode::analog},                             // i_c  ADC2_IN4
    {g4::kGpioA, 15, g4::PinMode::alternate, kAfTim2, g4::Pull::up},  // encoder A TIM2_CH1
    {g4::kGpioB, 3, g4::PinMode::alternate, kAfTim2, g4::Pull::up},   // encoder B TIM2_CH2
    {g4::kGpioA, 11, g4::PinMode::alternate, kAfFdcan1},              // FDCAN1_RX
    {g4::kGpioB, 9, g4::PinMode::alternate, kAfFdcan1, g4::Pull::none, g4::Speed::medium},  // TX
    {g4::kGpioB, 5, g4::PinMode::input, 0, g4::Pull::down},  // enable: open = inactive
    {g4::kGpioC, 6, g4::PinMode::output},                    // fault, low
    {g4::kGpioB, 7, g4::PinMode::output},                    // timing, low
}};

/// The drive on this board: the seed-000 realistic scenario's control settings
/// (hal_sim/scenarios/seed000_realistic.toml), references and enable from CAN.
constexpr DriveConfig drive_config() {
  DriveConfig c;
  c.sample_period_s = Real(kControlPeriod_ns * 1e-9);
  c.controller = first_law_in_image();  // the run image's one law (docs/flashing.md)
  // The IOL from its speed loop: the references come from CAN as speeds (set_speed), and
  // without the loop the IOL would follow a torque reference nothing sets. The other laws
  // do not read it.
  c.outer_speed_loop = true;
  c.pwm_latency_ticks = 1;  // duties act from the next carrier peak (tim1_pwm.hpp)
  c.compensate_latency = true;
  c.speed_reaching_pole = Real(0.98);
  c.flux_reaching_pole = Real(0.98);
  c.i_max_A = kCurrentLimit_A;
  c.dead_time_s =
      Real(kDeadTime_ns * 1e-9);  // what TIM1's BDTR programs, compensated in the duties
  c.max_accel_rad_s2 = 200.0;  // set_speed steps from CAN are ramped
  c.encoder_observer_bandwidth_rad_s = 400.0;
  c.adc_offset_limit_A = Real(0.02) * kCurrentRange_A;
  c.node_id = 1;
  c.commands_over_can = true;
  c.auto_enable = false;
  c.telemetry_rate_Hz = 100;
  c.flux2_ref_Wb2 = Real(0.2);
  c.max_flux2_Wb2 = Real(0.4);
  c.enable_input_line = kLineEnable;
  c.fault_output_line = kLineFault;
  c.timing_output_line = kLineTiming;
  ProtectionConfig& p = c.protection;
  p.overcurrent_A = Real(0.9) * kCurrentRange_A;  // 9 A: 1.5 x the limit, inside the range
  p.bus_min_V = Real(0.7) * kBusNominal_V;        // 218 V while enabled
  p.bus_max_V = 400.0;                      // margin below the 450 V capacitors
  p.overspeed_rad_s = 400.0;
  p.command_timeout_s = Real(0.2);
  p.adc_stuck_ticks = adc_stuck_ticks_for(c.sample_period_s);
  // 80 % of the period: the rest is sampling, CAN and margin.
  p.tick_budget_ns = kControlPeriod_ns / 5 * 4;
  return c;
}

static_assert(drive_config().protection.bus_max_V < kBusCapacitorRating_V);
static_assert(drive_config().protection.overcurrent_A < kCurrentRange_A);
static_assert(kAnalog.bus_divider_ratio * drive_config().protection.bus_max_V < kAnalog.vref_V);

}  // namespace imd::firmware::stm32g431
