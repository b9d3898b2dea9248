#pragma once
/// Persistent storage of one record (the motor parameters): the newest copy that was written
/// whole is loaded, and a save that is cut off by a power loss leaves the previous copy
/// loadable. Backends: a flash page pair (hal/storage/page_pair_store.hpp over the board's
/// flash driver; the STM32G4 and the simulated flash), and a file on Linux
/// (hal/linux/file_parameter_store.hpp). Not for tick context: a save erases flash or syncs a
/// file, milliseconds.
#include <cstddef>
#include <cstdint>
#include <span>

namespace imd::hal {

class ParameterStore {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so no
  // deleting destructor and no operator delete in the firmware's vtables.
  ~ParameterStore() = default;

 public:
  /// Copies the newest whole record into `out`; returns its length, 0 when there is none (or it
  /// does not fit in `out`).
  virtual std::size_t load(std::span<uint8_t> out) noexcept = 0;
  /// Writes `record` as the newest copy; false if the medium refused (the previous copy stays).
  virtual bool save(std::span<const uint8_t> record) noexcept = 0;
};

}  // namespace imd::hal
