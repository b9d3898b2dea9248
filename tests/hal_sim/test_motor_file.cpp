// The TOML motor file: the shipped files load, and every kind of bad input is rejected with a
// message of its own that names the key and the value.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "hal_sim/config_error.hpp"
#include "hal_sim/motor_file.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

const std::string kGoodTable = R"([motor]
Rs_Ohm = 14.0
Ls_H = 0.4
Lm_H = 0.377
Rr_Ohm = 10.1
Lr_H = 0.4128
J_kgm2 = 0.01
pole_pairs = 1
friction_Nms = 0.0
)";

/// The good table with the line that starts with `key =` replaced (or removed if empty).
std::string with_line(const std::string& key, const std::string& replacement) {
  std::string text = kGoodTable;
  const auto start = text.find(key + " =");
  const auto end = text.find('\n', start);
  text.replace(start, end - start + 1, replacement.empty() ? "" : replacement + "\n");
  return text;
}

std::string error_of_text(const std::string& text) {
  try {
    parse_motor_table(toml::parse(text), "test.toml");
  } catch (const ConfigError& error) {
    return error.what();
  }
  return "(no error)";
}

/// A file in a directory of this test process alone, so that parallel runs of the suite (two
/// build trees) cannot read each other's half-written files.
std::filesystem::path write_temp(const std::string& name, const std::string& text) {
  const auto directory = std::filesystem::temp_directory_path() /
                         ("imd_test_motor_file_" + std::to_string(::getpid()));
  std::filesystem::create_directories(directory);
  const auto path = directory / name;
  std::ofstream(path) << text;
  return path;
}

TEST(MotorFile, ShippedMotorsLoad) {
  const auto paper000 = load_motor_file(test::source_path("hal_sim/motors/seed000.toml"));
  EXPECT_EQ(paper000.Rs_Ohm, 14.0);
  EXPECT_EQ(paper000.Lr_H, 0.4128);
  EXPECT_EQ(paper000.pole_pairs, 1);
  const auto paper001 = load_motor_file(test::source_path("hal_sim/motors/seed001.toml"));
  EXPECT_EQ(paper001.Lm_H, 0.031);  // paper 001's m
  EXPECT_EQ(paper001.pole_pairs, 2);
  EXPECT_EQ(paper001.friction_Nms, 1e-4);
}

TEST(MotorFile, IntegersAreAcceptedForRealKeysAndExtraKeysAreFree) {
  const auto m = parse_motor_table(
      toml::parse(with_line("Rs_Ohm", "Rs_Ohm = 14\nname = \"x\"\nrated_power_W = 750")), "t");
  EXPECT_EQ(m.Rs_Ohm, 14.0);
}

TEST(MotorFile, EachBadInputHasItsOwnMessage) {
  struct Case {
    std::string text;
    std::string message;
  };
  const Case cases[] = {
      {with_line("Rs_Ohm", ""), "test.toml: missing key motor.Rs_Ohm"},
      {with_line("friction_Nms", ""), "test.toml: missing key motor.friction_Nms"},
      {with_line("Ls_H", "Ls_H = -0.4"), "test.toml: motor.Ls_H = -0.4: must be > 0"},
      {with_line("J_kgm2", "J_kgm2 = 0.0"), "test.toml: motor.J_kgm2 = 0: must be > 0"},
      {with_line("Rr_Ohm", "Rr_Ohm = nan"), "test.toml: motor.Rr_Ohm = nan: must be finite"},
      {with_line("Lr_H", "Lr_H = inf"), "test.toml: motor.Lr_H = inf: must be finite"},
      {with_line("friction_Nms", "friction_Nms = -0.5"),
       "test.toml: motor.friction_Nms = -0.5: must be >= 0"},
      {with_line("Lm_H", "Lm_H = 0.5"),
       "test.toml: motor.Lm_H = 0.5: must satisfy Lm_H^2 <= 0.999 Ls_H * Lr_H"},
      {with_line("Rs_Ohm", "Rs_Ohm = \"14\""),
       "test.toml: motor.Rs_Ohm must be a number, got a string"},
      {with_line("pole_pairs", "pole_pairs = 1.5"),
       "test.toml: motor.pole_pairs = 1.5: must be an integer"},
      {with_line("pole_pairs", "pole_pairs = 2.0"),
       "test.toml: motor.pole_pairs = 2.0: must be an integer"},
      {with_line("pole_pairs", "pole_pairs = \"2\""),
       "test.toml: motor.pole_pairs must be an integer, got a string"},
      {with_line("pole_pairs", "pole_pairs = 0"),
       "test.toml: motor.pole_pairs = 0: must be an integer in 1..32"},
      {"[drive]\nsample_period_s = 1e-4\n", "test.toml: missing table [motor]"},
      {"motor = 3\n", "test.toml: motor must be a table, got an integer"},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(error_of_text(c.text), c.message);
  }
}

