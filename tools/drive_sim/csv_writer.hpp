#pragma once
/// drive_sim's CSV: one row per tick, the columns of docs/scenarios.md, each number as "%.10g".
///
/// Rows are formatted into a memory buffer and written in blocks of about 1 MiB: formatting
/// with fmt and one fwrite per row cost 3.5x the simulation itself (docs/performance.md). A
/// column whose value has not changed since the last row reuses its text (a reference, the
/// state, a bus voltage), and the numbers go through format_g10 (csv_number.hpp). By default
/// the rows are formatted and written on a second thread (row_thread.hpp), in their order:
/// the file is the same, byte for byte.
#include <fmt/format.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>

#include "hal_sim/drive/tick_observer.hpp"
#include "tools/drive_sim/row_thread.hpp"

namespace imd::tools {

/// How rows are formatted, all to the same text: `threaded` formats with format_g10 on a
/// second thread, `buffered` the same on the caller's. The earlier methods are kept as the
/// benchmarks' baselines: `buffered_to_chars` (std::to_chars with a precision for every
/// number, on the caller's thread) and `fmt_per_row` (fmt's "{:.10g}", one fwrite per row).
enum class CsvFormatting { threaded, buffered, buffered_to_chars, fmt_per_row };

class CsvWriter {
 public:
  /// Writes to `file` (not owned; the caller closes it after finish()).
  explicit CsvWriter(std::FILE* file, CsvFormatting formatting = CsvFormatting::threaded);
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  void header();
  void row(const sim::SimRow& r);
  /// Writes every row given so far. False when a write failed (disk full), now or before.
  bool finish();

  static constexpr std::size_t kColumns = 44;

 private:
  void format(const sim::SimRow& r);  ///< into buffer_ (on the thread when threaded)
  void flush_buffer();

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
  std::unique_ptr<RowThread<sim::SimRow>> thread_;  ///< threaded: from the first row to finish()
};

}  // namespace imd::tools
