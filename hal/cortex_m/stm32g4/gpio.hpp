#pragma once
/// GPIO of the STM32G4 (RM0440 §9): pin configuration for the board's pin table (alternate
/// functions of the timers, ADC and FDCAN pins, plain inputs and outputs), and hal::Gpio on a
/// small table of board lines (enable input, fault output, timing output) through BSRR and IDR.
#include <cstddef>
#include <cstdint>
#include <span>

#include "hal/gpio.hpp"

namespace imd::hal::cortex_m::stm32g4 {

enum class PinMode : uint8_t { input = 0, output = 1, alternate = 2, analog = 3 };  // MODER
enum class Pull : uint8_t { none = 0, up = 1, down = 2 };                           // PUPDR
enum class Speed : uint8_t { low = 0, medium = 1, high = 2, very_high = 3 };        // OSPEEDR

/// One pin: port base (kGpioA..), number 0..15, mode, alternate function 0..15 (DS12589
/// Tables 13 to 15), pull, speed, and for an output its level before it is driven.
struct PinConfig {
  uintptr_t port = 0;
  uint8_t pin = 0;
  PinMode mode = PinMode::analog;
  uint8_t alternate = 0;
  Pull pull = Pull::none;
  Speed speed = Speed::low;
  bool initial_high = false;
};

/// Configures one pin (start-up only). An alternate function is selected before the mode
/// switches, and an output's level is set before it is driven, so the pin does not glitch.
void configure_pin(const PinConfig& pin) noexcept;
void configure_pins(std::span<const PinConfig> pins) noexcept;

/// Drives an output pin through BSRR (one write: safe from any context, also fault handlers).
void write_pin(uintptr_t port, uint8_t pin, bool high) noexcept;

/// One line of hal::Gpio: a pin and whether its active level is low. Outputs and inputs must
/// have been configured (configure_pin) with the matching mode.
struct GpioLine {
  uintptr_t port = 0;
  uint8_t pin = 0;
  bool output = false;
  bool active_low = false;
};

class BoardGpio final : public hal::Gpio {
 public:
  /// `lines` is indexed by DriveConfig's line numbers and must outlive this object.
  explicit BoardGpio(std::span<const GpioLine> lines) noexcept : lines_(lines) {}
  /// Drives an output line to its active (true) or inactive level; other lines are ignored.
  /// Tick context.
  void write(uint8_t line, bool level) noexcept override;
  /// The line's level (active = true); false for a line that does not exist. Tick context.
  bool read(uint8_t line) const noexcept override;

 private:
  std::span<const GpioLine> lines_;
};

}  // namespace imd::hal::cortex_m::stm32g4
