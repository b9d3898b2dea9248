#pragma once
/// Two pages of simulated NOR flash in RAM, for the parameter store of the simulated board.
/// The power can be cut after a given number of byte operations: each byte an erase sets to
/// 0xFF and each byte a write programs counts as one. After the cut nothing changes any more
/// and every operation fails, as on a board whose supply has gone; a new store built over the
/// same pages is the board after the next power-up. Programming ANDs the bits in, as flash
/// does, and a unit may be programmed only once between erases (a second time is a failure).
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "hal/flash_pages.hpp"

namespace imd::hal_sim {

class SimFlashPages final : public hal::FlashPages {
 public:
  /// STM32G4's geometry by default: 2 KiB pages, 8-byte units.
  explicit SimFlashPages(std::size_t page_bytes = 2048, std::size_t unit_bytes = 8)
      : unit_(unit_bytes),
        pages_{std::vector<uint8_t>(page_bytes, 0xFF), std::vector<uint8_t>(page_bytes, 0xFF)},
        written_{std::vector<bool>(page_bytes / unit_bytes), std::vector<bool>(page_bytes / unit_bytes)} {}

  std::size_t page_bytes() const noexcept override { return pages_[0].size(); }
  std::size_t program_unit() const noexcept override { return unit_; }

  bool erase(int page) noexcept override {
    if (!valid_page(page)) return false;
    for (uint8_t& b : pages_[page]) {
      if (!spend()) return false;
      b = 0xFF;
    }
    written_[page].assign(written_[page].size(), false);
    return true;
  }

  bool program(int page, std::size_t offset, std::span<const uint8_t> bytes) noexcept override {
    if (!valid_page(page) || offset % unit_ != 0 || bytes.size() % unit_ != 0 ||
        offset + bytes.size() > page_bytes()) {
      return false;
    }
    for (std::size_t u = 0; u < bytes.size() / unit_; ++u) {
      if (written_[page][offset / unit_ + u]) return false;
    }
    for (std::size_t i = 0; i < bytes.size(); ++i) {
      if (!spend()) return false;
      pages_[page][offset + i] &= bytes[i];
      written_[page][(offset + i) / unit_] = true;
    }
    return true;
  }

  void read(int page, std::size_t offset, std::span<uint8_t> out) const noexcept override {
    for (std::size_t i = 0; i < out.size(); ++i) {
      out[i] = valid_page(page) && offset + i < page_bytes() ? pages_[page][offset + i] : 0xFF;
    }
  }

  /// The power goes after `byte_operations` more byte operations.
  void cut_power_after(std::size_t byte_operations) noexcept { budget_ = byte_operations; }
  /// Power back (the next boot).
  void restore_power() noexcept { budget_ = std::numeric_limits<std::size_t>::max(); }
  bool powered() const noexcept { return budget_ > 0; }
  /// Byte operations so far (to size a sweep of cut points).
  std::size_t operations() const noexcept { return operations_; }

 private:
  bool valid_page(int page) const noexcept { return page == 0 || page == 1; }
  bool spend() noexcept {
    if (budget_ == 0) return false;
    if (budget_ != std::numeric_limits<std::size_t>::max()) --budget_;
    ++operations_;
    return true;
  }

  std::size_t unit_;
  std::array<std::vector<uint8_t>, 2> pages_;
  std::array<std::vector<bool>, 2> written_;
  std::size_t budget_ = std::numeric_limits<std::size_t>::max();
  std::size_t operations_ = 0;
};

}  // namespace imd::hal_sim
