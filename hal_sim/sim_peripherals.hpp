#pragma once
/// The simulated board's peripherals: each implements one HAL interface over state that the
/// board (SimBoard) updates in lock-step. They hold no physics of their own.
#include <array>
#include <cstddef>
#include <cstdint>

#include "hal/can_bus.hpp"
#include "hal/control_timer.hpp"
#include "hal/current_adc.hpp"
#include "hal/encoder.hpp"
#include "hal/gpio.hpp"
#include "hal/pwm.hpp"
#include "hal_sim/host_clock.hpp"

namespace imd::sim {

class SimPwm final : public hal::Pwm {
 public:
  explicit SimPwm(float period_s) : period_s_(period_s) {}
  void set_duties(const hal::PhaseDuties& duty) noexcept override { written_ = duty; }
  void enable() noexcept override { enabled_ = !tripped_; }  // as TIM1: not after a break
  void clear_trip() noexcept override { tripped_ = false; }
  void disable() noexcept override { enabled_ = false; }
  bool enabled() const noexcept override { return enabled_; }
  bool tripped() const noexcept override { return tripped_; }
  float period_s() const noexcept override { return period_s_; }
  const hal::PhaseDuties& written() const noexcept { return written_; }
  /// The board's over-current comparator on the break input: the outputs off in hardware.
  void trip() noexcept {
    enabled_ = false;
    tripped_ = true;
  }

 private:
  float period_s_;
  bool enabled_ = false, tripped_ = false;
  hal::PhaseDuties written_{0.5f, 0.5f, 0.5f};
};

class SimEncoder final : public hal::Encoder {
 public:
  explicit SimEncoder(uint32_t counts_per_rev) : counts_per_rev_(counts_per_rev) {}
  uint32_t count() const noexcept override { return count_; }
  uint32_t counts_per_rev() const noexcept override { return counts_per_rev_; }
  void latch(uint32_t count) noexcept { count_ = count; }

 private:
  uint32_t counts_per_rev_;
  uint32_t count_ = 0;
};

class SimAdc final : public hal::CurrentAdc {
 public:
  explicit SimAdc(const hal::AdcScale& scale) : scale_(scale) {}
  hal::AdcSample sample() const noexcept override { return sample_; }
  hal::AdcScale scale() const noexcept override { return scale_; }
  void latch(const hal::AdcSample& sample) noexcept { sample_ = sample; }

 private:
  hal::AdcScale scale_;
  hal::AdcSample sample_{};
};

/// A bounded FIFO of CAN frames in fixed storage. Single-threaded: the simulation and the
/// firmware run in one thread (hal::SpscRing's atomics and cache-line alignment would only
/// cost RAM on the MCU).
template <std::size_t Capacity>
class CanFrameQueue {
 public:
  /// False if full (the frame is not queued).
  bool push(const hal::CanFrame& frame) noexcept {
    if (size_ == Capacity) return false;
    frames_[(head_ + size_) % Capacity] = frame;
    ++size_;
    return true;
  }
  /// The oldest frame into `frame`; false if empty.
  bool pop(hal::CanFrame& frame) noexcept {
    if (size_ == 0) return false;
    frame = frames_[head_];
    head_ = (head_ + 1) % Capacity;
    --size_;
    return true;
  }

 private:
  std::array<hal::CanFrame, Capacity> frames_{};
  std::size_t head_ = 0;  ///< index of the oldest frame
  std::size_t size_ = 0;
};

/// A CAN bus whose far end is the simulation: frames sent are collected for logging, frames
/// injected arrive in order. Bounded queues, like a controller's mailboxes, in fixed storage.
class SimCan final : public hal::CanBus {
 public:
  static constexpr std::size_t kQueueDepth = 64;  ///< frames each way
  /// False when kQueueDepth sent frames are waiting for take_sent().
  bool try_send(const hal::CanFrame& frame) noexcept override;
  bool try_receive(hal::CanFrame& frame) noexcept override;
  /// Simulation side: deliver a frame to the firmware; false if it did not arrive (the receive
  /// queue is full, or the bus is silenced).
  bool inject(const hal::CanFrame& frame) noexcept;
  /// Simulation side: takes the oldest frame the firmware sent into `out`; false if none is
  /// left. (hal_sim/sim_can_host.hpp takes them all into a vector on the host.)
  bool take_sent(hal::CanFrame& out) noexcept { return sent_.pop(out); }

