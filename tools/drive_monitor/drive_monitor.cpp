// drive_monitor: watches a drive's CAN frames (live, or from a candump -L log) and sends it
// commands.
//
//   drive_monitor watch (BUS | --log FILE) [--node N] [--csv PATH] [--table | --no-table]
//                       [--duration-s S]
//   drive_monitor send BUS --node N COMMAND [VALUE] [--counter C] [--wait-heartbeat-s S]
//                      [--wait-ack-s S] [--repeat-hz F --for-s S [--enable]]
//   drive_monitor parameters BUS --node N [--set KEY=VALUE]... [--motor-file PATH]
//                            [--save] [--motor-out PATH] [--wait-s S] [--wait-heartbeat-s S]
//   drive_monitor identify BUS --node N [--rotate] [--motor-out PATH] [--timeout-s S]
//
// BUS is --can IFACE (SocketCAN) or --socketcand HOST:PORT (a socketcand server in raw mode,
// such as drive_hil --can socketcand:PORT, for a machine without SocketCAN).
// watch decodes node N's frames (default 1); the CSV's time_s is the log's timestamp, or with
// a live bus the seconds since watch started. Everything else a shared bus carries (error frames,
// 29-bit, CAN FD and remote frames, other nodes, unknown messages) is skipped and counted; one
// summary line on standard error ends the watch, and a warning when node N sent nothing.
// send learns the alive counter from the heartbeat.
// With --repeat-hz F --for-s S (both or neither; F in (0, 1000] Hz) send sends the command
// every 1/F s for S s, each frame with the next alive counter, and so keeps an enabled drive's
// command watchdog fed (it needs a frame every command_timeout_s, 0.2 s by default). Acks are
// matched as they come, --wait-ack-s per frame; SIGINT or SIGTERM ends the repetition early.
// It prints one summary line: frames sent, accepted, rejected by reason, unanswered. With
// --enable (set-speed only) an enable frame goes first and the speed frames follow at once, so
// one command starts the drive and feeds its watchdog; a refused enable stops the repetition. The
// emergency stop may be repeated too: the tool never stands in the way of a stop, and the
// drive obeys every estop frame whatever its counter, so repeats are harmless redundancy.
//
// Exit codes: 0 success (with --repeat-hz: every frame sent and accepted), 1 an output file
// could not be written once the work had begun (a write error on the CSV, --motor-out), 2 bad
// input (command line, interface, log file, a CSV that cannot be created), 3 a command frame
// rejected,
// 4 no heartbeat or no acknowledgement (with --repeat-hz: none rejected, but some frame not
// sent or unanswered); for watch, no frame at all from node N (in the log, or on the bus
// before the end of --duration-s or an interrupt).
//
// parameters writes the given fields (each answered after the drive has checked it: a refusal
// prints its reason and the exit code is 3), saves the record if asked, then reads every field
// back and prints it; --motor-out writes what it read as a motor file.
//
// identify starts the commissioning (the drive's record must hold the nameplate), prints its
// progress, and on success reads the identified record back as parameters does; exit code 3
// when the drive refuses or the run fails (the reason is printed), 4 when it does not answer.
#include <poll.h>
#include <unistd.h>
#include <CLI/CLI.hpp>
#include <imd_version.hpp>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "firmware/protection/protection_config.hpp"
#include "tools/drive_monitor/cli_io.hpp"
#include "tools/drive_monitor/identify_cli.hpp"
#include "tools/drive_monitor/monitor.hpp"
#include "tools/drive_monitor/parameters_cli.hpp"
#include "tools/drive_monitor/repeat_send.hpp"
#include "tools/drive_monitor/send_command.hpp"
#include "tools/drive_monitor/status_table.hpp"
#include "tools/drive_monitor/watch_cli.hpp"

