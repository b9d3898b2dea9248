#pragma once
/// One line of console text in a fixed buffer: strings, integers and numbers in scientific
/// notation, without printf (newlib's float formatting allocates). For reports outside the tick.
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace imd::hal::cortex_m {

class TextLine {
 public:
  static constexpr std::size_t kCapacity = 160;  ///< longer text is cut

  TextLine& operator<<(std::string_view text) noexcept;
  TextLine& operator<<(uint64_t value) noexcept;
  TextLine& operator<<(int64_t value) noexcept;
  /// `value` as d.dddddde+XX with `significant` digits (1..17); "nan", "inf", "-inf".
  TextLine& scientific(double value, int significant = 7) noexcept;

  std::string_view view() const noexcept { return {text_, size_}; }
  void clear() noexcept { size_ = 0; }

 private:
  void put(char c) noexcept {
    if (size_ < kCapacity) text_[size_++] = c;
  }

  char text_[kCapacity];
  std::size_t size_ = 0;
};

}  // namespace imd::hal::cortex_m
