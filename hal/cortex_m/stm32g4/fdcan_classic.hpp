#pragma once
/// hal::CanBus on FDCAN1 of the STM32G4 (RM0440 §44) in classic CAN mode (no FD frames, no bit
/// rate switch), 500 kbit/s, standard 11-bit identifiers only.
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
/// / 4 = 42.5 MHz (23.5 ns tq), 1 + 73 + 11 = 85 tq per bit = 500 kbit/s, sample point
/// 74/85 = 87.1 % (CiA 301 recommends 87.5 %), resynchronization jump width 11 tq.
struct FdcanConfig {
  uint32_t kernel_clock_Hz = 170'000'000;  ///< PCLK1 (RCC_CCIPR.FDCANSEL = 10)
  uint32_t prescaler = 4;                  ///< 1..512
  uint32_t tseg1 = 73;                     ///< propagation + phase 1, 2..256 tq
  uint32_t tseg2 = 11;                     ///< phase 2, 2..128 tq
  uint32_t sjw = 11;                       ///< 1..128 tq, <= tseg2
};

constexpr uint32_t nominal_bit_rate(const FdcanConfig& c) {
  return c.kernel_clock_Hz / (c.prescaler * (1 + c.tseg1 + c.tseg2));
}
static_assert(nominal_bit_rate(FdcanConfig{}) == 500'000);

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
