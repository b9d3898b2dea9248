#include "hal/linux/gpiod_lines.hpp"

#include <gpiod.h>

#include <cerrno>
#include <cstring>

namespace imd::hal {
namespace {

std::string text(const char* maybe_null) {
  return maybe_null != nullptr ? maybe_null : "";
}

/// "gpiochip0 (9030000.pl061)" or, with a line count, "gpiochip0 (9030000.pl061, 8 lines)".
std::string chip_title(const std::string& name, const std::string& label, std::string count = {}) {
  std::string details = label;
  if (!count.empty()) details += (details.empty() ? "" : ", ") + count;
  return details.empty() ? name : name + " (" + details + ")";
}

/// "fault output line 9", or "line 9" without a role.
std::string line_title(const GpioLineSpec& line) {
  const std::string offset = "line " + std::to_string(line.offset);
  return line.role.empty() ? offset : line.role + " " + offset;
}

}  // namespace

std::string validate_line_specs(const std::vector<GpioLineSpec>& lines) {
  if (lines.empty()) return "no GPIO lines to request";
  if (lines.size() > kMaxGpioLines) {
    return std::to_string(lines.size()) + " GPIO lines requested, at most " +
           std::to_string(kMaxGpioLines);
  }
  const auto role = [&](std::size_t i) {
    return lines[i].role.empty() ? "lines[" + std::to_string(i) + "]" : lines[i].role;
  };
  for (std::size_t i = 0; i < lines.size(); ++i) {
    for (std::size_t j = i + 1; j < lines.size(); ++j) {
      if (lines[i].offset == lines[j].offset) {
        return role(i) + " and " + role(j) + " both use line " + std::to_string(lines[i].offset);
      }
    }
  }
  return {};
}

std::string describe_open_error(const std::string& chip, int error_number) {
  switch (error_number) {
    case ENOENT:
      // gpiod_chip_open_lookup opens a path as such only under /dev/: "/run/x" becomes
      // "/dev//run/x".
      if (chip.starts_with('/') && !chip.starts_with("/dev/")) {
        return chip + ": no such GPIO chip (libgpiod opens paths under /dev/ only)";
      }
      return chip + ": no such GPIO chip";
    case ENOTTY:  // libgpiod's answer for a file that is not a GPIO character device
      return chip + ": not a GPIO chip";
    case EACCES:
    case EPERM:
      return chip + ": permission denied (the GPIO chip device needs read and write access)";
    case 0:
      return chip + ": cannot open GPIO chip";
    default:
      return chip + ": " + std::strerror(error_number);
  }
}

std::string describe_range_error(const std::string& chip_name, const std::string& chip_label,
                                 unsigned num_lines, const GpioLineSpec& line) {
  const std::string count = std::to_string(num_lines) + (num_lines == 1 ? " line" : " lines");
  const std::string range =
      num_lines == 0 ? "the chip has no lines" : "0.." + std::to_string(num_lines - 1);
  return chip_title(chip_name, chip_label, count) + ": " + line_title(line) + " out of range (" +
         range + ")";
}

std::string describe_line_error(const std::string& chip_name, const std::string& chip_label,
                                const GpioLineSpec& line, int error_number,
                                const std::string& consumer) {
  const std::string head = chip_title(chip_name, chip_label) + ": " + line_title(line);
  if (error_number == EBUSY) {
    return consumer.empty() ? head + " is busy" : head + " is busy (used by \"" + consumer + "\")";
  }
  return head + ": " + (error_number != 0 ? std::strerror(error_number) : "request failed");
}

GpiodLines::GpiodLines(gpiod_chip* chip)
    : chip_(chip),
      chip_name_(text(gpiod_chip_name(chip))),
      chip_label_(text(gpiod_chip_label(chip))) {}

std::unique_ptr<GpiodLines> GpiodLines::open(const std::string& chip,
                                             const std::vector<GpioLineSpec>& lines,
                                             const std::string& consumer, std::string& error) {
  // gpiod_chip_open_lookup("") opens /dev/gpiochip0: an empty name must not get that far.
  if (chip.empty()) {
    error = "empty GPIO chip name";
    return nullptr;
  }
  if (const std::string why = validate_line_specs(lines); !why.empty()) {
    error = chip + ": " + why;
    return nullptr;
  }
  errno = 0;
  gpiod_chip* handle = gpiod_chip_open_lookup(chip.c_str());
  if (handle == nullptr) {
    error = describe_open_error(chip, errno);
    return nullptr;
  }
  // Owns the chip from here: an early return closes it and resets the lines requested so far.
  std::unique_ptr<GpiodLines> result(new GpiodLines(handle));
  const unsigned num_lines = gpiod_chip_num_lines(handle);
  for (const GpioLineSpec& spec : lines) {  // every offset checked before any line is requested
    if (spec.offset >= num_lines) {
      error = describe_range_error(result->chip_name_, result->chip_label_, num_lines, spec);
      return nullptr;
    }
  }
  result->lines_.reserve(lines.size());
  for (const GpioLineSpec& spec : lines) {
    gpiod_line* line = gpiod_chip_get_line(handle, spec.offset);
    const gpiod_line_request_config config{
        consumer.c_str(),
        spec.output ? GPIOD_LINE_REQUEST_DIRECTION_OUTPUT : GPIOD_LINE_REQUEST_DIRECTION_INPUT,
        spec.active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0};
    if (line == nullptr || gpiod_line_request(line, &config, spec.initial_level ? 1 : 0) != 0) {
      const int e = errno;
      // The consumer read by gpiod_chip_get_line may be stale: ask the kernel again.
      std::string user;
      if (line != nullptr && e == EBUSY && gpiod_line_update(line) == 0) {
        user = text(gpiod_line_consumer(line));
      }
      error = describe_line_error(result->chip_name_, result->chip_label_, spec, e, user);
      return nullptr;
    }
    result->lines_.push_back({line, spec.output});
  }
  return result;
}

GpiodLines::~GpiodLines() {
  // A released output keeps its last level, so leave each one inactive (logical 0).
  for (const Line& line : lines_) {
    if (line.output) gpiod_line_set_value(line.handle, 0);
  }
  gpiod_chip_close(chip_);  // releases the requested lines too
}

void GpiodLines::write(uint8_t line, bool level) noexcept {
  if (line >= lines_.size() || !lines_[line].output ||
      gpiod_line_set_value(lines_[line].handle, level ? 1 : 0) != 0) {
    ++io_errors_;
  }
}

bool GpiodLines::read(uint8_t line) const noexcept {
  const int value = line < lines_.size() ? gpiod_line_get_value(lines_[line].handle) : -1;
  if (value < 0) {
    ++io_errors_;
    return false;
  }
  return value != 0;
}

}  // namespace imd::hal
