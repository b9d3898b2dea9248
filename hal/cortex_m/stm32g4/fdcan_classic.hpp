#pragma once
/// hal::CanBus on FDCAN1 of the STM32G4 (RM0440 §44) in classic CAN mode (no FD frames, no bit
/// rate switch), standard 11-bit identifiers only, at the bit rate fdcan_timing() derives.
///
/// Receive: every standard data frame goes to Rx FIFO 0 (no filter elements; non-matching
/// standard frames are accepted into FIFO 0, extended and remote frames rejected); the tick
/// takes them with try_receive (FIFO 0 get index, acknowledged one by one).
/// Transmit: the G4's message RAM has only three Tx buffers, while the drive queues a burst of
/// up to five frames in one tick (heartbeat, three telemetry frames, an acknowledgement). So
/// try_send puts the frame in a lock-free ring (tick -> main loop) and returns false only when
/// that ring is full; pump(), from the main loop, moves frames into the hardware Tx FIFO at its
/// put index while it is not full. Transmission thus happens outside the tick, as designed.
/// Pins (board): FDCAN1_RX = PA11, FDCAN1_TX = PB9 (AF9), to an isolated CAN transceiver.
#include <cstddef>
#include <cstdint>

#include "hal/can_bus.hpp"
#include "hal/spsc_ring.hpp"

namespace imd::hal::cortex_m::stm32g4 {

/// Nominal bit timing (FDCAN_NBTP), in time quanta of prescaler / kernel clock. Default: 170 MHz
/// / 2 = 85 MHz (11.8 ns tq), 1 + 73 + 11 = 85 tq per bit = 1 Mbit/s, sample point
/// 74/85 = 87.1 % (CiA 301 recommends 87.5 %), resynchronization jump width 11 tq.
struct FdcanConfig {
  uint32_t kernel_clock_Hz = 170'000'000;  ///< PCLK1 (RCC_CCIPR.FDCANSEL = 10)
  uint32_t prescaler = 2;                  ///< 1..512
  uint32_t tseg1 = 73;                     ///< propagation + phase 1, 2..256 tq
  uint32_t tseg2 = 11;                     ///< phase 2, 2..128 tq
  uint32_t sjw = 11;                       ///< 1..128 tq, <= tseg2
};

constexpr uint32_t tq_per_bit(const FdcanConfig& c) {
  return 1 + c.tseg1 + c.tseg2;
}
constexpr uint32_t nominal_bit_rate(const FdcanConfig& c) {
  return c.kernel_clock_Hz / (c.prescaler * tq_per_bit(c));
}
/// The bit rate is exactly nominal_bit_rate (no rounding in the division) and the fields are
/// within FDCAN_NBTP's ranges.
constexpr bool timing_is_exact(const FdcanConfig& c) {
  return c.prescaler >= 1 && c.prescaler <= 512 && c.tseg1 >= 2 && c.tseg1 <= 256 &&
         c.tseg2 >= 2 && c.tseg2 <= 128 && c.sjw >= 1 && c.sjw <= c.tseg2 &&
         c.kernel_clock_Hz % (c.prescaler * tq_per_bit(c)) == 0;
}

/// The timing for `bit_rate_bit_s` from `kernel_clock_Hz`: always 85 tq per bit with the
/// sample point at 74/85 = 87.1 %, so only the prescaler changes (170 MHz: 2 for 1 Mbit/s, 4
/// for 500 kbit/s, 8 for 250 kbit/s). Check the result with timing_is_exact.
constexpr FdcanConfig fdcan_timing(uint32_t kernel_clock_Hz, uint32_t bit_rate_bit_s) {
  FdcanConfig c;
  c.kernel_clock_Hz = kernel_clock_Hz;
  c.prescaler = kernel_clock_Hz / (bit_rate_bit_s * tq_per_bit(c));
  return c;
}
static_assert(timing_is_exact(FdcanConfig{}) && nominal_bit_rate(FdcanConfig{}) == 1'000'000);

class FdcanClassic final : public hal::CanBus {
 public:
  static constexpr std::size_t kTxQueueFrames = 32;

  /// Initializes FDCAN1 and joins the bus. Requires the FDCAN clock and its kernel clock.
  /// Start-up only; ok() tells whether the controller left its initialization state.
  explicit FdcanClassic(const FdcanConfig& config) noexcept;
  bool ok() const noexcept { return ok_; }

  /// Queues a frame for pump(); false if the queue is full. Tick context.
  bool try_send(const hal::CanFrame& frame) noexcept override;
  /// The oldest standard data frame of Rx FIFO 0; false if none. Tick context.
  bool try_receive(hal::CanFrame& frame) noexcept override;
  /// PSR.BO: the controller is bus-off. Tick context.
  bool bus_off() const noexcept override;

  /// Main loop: moves queued frames into the hardware Tx FIFO while it has room, and starts
  /// the bus-off recovery (128 x 11 recessive bits) when the controller has gone bus-off.
  void pump() noexcept;
  uint32_t bus_off_recoveries() const noexcept { return recoveries_; }

 private:
  hal::SpscRing<hal::CanFrame, kTxQueueFrames> tx_;
  uint32_t recoveries_ = 0;
  bool ok_ = false;
};

}  // namespace imd::hal::cortex_m::stm32g4
