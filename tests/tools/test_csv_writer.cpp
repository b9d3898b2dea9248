// drive_sim's CSV writer (tools/drive_sim/csv_writer.hpp): every formatting method writes the
// same file, byte for byte, the threaded one included, over more rows than its blocks hold
// (so that the worker takes several blocks, a partial one last), with values that repeat
// (the column cache) and values that change every row.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "tools/drive_sim/csv_writer.hpp"

namespace {

std::vector<imd::sim::SimRow> rows(int count) {
  std::mt19937_64 random(11);
  std::normal_distribution<double> normal;
  std::vector<imd::sim::SimRow> out(std::size_t(count), imd::sim::SimRow{});
  for (int k = 0; k < count; ++k) {
    imd::sim::SimRow& r = out[std::size_t(k)];
    r.t_s = k * 1e-4;
    r.omega_mech_rad_s = 50.0 + normal(random);
    r.omega_ref_rad_s = k < count / 2 ? 0.0 : 50.0;  // repeats: the cached text
    r.i_alpha_A = normal(random) * 1e-6;
    r.v_bus_meas_V = 300.0 + double(k % 3);
    r.theta_mech_rad = normal(random) * 1e12;
    r.state = k % 5;
    r.saturated = (k % 7) == 0;
  }
  return out;
}

std::string written(imd::tools::CsvFormatting formatting,
                    const std::vector<imd::sim::SimRow>& input) {
  std::FILE* file = std::tmpfile();
  EXPECT_NE(file, nullptr);
  if (file == nullptr) return {};
  imd::tools::CsvWriter writer(file, formatting);
  writer.header();
  for (const imd::sim::SimRow& r : input) writer.row(r);
  EXPECT_TRUE(writer.finish());
  std::string text(std::size_t(std::ftell(file)), '\0');
  std::rewind(file);
  EXPECT_EQ(std::fread(text.data(), 1, text.size(), file), text.size());
  std::fclose(file);
  return text;
}

TEST(CsvWriter, EveryMethodWritesTheSameBytes) {
  using imd::tools::CsvFormatting;
  const std::vector<imd::sim::SimRow> input = rows(3000);  // 11 blocks of 256 and a part
  const std::string reference = written(CsvFormatting::fmt_per_row, input);
  EXPECT_EQ(std::count(reference.begin(), reference.end(), '\n'), 3001);
  EXPECT_EQ(written(CsvFormatting::buffered_to_chars, input), reference);
  EXPECT_EQ(written(CsvFormatting::buffered, input), reference);
  EXPECT_EQ(written(CsvFormatting::threaded, input), reference);
}

// finish() writes every row given so far, and the writer goes on after it.
TEST(CsvWriter, FinishThenMoreRows) {
  using imd::tools::CsvFormatting;
  const std::vector<imd::sim::SimRow> input = rows(600);
  const std::string reference = written(CsvFormatting::buffered, input);
  std::FILE* file = std::tmpfile();
  ASSERT_NE(file, nullptr);
  imd::tools::CsvWriter writer(file, CsvFormatting::threaded);
  writer.header();
  for (std::size_t k = 0; k < input.size(); ++k) {
    writer.row(input[k]);
    if (k == 300) {
      EXPECT_TRUE(writer.finish());
    }
  }
  EXPECT_TRUE(writer.finish());
  std::string text(std::size_t(std::ftell(file)), '\0');
  std::rewind(file);
  EXPECT_EQ(std::fread(text.data(), 1, text.size(), file), text.size());
  std::fclose(file);
  EXPECT_EQ(text, reference);
}

// A write that fails (a full disk) makes finish() false, for every method: with the threaded
// one the failure happens on the worker and must reach the caller.
TEST(CsvWriter, AFullDiskIsReported) {
  using imd::tools::CsvFormatting;
  const std::vector<imd::sim::SimRow> input = rows(3000);
  for (CsvFormatting formatting : {CsvFormatting::threaded, CsvFormatting::buffered,
                                   CsvFormatting::buffered_to_chars, CsvFormatting::fmt_per_row}) {
    std::FILE* file = std::fopen("/dev/full", "w");
    ASSERT_NE(file, nullptr) << "no /dev/full";
    imd::tools::CsvWriter writer(file, formatting);
    writer.header();
    for (const imd::sim::SimRow& r : input) writer.row(r);
    EXPECT_FALSE(writer.finish()) << "method " << static_cast<int>(formatting);
    EXPECT_FALSE(writer.finish()) << "a failure stays reported";
    std::fclose(file);
  }
}

}  // namespace
