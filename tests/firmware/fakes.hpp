#pragma once
// Small fakes of the HAL for the firmware's stage tests: each holds what the test sets and
// records what the stage wrote. No plant: the stages are tested on the values they see.
#include <cstdint>
#include <deque>
#include <vector>

#include "hal/can_bus.hpp"
#include "hal/control_timer.hpp"
#include "hal/current_adc.hpp"
#include "hal/encoder.hpp"
#include "hal/gpio.hpp"
#include "hal/pwm.hpp"

namespace imd::test {

/// 12-bit converter, 10 A full scale, 400 V bus full scale.
struct FakeAdc final : hal::CurrentAdc {
  hal::AdcSample next{{2048, 2048, 2048}, 2000};
  hal::AdcScale adc_scale{10.0f / 2048.0f, 2048, 400.0f / 4095.0f, 4095};
  hal::AdcSample sample() const noexcept override { return next; }
  hal::AdcScale scale() const noexcept override { return adc_scale; }
};

struct FakeEncoder final : hal::Encoder {
  uint32_t counter = 0;
  uint32_t cpr = 8192;
  uint32_t count() const noexcept override { return counter; }
  uint32_t counts_per_rev() const noexcept override { return cpr; }
};

struct FakePwm final : hal::Pwm {
  hal::PhaseDuties duty{0.5f, 0.5f, 0.5f};
  bool on = false;
  int writes = 0;
  void set_duties(const hal::PhaseDuties& d) noexcept override {
    duty = d;
    ++writes;
  }
  void enable() noexcept override { on = true; }
  void disable() noexcept override { on = false; }
  bool enabled() const noexcept override { return on; }
  float period_s() const noexcept override { return 1e-4f; }
};

/// A timer whose clock advances by `step_counts` at every read.
struct FakeTimer final : hal::ControlTimer {
  uint64_t ticks = 0;
  mutable uint32_t counts = 0;
  uint32_t step_counts = 10;
  uint32_t hz = 1'000'000'000u;
  void start(hal::TickHandler&) noexcept override {}
  void stop() noexcept override {}
  uint32_t period_ns() const noexcept override { return 100'000; }
  uint64_t tick_count() const noexcept override { return ticks; }
  uint32_t execution_counts() const noexcept override { return counts += step_counts; }
  uint32_t execution_clock_Hz() const noexcept override { return hz; }
};

struct FakeCan final : hal::CanBus {
  std::deque<hal::CanFrame> inbox;
  std::vector<hal::CanFrame> sent;
  bool try_send(const hal::CanFrame& frame) noexcept override {
    sent.push_back(frame);
    return true;
  }
  bool try_receive(hal::CanFrame& frame) noexcept override {
    if (inbox.empty()) return false;
    frame = inbox.front();
    inbox.pop_front();
    return true;
  }
};

struct FakeGpio final : hal::Gpio {
  bool levels[8] = {};
  void write(uint8_t line, bool level) noexcept override { levels[line] = level; }
  bool read(uint8_t line) const noexcept override { return levels[line]; }
};

}  // namespace imd::test
