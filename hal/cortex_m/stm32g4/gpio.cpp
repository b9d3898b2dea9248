#include "hal/cortex_m/stm32g4/gpio.hpp"

#include "hal/cortex_m/armv7m.hpp"

namespace imd::hal::cortex_m::stm32g4 {
namespace {

// GPIO port registers (RM0440 §9.4).
constexpr uintptr_t kModer = 0x00;    // 2 bits per pin
constexpr uintptr_t kOspeedr = 0x08;  // 2 bits per pin
constexpr uintptr_t kPupdr = 0x0C;    // 2 bits per pin
constexpr uintptr_t kIdr = 0x10;
constexpr uintptr_t kBsrr = 0x18;  // [15:0] set, [31:16] reset
constexpr uintptr_t kAfrl = 0x20;  // 4 bits per pin, pins 0..7; AFRH (0x24) pins 8..15

void set_field(uintptr_t address, uint32_t shift, uint32_t width_mask, uint32_t value) noexcept {
  reg32(address) = (reg32(address) & ~(width_mask << shift)) | ((value & width_mask) << shift);
}

}  // namespace

void write_pin(uintptr_t port, uint8_t pin, bool high) noexcept {
  reg32(port + kBsrr) = high ? (1u << pin) : (1u << (pin + 16u));
}

void configure_pin(const PinConfig& p) noexcept {
  const uint32_t two_bits = 2u * p.pin;
  set_field(p.port + kPupdr, two_bits, 0x3u, static_cast<uint32_t>(p.pull));
  set_field(p.port + kOspeedr, two_bits, 0x3u, static_cast<uint32_t>(p.speed));
  if (p.mode == PinMode::alternate) {
    set_field(p.port + kAfrl + 4u * (p.pin / 8u), 4u * (p.pin % 8u), 0xFu, p.alternate);
  }
  if (p.mode == PinMode::output) write_pin(p.port, p.pin, p.initial_high);
  set_field(p.port + kModer, two_bits, 0x3u, static_cast<uint32_t>(p.mode));
}

void configure_pins(std::span<const PinConfig> pins) noexcept {
  for (const PinConfig& p : pins) configure_pin(p);
}

void BoardGpio::write(uint8_t line, bool level) noexcept {
  if (line >= lines_.size() || !lines_[line].output) return;
  const GpioLine& l = lines_[line];
  write_pin(l.port, l.pin, level != l.active_low);
}

bool BoardGpio::read(uint8_t line) const noexcept {
  if (line >= lines_.size()) return false;
  const GpioLine& l = lines_[line];
  return ((reg32(l.port + kIdr) >> l.pin) & 1u) != (l.active_low ? 1u : 0u);
}

}  // namespace imd::hal::cortex_m::stm32g4
