#pragma once
/// The parameter record in a file on Linux. A save writes the whole framed copy
/// (hal/storage/stored_slot.hpp) to PATH.tmp, flushes it to the disk, renames it over PATH and
/// flushes the directory: rename is atomic, so after a crash PATH holds the old copy or the new
/// one, whole. The frame's CRC and commit word still guard against a file cut or edited by
/// other means. Not for tick context.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "hal/parameter_store.hpp"

namespace imd::hal {

class FileParameterStore final : public ParameterStore {
 public:
  explicit FileParameterStore(std::string path) : path_(std::move(path)) {}

  std::size_t load(std::span<uint8_t> out) noexcept override;
  bool save(std::span<const uint8_t> record) noexcept override;

  const std::string& path() const noexcept { return path_; }
  /// Why the last load found nothing or the last save failed ("" after success).
  const std::string& last_error() const noexcept { return error_; }

 private:
  std::string path_;
  std::string error_;
};

}  // namespace imd::hal
