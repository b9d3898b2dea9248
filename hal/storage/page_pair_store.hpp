#pragma once
/// A record kept in two flash pages, one copy in each (hal/storage/stored_slot.hpp frames it
/// with a sequence number, a CRC and a commit word). A save erases the page that does not hold
/// the newest copy and writes there, the commit word last: a power loss at any point leaves
/// the newest copy of before untouched on the other page, and the cut copy is not loaded. Load
/// takes the valid copy with the newer sequence number. No heap: the copy's buffer is a member,
/// sized for records up to MaxRecordBytes.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "hal/flash_pages.hpp"
#include "hal/parameter_store.hpp"
#include "hal/storage/stored_slot.hpp"

namespace imd::hal {

template <std::size_t MaxRecordBytes>
class PagePairStore final : public ParameterStore {
 public:
  explicit PagePairStore(FlashPages& flash) noexcept : flash_(flash) {}

  std::size_t load(std::span<uint8_t> out) noexcept override {
    const std::optional<Newest> newest = find_newest();
    if (!newest) return 0;
    read_page(newest->page);
    const std::optional<SlotView> slot = decode_slot(buffer_);
    if (!slot || slot->data.size() > out.size()) return 0;
    for (std::size_t i = 0; i < slot->data.size(); ++i) out[i] = slot->data[i];
    return slot->data.size();
  }

  bool save(std::span<const uint8_t> record) noexcept override {
    if (record.size() > MaxRecordBytes || slot_bytes(record.size()) > flash_.page_bytes() ||
        kSlotAlign % flash_.program_unit() != 0) {
      return false;
    }
    const std::optional<Newest> newest = find_newest();
    const int page = newest ? 1 - newest->page : 0;
    const uint32_t sequence = newest ? newest->sequence + 1 : 1;
    const std::size_t body = encode_slot_body(sequence, record, buffer_);
    if (!flash_.erase(page)) return false;
    if (!flash_.program(page, 0, std::span<const uint8_t>(buffer_).first(body))) return false;
    const auto commit = slot_commit_unit();
    return flash_.program(page, body, commit);
  }

 private:
  struct Newest {
    int page;
    uint32_t sequence;
  };

  void read_page(int page) noexcept {
    const std::size_t n = std::min(buffer_.size(), flash_.page_bytes());
    flash_.read(page, 0, std::span<uint8_t>(buffer_).first(n));
    for (std::size_t i = n; i < buffer_.size(); ++i) buffer_[i] = 0xFF;
  }

  std::optional<Newest> find_newest() noexcept {
    std::optional<Newest> best;
    for (int page = 0; page < 2; ++page) {
      read_page(page);
      const std::optional<SlotView> slot = decode_slot(buffer_);
      if (slot && (!best || newer(slot->sequence, best->sequence))) {
        best = Newest{page, slot->sequence};
      }
    }
    return best;
  }

  FlashPages& flash_;
  std::array<uint8_t, slot_bytes(MaxRecordBytes)> buffer_{};
};

}  // namespace imd::hal
