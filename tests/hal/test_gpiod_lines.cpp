// GpiodLines without a GPIO chip: the checks made before the kernel is asked, the failures this
// host really gives (no such chip, a character device that is not a GPIO chip) and the wording of
// the range and busy messages. Reads and writes on a real chip are the qemu tier's (PL061).
#include <gtest/gtest.h>

#include <cerrno>
#include <string>
#include <vector>

#include "hal/linux/gpiod_lines.hpp"

namespace imd::hal {
namespace {

GpioLineSpec input(unsigned offset, std::string role) {
  GpioLineSpec spec;
  spec.offset = offset;
  spec.role = std::move(role);
  return spec;
}

GpioLineSpec output(unsigned offset, std::string role) {
  GpioLineSpec spec = input(offset, std::move(role));
  spec.output = true;
  return spec;
}

const std::vector<GpioLineSpec> kBoard = {input(3, "enable input"), output(9, "fault output"),
                                          output(5, "timing output")};

TEST(gpiod_lines_open, NamesAMissingChip) {
  std::string error;
  EXPECT_EQ(GpiodLines::open("gpiochip999", kBoard, "imd-test", error), nullptr);
  EXPECT_EQ(error, "gpiochip999: no such GPIO chip");
  EXPECT_EQ(GpiodLines::open("/dev/gpiochip999", kBoard, "imd-test", error), nullptr);
  EXPECT_EQ(error, "/dev/gpiochip999: no such GPIO chip");
  EXPECT_EQ(GpiodLines::open("imd-no-such-label", kBoard, "imd-test", error), nullptr);  // a label
  EXPECT_EQ(error, "imd-no-such-label: no such GPIO chip");
}

TEST(gpiod_lines_open, SaysThatPathsOutsideDevAreNotOpened) {
  std::string error;
  EXPECT_EQ(GpiodLines::open("/etc/hostname", kBoard, "imd-test", error), nullptr);
  EXPECT_EQ(error, "/etc/hostname: no such GPIO chip (libgpiod opens paths under /dev/ only)");
}

TEST(gpiod_lines_open, RejectsADeviceThatIsNotAGpioChip) {
  std::string error;
  EXPECT_EQ(GpiodLines::open("/dev/null", kBoard, "imd-test", error), nullptr);
  EXPECT_EQ(error, "/dev/null: not a GPIO chip");
}

TEST(gpiod_lines_open, RejectsAnEmptyChipName) {
  // libgpiod would take "" for chip number 0.
  std::string error;
  EXPECT_EQ(GpiodLines::open("", kBoard, "imd-test", error), nullptr);
  EXPECT_EQ(error, "empty GPIO chip name");
}

TEST(gpiod_lines_open, RejectsAnEmptyLineList) {
  std::string error;
  EXPECT_EQ(GpiodLines::open("gpiochip0", {}, "imd-test", error), nullptr);
  EXPECT_EQ(error, "gpiochip0: no GPIO lines to request");
}

TEST(gpiod_lines_open, ChecksTheLinesBeforeLookingForTheChip) {
  // gpiochip7 does not exist: the duplicate is reported, so the chip was never looked up.
  std::vector<GpioLineSpec> lines = kBoard;
  lines.push_back(output(5, "brake output"));
  std::string error;
  EXPECT_EQ(GpiodLines::open("gpiochip7", lines, "imd-test", error), nullptr);
  EXPECT_EQ(error, "gpiochip7: timing output and brake output both use line 5");
}

TEST(gpiod_line_specs, AcceptsDistinctOffsets) {
  EXPECT_EQ(validate_line_specs(kBoard), "");
}

TEST(gpiod_line_specs, NamesBothRolesOfADuplicateOffset) {
  EXPECT_EQ(validate_line_specs(
                {output(5, "fault output"), input(3, "enable input"), output(5, "timing output")}),
            "fault output and timing output both use line 5");
  // Without roles the entries are named by their index.
  EXPECT_EQ(validate_line_specs({input(1, ""), input(2, ""), input(1, "")}),
            "lines[0] and lines[2] both use line 1");
}

TEST(gpiod_line_specs, AllowsAtMost255Lines) {
  std::vector<GpioLineSpec> lines;
  for (unsigned i = 0; i < kMaxGpioLines; ++i) lines.push_back(input(i, "input"));
  EXPECT_EQ(validate_line_specs(lines), "");
  lines.push_back(input(255, "input"));
  EXPECT_EQ(validate_line_specs(lines), "256 GPIO lines requested, at most 255");
  std::string error;
  EXPECT_EQ(GpiodLines::open("gpiochip0", lines, "imd-test", error), nullptr);
  EXPECT_EQ(error, "gpiochip0: 256 GPIO lines requested, at most 255");
}

TEST(gpiod_messages, OpenErrorsNameTheChip) {
  EXPECT_EQ(describe_open_error("gpiochip7", ENOENT), "gpiochip7: no such GPIO chip");
  EXPECT_EQ(describe_open_error("/dev/null", ENOTTY), "/dev/null: not a GPIO chip");
  EXPECT_EQ(describe_open_error("gpiochip0", EACCES),
            "gpiochip0: permission denied (the GPIO chip device needs read and write access)");
  EXPECT_EQ(describe_open_error("/dev/tty", ENXIO), "/dev/tty: No such device or address");
}

TEST(gpiod_messages, RangeErrorGivesTheChipLabelAndValidOffsets) {
  EXPECT_EQ(describe_range_error("gpiochip0", "9030000.pl061", 8, output(9, "fault output")),
            "gpiochip0 (9030000.pl061, 8 lines): fault output line 9 out of range (0..7)");
  EXPECT_EQ(describe_range_error("gpiochip2", "", 1, input(1, "")),
            "gpiochip2 (1 line): line 1 out of range (0..0)");
  EXPECT_EQ(describe_range_error("gpiochip3", "empty", 0, input(0, "enable input")),
            "gpiochip3 (empty, 0 lines): enable input line 0 out of range (the chip has no lines)");
}

TEST(gpiod_messages, BusyLineNamesItsUser) {
  EXPECT_EQ(describe_line_error("gpiochip0", "9030000.pl061", input(3, "enable input"), EBUSY,
                                "gpio-keys"),
            "gpiochip0 (9030000.pl061): enable input line 3 is busy (used by \"gpio-keys\")");
  EXPECT_EQ(describe_line_error("gpiochip0", "9030000.pl061", input(3, "enable input"), EBUSY, ""),
            "gpiochip0 (9030000.pl061): enable input line 3 is busy");
}

TEST(gpiod_messages, OtherRequestErrorsGiveTheErrnoText) {
  EXPECT_EQ(describe_line_error("gpiochip0", "", output(4, "fault output"), EINVAL, ""),
            "gpiochip0: fault output line 4: Invalid argument");
}

}  // namespace
}  // namespace imd::hal