TEST(MotorFile, SyntaxErrorNamesFileLineAndColumn) {
  const auto path = write_temp("imd_bad_syntax.toml", "[motor]\nRs_Ohm = = 14.0\n");
  try {
    load_motor_file(path);
    FAIL() << "no error";
  } catch (const ConfigError& error) {
    EXPECT_TRUE(std::string(error.what()).starts_with(path.string() + ":2:")) << error.what();
    EXPECT_NE(std::string(error.what()).find("TOML syntax error"), std::string::npos);
  }
}

TEST(MotorFile, MissingFileIsAClearError) {
  try {
    load_motor_file("/nonexistent/motor.toml");
    FAIL() << "no error";
  } catch (const ConfigError& error) {
    EXPECT_STREQ(error.what(), "/nonexistent/motor.toml: cannot open file");
  }
}

TEST(MotorFile, DirectoryIsAClearError) {
  const auto directory = write_temp("placeholder.toml", "").parent_path();
  try {
    load_motor_file(directory);
    FAIL() << "no error";
  } catch (const ConfigError& error) {
    EXPECT_EQ(std::string(error.what()), directory.string() + ": not a regular file");
  }
}

TEST(MotorFile, ErrorsFromAFileNameTheFile) {
  const auto path = write_temp("imd_bad_value.toml", with_line("Rs_Ohm", "Rs_Ohm = -3.2"));
  try {
    load_motor_file(path);
    FAIL() << "no error";
  } catch (const ConfigError& error) {
    EXPECT_EQ(std::string(error.what()), path.string() + ": motor.Rs_Ohm = -3.2: must be > 0");
  }
}

}  // namespace
}  // namespace imd::sim

namespace imd::sim {
namespace {

// A written motor file reads back bit for bit, whatever the values' magnitudes.
TEST(MotorFileText, ReadsBackExactly) {
  for (const auto& motor : test::test_motors()) {
    control::MotorParameters m = motor.parameters;
    m.friction_Nms = 0.0;  // "0" would be an integer in TOML: written as 0.0
    const std::string text = motor_file_text(m, "a \"quoted\" name", "line one\nline two");
    EXPECT_EQ(text.rfind("# line one\n# line two\n[motor]\n", 0), 0u) << text;
    const toml::table doc = toml::parse(text);
    const control::MotorParameters back = parse_motor_table(doc, "written");
    EXPECT_EQ(back.Rs_Ohm, m.Rs_Ohm);
    EXPECT_EQ(back.Ls_H, m.Ls_H);
    EXPECT_EQ(back.Lm_H, m.Lm_H);
    EXPECT_EQ(back.Rr_Ohm, m.Rr_Ohm);
    EXPECT_EQ(back.Lr_H, m.Lr_H);
    EXPECT_EQ(back.J_kgm2, m.J_kgm2);
    EXPECT_EQ(back.pole_pairs, m.pole_pairs);
    EXPECT_EQ(back.friction_Nms, 0.0);
    EXPECT_EQ(doc["motor"]["name"].value<std::string>(), "a \"quoted\" name");
  }
}

}  // namespace
}  // namespace imd::sim