  /// Fault: from now on every injected frame is lost (the host side falls silent). Frames
  /// already received stay; the firmware's sent frames are still collected.
  void silence() noexcept { silenced_ = true; }
  void unsilence() noexcept { silenced_ = false; }
  bool silenced() const noexcept { return silenced_; }
  /// Frames lost to the silence so far.
  uint64_t dropped_frames() const noexcept { return dropped_; }

 private:
  CanFrameQueue<kQueueDepth> sent_, received_;
  bool silenced_ = false;
  uint64_t dropped_ = 0;
};

class SimGpio final : public hal::Gpio {
 public:
  static constexpr int kLines = 32;
  void write(uint8_t line, bool level) noexcept override {
    if (line < kLines) levels_[line] = level;
  }
  bool read(uint8_t line) const noexcept override { return line < kLines && levels_[line]; }

 private:
  bool levels_[kLines] = {};
};

/// Lock-step timer: the board calls the handler once per simulated period. The execution clock
/// counts nanoseconds of host_clock_ns() (hal_sim/host_clock.hpp), plus any time a stall (an
/// overrun fault) has stolen.
class SimTimer final : public hal::ControlTimer {
 public:
  /// Reads the host clock once: its first read calibrates it (host_clock_linux.cpp), which
  /// must happen here and not in a tick.
  explicit SimTimer(uint32_t period_ns) : period_ns_(period_ns) { (void)host_clock_ns(); }
  void start(hal::TickHandler& handler) noexcept override { handler_ = &handler; }
  void stop() noexcept override { handler_ = nullptr; }
  uint32_t period_ns() const noexcept override { return period_ns_; }
  uint64_t tick_count() const noexcept override { return ticks_; }
  /// Host time in ns plus the stalls of past ticks, the low 32 bits; inside fire(), every read
  /// after the first one also adds this tick's stall, so a tick measured from its first read
  /// takes stall_ns longer.
  uint32_t execution_counts() const noexcept override;
  uint32_t execution_clock_Hz() const noexcept override { return 1'000'000'000u; }
  /// Board side: runs the handler (if started) and counts the period.
  void fire() noexcept;

  /// Fault: from now on every tick takes `stall_ns` longer on the execution clock, as if an
  /// interrupt of higher priority stole that time inside the tick. 0 removes the stall.
  void set_stall_ns(uint64_t stall_ns) noexcept { stall_ns_ = stall_ns; }
  uint64_t stall_ns() const noexcept { return stall_ns_; }

 private:
  uint32_t period_ns_;
  uint64_t ticks_ = 0;
  hal::TickHandler* handler_ = nullptr;
  uint64_t stall_ns_ = 0;
  uint64_t stolen_ns_ = 0;  ///< stalls of the ticks fired so far: keeps the clock monotonic
  bool in_fire_ = false;
  mutable int reads_in_fire_ = 0;
};

/// The analog part of the preliminary feedback (2) of paper 000, a device only the simulated
/// board has: u(t) = sigma p w(t) J (I(t) + beta Phi(t)) + e^{p th(t) J} v~_k, evaluated
/// continuously, with v~_k written once per period (rotor-aligned frame). Real boards run (2)
/// digitally through the PWM; the paper's hybrid scheme needs this device. The board reads the
/// latest input (in double, so that the paper's exactness can be checked).
class SimAnalogInnerLoop {
 public:
  void set_input_AB_V(double v_A_V, double v_B_V) noexcept {
    v_A_V_ = v_A_V;
    v_B_V_ = v_B_V;
  }
  double v_A_V() const noexcept { return v_A_V_; }
  double v_B_V() const noexcept { return v_B_V_; }

 private:
  double v_A_V_ = 0.0, v_B_V_ = 0.0;
};

/// An ideal stator current source, as paper 001 assumes ("current-fed"): the rotor-frame
/// current written is imposed exactly and held until the next write. Real boards reach the
/// current-fed mode through an inner current loop on the PWM; only the simulated board has
/// this device. The board reads the latest current (in double).
class SimCurrentSource {
 public:
  void set_current_AB_A(double iA_A, double iB_A) noexcept {
    iA_A_ = iA_A;
    iB_A_ = iB_A;
  }
  double iA_A() const noexcept { return iA_A_; }
  double iB_A() const noexcept { return iB_A_; }

 private:
  double iA_A_ = 0.0, iB_A_ = 0.0;
};

}  // namespace imd::sim
