#pragma once
/// hal::Gpio over libgpiod's v1 C API (Debian 12: libgpiod 1.6): a fixed set of lines of one GPIO
/// chip, requested at start-up and held until destruction. Levels are logical: the kernel applies
/// the active-low flag on both read and write.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hal/gpio.hpp"

// libgpiod's handles, declared here so that users of this header need no <gpiod.h>.
struct gpiod_chip;
struct gpiod_line;

namespace imd::hal {

/// One line to request: its offset on the chip, direction, polarity, and its role for messages.
struct GpioLineSpec {
  unsigned offset = 0;
  bool output = false;
  bool active_low = false;     ///< GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW: logical 1 = physical low
  bool initial_level = false;  ///< outputs: logical level at request time
  std::string role;            ///< e.g. "enable input", "fault output" (for messages)
};

/// The most lines one GpiodLines holds: read() and write() index them with a uint8_t.
inline constexpr std::size_t kMaxGpioLines = 255;

/// Empty if `lines` can be requested, else why not: no lines, more than kMaxGpioLines, or two
/// entries with the same offset ("fault output and timing output both use line 5").
std::string validate_line_specs(const std::vector<GpioLineSpec>& lines);

/// Why gpiod_chip_open_lookup(`chip`) failed with errno `error_number`, e.g. "gpiochip7: no such
/// GPIO chip" (ENOENT) or "/dev/null: not a GPIO chip" (ENOTTY).
std::string describe_open_error(const std::string& chip, int error_number);

/// "gpiochip0 (9030000.pl061, 8 lines): fault output line 9 out of range (0..7)".
std::string describe_range_error(const std::string& chip_name, const std::string& chip_label,
                                 unsigned num_lines, const GpioLineSpec& line);

/// Why requesting `line` failed with errno `error_number`. For EBUSY `consumer` names the current
/// user (empty if the kernel gave none): "gpiochip0 (9030000.pl061): enable input line 3 is busy
/// (used by \"gpio-keys\")"; otherwise the errno text follows the line.
std::string describe_line_error(const std::string& chip_name, const std::string& chip_label,
                                const GpioLineSpec& line, int error_number,
                                const std::string& consumer);

class GpiodLines final : public Gpio {
 public:
  /// Opens `chip` (a name "gpiochip0", a path "/dev/gpiochip0", a number "0" or a label like
  /// "9030000.pl061": gpiod_chip_open_lookup) and requests every line with consumer name
  /// `consumer`. Index i of read()/write() is lines[i]. On failure returns nullptr and sets
  /// `error` to a message that names the chip, line and role (see the describe_* functions).
  static std::unique_ptr<GpiodLines> open(const std::string& chip,
                                          const std::vector<GpioLineSpec>& lines,
                                          const std::string& consumer, std::string& error);

  /// Drives the outputs to their inactive level (logical 0), releases the lines, closes the chip.
  ~GpiodLines();
  GpiodLines(const GpiodLines&) = delete;
  GpiodLines& operator=(const GpiodLines&) = delete;

  /// Sets an output's logical level. An index out of range, an input or a failed ioctl is
  /// counted in io_errors() and nothing is written.
  void write(uint8_t line, bool level) noexcept override;
  /// Logical level of an input or output; false (and counted in io_errors()) on error.
  bool read(uint8_t line) const noexcept override;

  /// Failed or invalid reads and writes since open().
  uint32_t io_errors() const noexcept { return io_errors_; }
  /// The kernel's name of the chip ("gpiochip0") and its label ("9030000.pl061").
  const std::string& chip_name() const noexcept { return chip_name_; }
  const std::string& chip_label() const noexcept { return chip_label_; }
  std::size_t size() const noexcept { return lines_.size(); }

 private:
  struct Line {
    gpiod_line* handle;
    bool output;
  };

  explicit GpiodLines(gpiod_chip* chip);

  gpiod_chip* chip_;
  std::vector<Line> lines_;  // filled in open(), never resized afterwards
  std::string chip_name_;
  std::string chip_label_;
  mutable uint32_t io_errors_ = 0;  // read() is const but counts its failures
};

}  // namespace imd::hal
