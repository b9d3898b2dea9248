// libFuzzer harness: arbitrary text, line by line, into the candump -L parser and the frames it
// accepts into drive_monitor's decoder. Checks that the parser either gives a frame (that the
// writer writes back to the same frame, whatever its kind) or a message, that only classic
// 11-bit frames reach the decoder, and that decoding, describing, row assembly and the status
// table cope with any frame.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>

#include "fuzz_check.hpp"
#include "tools/can_log/candump_log.hpp"
#include "tools/drive_monitor/capture_report.hpp"
#include "tools/drive_monitor/monitor.hpp"
#include "tools/drive_monitor/status_table.hpp"

namespace {

/// Beyond 2^50 us (~36 years) the writer's double time_s no longer holds every microsecond.
constexpr int64_t kExactTime_us = int64_t(1) << 50;

bool same_frame(const imd::can_log::LogFrame& a, const imd::can_log::LogFrame& b) {
  return a.type == b.type && a.extended == b.extended && a.id == b.id && a.length == b.length &&
         a.raw_dlc == b.raw_dlc && a.fd_flags == b.fd_flags && a.data == b.data;
}

void check_line(std::string_view text, imd::monitor::DriveMonitor& monitor,
                imd::monitor::SkippedFrames& skipped) {
  const imd::can_log::ParseResult r = imd::can_log::parse_log_line(text);
  if (!r.ok()) {
    FUZZ_CHECK(!r.error.message.empty());
    return;
  }
  const imd::can_log::ParsedLine& line = *r.line;
  FUZZ_CHECK(line.frame.length <= 64);
  FUZZ_CHECK(!line.iface.empty() && line.iface.size() <= 15);
  FUZZ_CHECK(line.time_us >= 0);

  const std::string written =
      imd::can_log::format_log_line(line.time_s, line.iface, line.frame, line.direction);
  const imd::can_log::ParseResult again = imd::can_log::parse_log_line(written);
  FUZZ_CHECK(again.ok());
  FUZZ_CHECK(same_frame(again.line->frame, line.frame));
  FUZZ_CHECK(again.line->direction == line.direction);
  FUZZ_CHECK(again.line->iface == line.iface);
  if (line.time_us < kExactTime_us) FUZZ_CHECK(again.line->time_us == line.time_us);

  const std::optional<imd::hal::CanFrame> frame = imd::monitor::take_frame(line.frame, skipped);
  if (!frame) return;
  FUZZ_CHECK(frame->id <= 0x7FF);
  FUZZ_CHECK(frame->length <= 8);
  const imd::monitor::DecodedFrame d = imd::monitor::decode_frame(*frame, monitor.node_id());
  FUZZ_CHECK(d.signal_count <= imd::monitor::kMaxSignals);
  FUZZ_CHECK(!imd::monitor::describe(d).empty());
  if (const auto row = monitor.feed(line.time_s, *frame)) {
    FUZZ_CHECK(!imd::monitor::csv_row(*row).empty());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  imd::monitor::DriveMonitor monitor(1);
  imd::monitor::SkippedFrames skipped;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    check_line(text.substr(start, end - start), monitor, skipped);
    start = end + 1;
  }
  const imd::monitor::DriveStatus& s = monitor.status();
  FUZZ_CHECK(s.frames.total ==
             s.frames.decoded + s.frames.other_nodes + s.frames.unknown + s.frames.wrong_length);
  FUZZ_CHECK(!imd::monitor::render_table(s, monitor.node_id(), "fuzz").empty());
  FUZZ_CHECK(!imd::monitor::summary_line(s, skipped, monitor.node_id(), false).empty());
  return 0;
}
