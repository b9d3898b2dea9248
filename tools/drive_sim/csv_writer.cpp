#include "tools/drive_sim/csv_writer.hpp"

#include <bit>
#include <iterator>

#include "tools/drive_sim/csv_number.hpp"

namespace imd::tools {
namespace {

constexpr std::size_t kBlockBytes = std::size_t(1) << 20;

/// The CSV columns (docs/scenarios.md): one table for the header and the rows.
struct Column {
  const char* name;
  double (*value)(const sim::SimRow&);
};
#define IMD_COLUMN(field) \
  Column { #field, [](const sim::SimRow& r) { return static_cast<double>(r.field); } }
const Column kColumnTable[] = {
    IMD_COLUMN(t_s),
    IMD_COLUMN(omega_mech_rad_s),
    IMD_COLUMN(omega_ref_rad_s),
    IMD_COLUMN(omega_est_rad_s),
    IMD_COLUMN(flux2_Wb2),
    IMD_COLUMN(flux2_ref_Wb2),
    IMD_COLUMN(flux2_est_Wb2),
    IMD_COLUMN(load_Nm),
    IMD_COLUMN(load_est_Nm),
    IMD_COLUMN(i_alpha_A),
    IMD_COLUMN(i_beta_A),
    IMD_COLUMN(v_alpha_V),
    IMD_COLUMN(v_beta_V),
    IMD_COLUMN(discriminant),
    IMD_COLUMN(c_k),
    IMD_COLUMN(flux_A_Wb),
    IMD_COLUMN(flux_B_Wb),
    IMD_COLUMN(flux_A_est_Wb),
    IMD_COLUMN(flux_B_est_Wb),
    IMD_COLUMN(theta_mech_rad),
    IMD_COLUMN(theta_est_rad),
    IMD_COLUMN(torque_Nm),
    IMD_COLUMN(torque_ref_Nm),
    IMD_COLUMN(y2),
    IMD_COLUMN(y2_ref),
    IMD_COLUMN(stator_flux2_Wb2),
    IMD_COLUMN(stator_flux2_ref_Wb2),
    IMD_COLUMN(i_hold_err_A),
    IMD_COLUMN(iol_boundary),
    IMD_COLUMN(state),
    IMD_COLUMN(saturated),
    IMD_COLUMN(omega_ref_cmd_rad_s),
    IMD_COLUMN(flux2_ctrl_est_Wb2),
    IMD_COLUMN(flux2_ctrl_ref_Wb2),
    IMD_COLUMN(iA_est_A),
    IMD_COLUMN(iB_est_A),
    IMD_COLUMN(v_bus_meas_V),
    IMD_COLUMN(u_alpha_cmd_V),
    IMD_COLUMN(u_beta_cmd_V),
    IMD_COLUMN(rr_est_Ohm),
    IMD_COLUMN(Rr_plant_Ohm),
    IMD_COLUMN(limited),
    IMD_COLUMN(stop),
    IMD_COLUMN(brake_engaged),
};
#undef IMD_COLUMN
static_assert(std::size(kColumnTable) == CsvWriter::kColumns);

}  // namespace

CsvWriter::CsvWriter(std::FILE* file, CsvFormatting formatting)
    : file_(file), formatting_(formatting) {
  buffer_.reserve(kBlockBytes + 4096);
}

void CsvWriter::header() {
  for (const Column& column : kColumnTable) {
    buffer_.append(std::string_view(column.name));
    buffer_.push_back(&column == &kColumnTable[kColumns - 1] ? '\n' : ',');
  }
  finish();
}

void CsvWriter::row(const sim::SimRow& r) {
  if (formatting_ == CsvFormatting::fmt_per_row) {
    fmt::memory_buffer line;
    for (const Column& column : kColumnTable) {
      fmt::format_to(std::back_inserter(line), "{:.10g},", column.value(r));
    }
    line[line.size() - 1] = '\n';
    if (std::fwrite(line.data(), 1, line.size(), file_) != line.size()) failed_ = true;
    return;
  }
  // A row is at most 44 x 24 characters: room for it, then format in place.
  const std::size_t start = buffer_.size();
  buffer_.resize(start + kColumns * 32);
  char* out = buffer_.data() + start;
  for (std::size_t i = 0; i < kColumns; ++i) {
    const double value = kColumnTable[i].value(r);
    Cached& cached = cached_[i];
    const uint64_t bits = std::bit_cast<uint64_t>(value);
    if (cached.length == 0 || cached.bits != bits) {
      cached.bits = bits;
      cached.length = static_cast<unsigned char>(format_g10(value, cached.text) - cached.text);
    }
    std::memcpy(out, cached.text, cached.length);
    out += cached.length;
    *out++ = ',';
  }
  out[-1] = '\n';
  buffer_.resize(std::size_t(out - buffer_.data()));
  flush_if_full();
}

void CsvWriter::flush_if_full() {
  if (buffer_.size() >= kBlockBytes) finish();
}

bool CsvWriter::finish() {
  if (buffer_.size() != 0 &&
      std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size()) {
    failed_ = true;
  }
  buffer_.clear();
  return !failed_;
}

}  // namespace imd::tools
