#pragma once
/// hal::FlashPages on the STM32G431's own flash (RM0440 §5.3): the last two 2 KiB pages of the
/// 128 KiB (pages 62 and 63, at 0x0801F000 and 0x0801F800), which the linker script keeps out
/// of the image. Erase by page (PER, PNB, STRT), program by 64-bit double word (PG, two 32-bit
/// writes), each checked against the status register's error flags.
///
/// The G431 has one bank: while the flash erases or programs, every fetch from it stalls, the
/// tick's interrupt included. An erase takes up to 40 ms (DS12589 Table 52), so a save is
/// allowed only while the PWM is off (the drive saves only on a command in idle; ticks are
/// late meanwhile, nothing drives the motor). Not for tick context.
#include <cstddef>
#include <cstdint>
#include <span>

#include "hal/flash_pages.hpp"

namespace imd::hal::cortex_m::stm32g4 {

inline constexpr uintptr_t kParameterPage0 = 0x0801'F000;  ///< the linker script ends flash here
inline constexpr std::size_t kFlashPageBytes = 2048;
inline constexpr uint32_t kParameterFirstPage = 62;

class FlashPagePair final : public hal::FlashPages {
 public:
  std::size_t page_bytes() const noexcept override { return kFlashPageBytes; }
  std::size_t program_unit() const noexcept override { return 8; }
  bool erase(int page) noexcept override;
  bool program(int page, std::size_t offset, std::span<const uint8_t> bytes) noexcept override;
  void read(int page, std::size_t offset, std::span<uint8_t> out) const noexcept override;

  /// The status register's error bits of the last failed operation (0: none).
  uint32_t last_error() const noexcept { return last_error_; }

 private:
  bool unlock() noexcept;
  void lock() noexcept;
  bool wait_done() noexcept;

  uint32_t last_error_ = 0;
};

}  // namespace imd::hal::cortex_m::stm32g4
