#include "tools/drive_sim/csv_writer.hpp"

#include <bit>
#include <charconv>
#include <iterator>

#include "tools/drive_sim/csv_number.hpp"

namespace imd::tools {
namespace {

constexpr std::size_t kBlockBytes = std::size_t(1) << 20;

/// The CSV columns (docs/scenarios.md), in order: one list for the header and the rows.
#define IMD_CSV_COLUMNS(X) \
  X(t_s)                   \
  X(omega_mech_rad_s)      \
  X(omega_ref_rad_s)       \
  X(omega_est_rad_s)       \
  X(flux2_Wb2)             \
  X(flux2_ref_Wb2)         \
  X(flux2_est_Wb2)         \
  X(load_Nm)               \
  X(load_est_Nm)           \
  X(i_alpha_A)             \
  X(i_beta_A)              \
  X(v_alpha_V)             \
  X(v_beta_V)              \
  X(discriminant)          \
  X(c_k)                   \
  X(flux_A_Wb)             \
  X(flux_B_Wb)             \
  X(flux_A_est_Wb)         \
  X(flux_B_est_Wb)         \
  X(theta_mech_rad)        \
  X(theta_est_rad)         \
  X(torque_Nm)             \
  X(torque_ref_Nm)         \
  X(y2)                    \
  X(y2_ref)                \
  X(stator_flux2_Wb2)      \
  X(stator_flux2_ref_Wb2)  \
  X(i_hold_err_A)          \
  X(iol_boundary)          \
  X(state)                 \
  X(saturated)             \
  X(omega_ref_cmd_rad_s)   \
  X(flux2_ctrl_est_Wb2)    \
  X(flux2_ctrl_ref_Wb2)    \
  X(iA_est_A)              \
  X(iB_est_A)              \
  X(v_bus_meas_V)          \
  X(u_alpha_cmd_V)         \
  X(u_beta_cmd_V)          \
  X(rr_est_Ohm)            \
  X(Rr_plant_Ohm)          \
  X(limited)               \
  X(stop)                  \
  X(brake_engaged)

#define IMD_COLUMN_NAME(field) #field,
constexpr const char* kColumnNames[] = {IMD_CSV_COLUMNS(IMD_COLUMN_NAME)};
#undef IMD_COLUMN_NAME
static_assert(std::size(kColumnNames) == CsvWriter::kColumns);

/// A row's columns as numbers, in one pass (no call per column).
void column_values(const sim::SimRow& r, double* values) noexcept {
  std::size_t i = 0;
#define IMD_COLUMN_VALUE(field) values[i++] = static_cast<double>(r.field);
  IMD_CSV_COLUMNS(IMD_COLUMN_VALUE)
#undef IMD_COLUMN_VALUE
}

}  // namespace

CsvWriter::CsvWriter(std::FILE* file, CsvFormatting formatting)
    : file_(file), formatting_(formatting) {
  buffer_.reserve(kBlockBytes + 4096);
}

void CsvWriter::header() {
  for (std::size_t i = 0; i < kColumns; ++i) {
    buffer_.append(std::string_view(kColumnNames[i]));
    buffer_.push_back(i + 1 == kColumns ? '\n' : ',');
  }
  flush_buffer();
}

void CsvWriter::row(const sim::SimRow& r) {
  if (formatting_ != CsvFormatting::threaded) {
    format(r);
    return;
  }
  if (!thread_) {
    thread_ = std::make_unique<RowThread<sim::SimRow>>(
        [this](const sim::SimRow* rows, std::size_t count) {
          for (std::size_t i = 0; i < count; ++i) format(rows[i]);
        });
  }
  thread_->push(r);
}

void CsvWriter::format(const sim::SimRow& r) {
  double values[kColumns];
  column_values(r, values);
  if (formatting_ == CsvFormatting::fmt_per_row) {
    fmt::memory_buffer line;
    for (const double value : values) fmt::format_to(std::back_inserter(line), "{:.10g},", value);
    line[line.size() - 1] = '\n';
    if (std::fwrite(line.data(), 1, line.size(), file_) != line.size()) failed_ = true;
    return;
  }
  // A row is at most 44 x 24 characters: room for it, then format in place.
  const std::size_t start = buffer_.size();
  buffer_.resize(start + kColumns * 32);
  char* out = buffer_.data() + start;
  for (std::size_t i = 0; i < kColumns; ++i) {
    const double value = values[i];
    Cached& cached = cached_[i];
    const uint64_t bits = std::bit_cast<uint64_t>(value);
    if (cached.length == 0 || cached.bits != bits) {
      cached.bits = bits;
      const char* end =
          formatting_ == CsvFormatting::buffered_to_chars
              ? std::to_chars(cached.text, cached.text + 24, value, std::chars_format::general, 10)
                    .ptr
              : format_g10(value, cached.text);
      cached.length = static_cast<unsigned char>(end - cached.text);
    }
    std::memcpy(out, cached.text, 24);  // a fixed size copies faster; the room is there
    out += cached.length;
    *out++ = ',';
  }
  out[-1] = '\n';
  buffer_.resize(std::size_t(out - buffer_.data()));
  if (buffer_.size() >= kBlockBytes) flush_buffer();
}

bool CsvWriter::finish() {
  thread_.reset();  // drains: every row formatted, the thread ended
  flush_buffer();
  return !failed_;
}

void CsvWriter::flush_buffer() {
  if (buffer_.size() != 0 &&
      std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size()) {
    failed_ = true;
  }
  buffer_.clear();
}

}  // namespace imd::tools
