#pragma once
/// drive_sim's CSV: one row per tick, the columns of docs/scenarios.md, each number as "%.10g".
///
/// Rows are formatted into a memory buffer and written in blocks of about 1 MiB: formatting
/// with fmt and one fwrite per row cost 3.5x the simulation itself (docs/performance.md). A
/// column whose value has not changed since the last row reuses its text (a reference, the
/// state, a bus voltage), and the numbers go through format_g10 (csv_number.hpp).
#include <fmt/format.h>

#include <cstdint>
#include <cstdio>
#include <cstring>

#include "hal_sim/drive/tick_observer.hpp"

namespace imd::tools {

/// How rows are formatted: `fmt_per_row` is the method before the buffered writer (fmt's
/// "{:.10g}" for every number, one fwrite per row), kept as the benchmarks' baseline; the
/// text is the same.
enum class CsvFormatting { buffered, fmt_per_row };

class CsvWriter {
 public:
  /// Writes to `file` (not owned; the caller closes it after finish()).
  explicit CsvWriter(std::FILE* file, CsvFormatting formatting = CsvFormatting::buffered);
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  void header();
  void row(const sim::SimRow& r);
  /// Writes what is buffered. False when a write failed (disk full), now or before.
  bool finish();

  static constexpr std::size_t kColumns = 44;

 private:
  void flush_if_full();

  /// A column's last value and its text.
  struct Cached {
    uint64_t bits = 0;
    unsigned char length = 0;  ///< 0: nothing cached yet
    char text[31];
  };

  std::FILE* file_;
  CsvFormatting formatting_;
  fmt::memory_buffer buffer_;
  Cached cached_[kColumns];
  bool failed_ = false;
};

}  // namespace imd::tools
