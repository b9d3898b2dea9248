#pragma once
/// Two pages of simulated NOR flash in RAM, for the parameter store of the simulated board.
/// The power can be cut after a given number of byte operations: each byte an erase sets to
/// 0xFF and each byte a write programs counts as one. After the cut nothing changes any more
/// and every operation fails, as on a board whose supply has gone; a new store built over the
/// same pages is the board after the next power-up. Programming ANDs the bits in, as flash
/// does, and a unit may be programmed only once between erases (a second time is a failure).
/// STM32G4's geometry: 2 KiB pages, 8-byte units. No heap (the processor-in-the-loop image
/// has one).
#include <array>
#include <cstddef>
#include <cstdint>
#include <bitset>
#include <limits>
#include <span>

#include "hal/flash_pages.hpp"

namespace imd::sim {

class SimFlashPages final : public hal::FlashPages {
 public:
  static constexpr std::size_t kPageBytes = 2048, kUnitBytes = 8;

  SimFlashPages() noexcept {
    for (auto& page : pages_) page.fill(0xFF);
  }

  std::size_t page_bytes() const noexcept override { return kPageBytes; }
  std::size_t program_unit() const noexcept override { return kUnitBytes; }

  bool erase(int page) noexcept override {
    if (!valid_page(page)) return false;
    for (uint8_t& b : pages_[page]) {
      if (!spend()) return false;
      b = 0xFF;
    }
    written_[page].reset();
    return true;
  }

  bool program(int page, std::size_t offset, std::span<const uint8_t> bytes) noexcept override {
    if (!valid_page(page) || offset % kUnitBytes != 0 || bytes.size() % kUnitBytes != 0 ||
        offset + bytes.size() > page_bytes()) {
      return false;
    }
    for (std::size_t u = 0; u < bytes.size() / kUnitBytes; ++u) {
      if (written_[page][offset / kUnitBytes + u]) return false;
    }
    for (std::size_t i = 0; i < bytes.size(); ++i) {
      if (!spend()) return false;
      pages_[page][offset + i] &= bytes[i];
      written_[page][(offset + i) / kUnitBytes] = true;
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

  std::array<std::array<uint8_t, kPageBytes>, 2> pages_;
  std::array<std::bitset<kPageBytes / kUnitBytes>, 2> written_;
  std::size_t budget_ = std::numeric_limits<std::size_t>::max();
  std::size_t operations_ = 0;
};

}  // namespace imd::sim