namespace {

using namespace imd::monitor::cli;

/// A --repeat-hz rate in (0, kMaxRepeatRate_Hz].
const CLI::Validator kRepeatRate(
    [](std::string& text) -> std::string {
      char* end = nullptr;
      const double value = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0') return "must be a number, got " + text;
      if (!(value > 0.0 && value <= imd::monitor::kMaxRepeatRate_Hz)) {
        return "must be a rate in (0, " + seconds_text(imd::monitor::kMaxRepeatRate_Hz) +
               "] Hz, got " + text;
      }
      return {};
    },
    "HZ");

struct SendOptions {
  BusChoice bus;
  int node = 1;
  std::string command;
  std::optional<std::string> value;
  int counter = -1;
  double wait_heartbeat_s = 0.5;
  double wait_ack_s = 0.5;
  std::optional<imd::monitor::RepeatPlan> repeat;  ///< --repeat-hz/--for-s; nullopt: send once
  bool enable = false;                             ///< --enable: an enable frame first
};

/// send --repeat-hz: the frames go out on CommandRepeater's schedule; between them the loop
/// only sleeps until the next slot, the next ack deadline or a received frame, so an ack never
/// holds up the next frame.
int send_repeated(LiveBus& bus, const SendOptions& o,
                  const imd::firmware::protocol::Command& command, uint8_t counter) {
  const imd::monitor::RepeatPlan& plan = *o.repeat;
  // Slower than the watchdog is allowed (a test may want it), but worth a word, except for the
  // emergency stop, which leaves the drive faulted and its watchdog with nothing to guard.
  const double default_timeout_s = imd::firmware::ProtectionConfig{}.command_timeout_s;
  if (1.0 / plan.rate_Hz >= default_timeout_s &&
      command.kind != imd::firmware::protocol::CommandKind::emergency_stop) {
    std::cerr << "drive_monitor: note: a frame every " << seconds_text(1.0 / plan.rate_Hz)
              << " s does not keep an enabled drive alive if its command_timeout_s is the "
                 "default "
              << seconds_text(default_timeout_s) << " s\n";
  }
  const auto lead = o.enable ? std::optional(imd::firmware::protocol::Command{
                                   imd::firmware::protocol::CommandKind::enable})
                             : std::nullopt;
  imd::monitor::CommandRepeater repeater(static_cast<uint8_t>(o.node), command, counter, plan,
                                         Clock::now(), lead);
  std::string bus_error;
  imd::hal::CanFrame frame;
  for (;;) {
    if (g_stop != 0) repeater.stop(Clock::now());
    while (bus.try_receive(frame)) repeater.receive(Clock::now(), frame);
    const Clock::time_point now = Clock::now();
    if (const auto due = repeater.frame_due(now)) repeater.sent(now, bus.try_send(*due));
    if (const auto lost = bus.lost(); bus_error.empty() && lost) {
      bus_error = *lost;
      repeater.stop(now);
    }
    if (repeater.finished(now)) break;
    wait_readable(bus, repeater.next_event());
  }
  if (!bus_error.empty()) std::cerr << "drive_monitor: " << bus_error << '\n';
  std::cout << imd::monitor::repeat_summary(repeater.tally(), command, plan.rate_Hz) << '\n';
  switch (imd::monitor::verdict(repeater.tally())) {
    case imd::monitor::RepeatVerdict::all_accepted:
      return 0;
    case imd::monitor::RepeatVerdict::rejected:
      return kExitRejected;
    case imd::monitor::RepeatVerdict::not_all_accepted:
      break;
  }
  return kExitNoAnswer;
}

int send(const SendOptions& o) {
  namespace protocol = imd::firmware::protocol;
  std::string error;
  const auto command = imd::monitor::parse_command(o.command, o.value, error);
  if (!command) return fail(error);
  if (o.enable && command->kind != protocol::CommandKind::set_speed) {
    return fail("--enable goes with set-speed only (it starts the drive at that speed), not " +
                o.command);
  }
  if (!o.bus.given()) return fail("send: give --can IFACE or --socketcand HOST:PORT");
  const auto bus = LiveBus::open(o.bus, error);
  if (!bus) return fail(error);
  const auto node = static_cast<uint8_t>(o.node);
  const StopSignals stop_signals;

  uint8_t counter = static_cast<uint8_t>(o.counter);
  if (o.counter < 0) {
    std::optional<uint8_t> last;
    receive_until(*bus, o.wait_heartbeat_s, [&](const imd::hal::CanFrame& f) {
      last = imd::monitor::heartbeat_command_counter(f, node);
      return last.has_value();
    });
    if (!last) {
      return fail("no heartbeat from node " + std::to_string(o.node) + " on " + bus->name() +
                      " within " + seconds_text(o.wait_heartbeat_s) +
                      " s (use --counter C to send without one)",
                  kExitNoAnswer);
    }
    counter = static_cast<uint8_t>((*last + 1) & 0x0F);
  }
  receive_until(*bus, 0.0, [](const imd::hal::CanFrame&) { return false; });  // drop old frames
  if (o.repeat) return send_repeated(*bus, o, *command, counter);
  protocol::CommandEncoder encoder(node, counter);
  const imd::hal::CanFrame frame = encoder.encode(*command);
  const auto message_id = protocol::message_of(frame.id);
  if (!bus->try_send(frame)) {
    return fail(bus->name() + ": could not send (transmit queue full or interface down)",
                kExitNoAnswer);
  }
  const std::string sent = imd::monitor::describe_command(*command) + " to node " +
                           std::to_string(o.node) + ", counter " + std::to_string(counter);
  std::optional<imd::monitor::Ack> ack;
  receive_until(*bus, o.wait_ack_s, [&](const imd::hal::CanFrame& f) {
    ack = imd::monitor::match_ack(f, node, message_id, counter);
    return ack.has_value();
  });
  if (!ack) return fail("sent " + sent + ": no command_ack", kExitNoAnswer);
  std::cout << "sent " << sent << ": " << imd::monitor::result_name(ack->result)
            << " (rejected_total " << ack->rejected_total << ")\n";
  return ack->result == protocol::CommandResult::accepted ? 0 : kExitRejected;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Watches an induction-motor drive on CAN and sends it commands."};
  app.set_version_flag("--version", imd::version::kText);
  app.require_subcommand(1);

  WatchOptions w;
  CLI::App* watch = add_watch_command(app, w);

  SendOptions s;
  CLI::App* send_cmd = app.add_subcommand(
      "send", "Send a command and print its ack, or repeat it (--repeat-hz, --for-s)");
  add_bus_options(*send_cmd, s.bus);
  send_cmd->add_option("--node", s.node, "Node id of the drive")
      ->check(CLI::Range(0, imd::firmware::protocol::kMaxNodeId))
      ->required();
  send_cmd->add_option("command", s.command, imd::monitor::command_usage())->required();
  std::string value;
  CLI::Option* value_option = send_cmd->add_option("value", value, "The command's value");
  send_cmd->add_option("--counter", s.counter, "Alive counter to use (default: heartbeat's + 1)")
      ->check(CLI::Range(0, 15));
  send_cmd->add_option("--wait-heartbeat-s", s.wait_heartbeat_s, "How long to wait for it")
      ->check(kSeconds)
      ->capture_default_str();
  send_cmd->add_option("--wait-ack-s", s.wait_ack_s, "How long to wait for the command_ack")
      ->check(kSeconds)
      ->capture_default_str();
  double repeat_Hz = 0.0;
  double for_s = 0.0;
  CLI::Option* repeat_option =
      send_cmd
          ->add_option("--repeat-hz", repeat_Hz,
                       "Send the command at this rate, each frame with the next counter (a "
                       "keep-alive: the drive's watchdog wants one every 0.2 s by default)")
          ->check(kRepeatRate);
  CLI::Option* for_option =
      send_cmd->add_option("--for-s", for_s, "How long to repeat (with --repeat-hz)")
          ->check(kSeconds);
  repeat_option->needs(for_option);
  for_option->needs(repeat_option);
  send_cmd
      ->add_flag("--enable", s.enable,
                 "With set-speed: send enable first, then the speed at once and repeated, so one "
                 "command starts the drive and keeps its watchdog fed")
      ->needs(repeat_option);

  ParametersOptions p;
  CLI::App* parameters = add_parameters_command(app, p);
  IdentifyOptions id;
  CLI::App* identify = add_identify_command(app, id);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);
    return code == 0 ? 0 : kExitBadInput;
  }
  if (watch->parsed()) return run_watch(w);
  if (parameters->parsed()) return run_parameters(p);
  if (identify->parsed()) return run_identify(id);
  if (value_option->count() > 0) s.value = value;
  if (repeat_option->count() > 0) {
    s.repeat = imd::monitor::RepeatPlan{repeat_Hz, for_s, s.wait_ack_s};
  }
  return send(s);
}
