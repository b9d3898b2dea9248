#pragma once
/// Two erasable pages of non-volatile memory, the medium of hal/storage/page_pair_store.hpp.
/// Erasing sets every byte of a page to 0xFF; programming writes whole units of
/// program_unit() bytes at aligned offsets, each unit once between erases (NOR flash). A board
/// implements it with its flash controller; the simulation keeps the pages in RAM and can cut
/// the power in the middle of an erase or a write.
#include <cstddef>
#include <cstdint>
#include <span>

namespace imd::hal {

class FlashPages {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so no
  // deleting destructor and no operator delete in the firmware's vtables.
  ~FlashPages() = default;

 public:
  virtual std::size_t page_bytes() const noexcept = 0;
  virtual std::size_t program_unit() const noexcept = 0;
  /// False if the medium failed (the page's content is then undefined).
  virtual bool erase(int page) noexcept = 0;
  /// `bytes.size()` and `offset` are multiples of program_unit().
  virtual bool program(int page, std::size_t offset, std::span<const uint8_t> bytes) noexcept = 0;
  virtual void read(int page, std::size_t offset, std::span<uint8_t> out) const noexcept = 0;
};

}  // namespace imd::hal
