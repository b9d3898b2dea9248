#include "tools/drive_monitor/identify_cli.hpp"

#include <iostream>
#include <optional>

#include "firmware/protocol/commands.hpp"
#include "firmware/protocol/e2e.hpp"
#include "tools/drive_monitor/cli_io.hpp"
#include "tools/drive_monitor/parameter_access.hpp"
#include "tools/drive_monitor/parameter_session.hpp"
#include "tools/drive_monitor/send_command.hpp"

namespace imd::monitor::cli {

namespace protocol = firmware::protocol;

CLI::App* add_identify_command(CLI::App& app, IdentifyOptions& o) {
  CLI::App* c = app.add_subcommand(
      "identify",
      "Commission the motor: identify its parameters from the nameplate the drive holds (write "
      "it first: parameters --set rated_voltage_V=... rated_current_A=... rated_frequency_Hz=... "
      "pole_pairs=...), show the progress, read back the result. The drive must be idle or "
      "unconfigured with its enable input on; Ctrl-C sends a disable, which aborts the run");
  add_bus_options(*c, o.bus);
  c->add_option("--node", o.node, "Node id of the drive")
      ->check(CLI::Range(0, protocol::kMaxNodeId))
      ->required();
  c->add_flag("--rotate", o.rotate,
              "After the standstill steps, turn the motor to measure inertia and friction (the "
              "shaft must be free to turn); without it the drive keeps the mechanics its "
              "record has, or on a new drive guesses J from the nameplate");
  c->add_option("--motor-out", o.motor_out, "Write the identified record as a motor file");
  c->add_option("--timeout-s", o.timeout_s, "Give up waiting for the end after this long")
      ->check(kSeconds)
      ->capture_default_str();
  c->add_option("--wait-s", o.wait_s, "How long to wait for each answer")
      ->check(kSeconds)
      ->capture_default_str();
  c->add_option("--wait-heartbeat-s", o.wait_heartbeat_s,
                "How long to wait for the heartbeat (it gives the alive counter)")
      ->check(kSeconds)
      ->capture_default_str();
  return c;
}

int run_identify(const IdentifyOptions& o) {
  std::string error;
  if (!o.bus.given()) return fail("identify: give --can IFACE or --socketcand HOST:PORT");
  const auto bus = LiveBus::open(o.bus, error);
  if (!bus) return fail(error);
  const auto node = static_cast<uint8_t>(o.node);
  const StopSignals stop_signals;
  const std::optional<uint8_t> counter = first_counter(*bus, node, bus->name(), o.wait_heartbeat_s);
  if (!counter) return kExitNoAnswer;
  ParameterSession session(*bus, node, *counter, o.wait_s);
  const protocol::Command identify{protocol::CommandKind::identify, o.rotate ? 1.0f : 0.0f};
  const hal::CanFrame frame = session.encode(identify);
  if (!bus->try_send(frame)) return fail("identify: cannot send", kExitNoAnswer);
  std::optional<Ack> ack;
  receive_until(*bus, o.wait_s, [&](const hal::CanFrame& f) {
    ack = match_ack(f, node, uint8_t(protocol::MessageId::identify),
                    protocol::e2e_counter(frame.data));
    return ack.has_value();
  });
  if (!ack) return fail("identify: no acknowledgement", kExitNoAnswer);
  if (ack->result == protocol::CommandResult::not_in_image) {
    return fail("identify: rejected (not_in_image): this firmware image has no commissioning; "
                "flash the commissioning image (docs/flashing.md)",
                kExitRejected);
  }
  if (ack->result != protocol::CommandResult::accepted) {
    return fail("identify: rejected (" + result_name(ack->result) +
                    "): the drive must be idle or unconfigured, with its enable line on",
                kExitRejected);
  }
  // The progress at 10 Hz: a line per step, the fraction on the same line as it grows. The
  // drive sends none between the ack and the run's start (or its refusal): every frame from
  // here on is this run's.
  std::optional<IdentifyProgress> progress;
  uint8_t shown_step = 0xFF;
  receive_until(*bus, o.timeout_s, [&](const hal::CanFrame& f) {
    const auto p = decode_identify_progress(f, node);
    if (!p) return false;
    if (p->step != shown_step && shown_step != 0xFF) std::cout << '\n';
    shown_step = p->step;
    std::cout << '\r' << progress_text(*p) << "    " << std::flush;
    progress = p;
    return p->ended();
  });
  std::cout << '\n';
  if (!progress || !progress->ended()) {
    // The host leaves: a run that turns the motor must not go on unattended.
    const bool sent = bus->try_send(session.encode({protocol::CommandKind::disable}));
    const std::string why = g_stop != 0
                                ? "identify: stopped"
                                : "identify: no end within " + seconds_text(o.timeout_s) + " s";
    return fail(why + (sent ? "; disable sent, which aborts the run"
                            : "; disable could not be sent: the run goes on, disable the drive"),
                kExitNoAnswer);
  }
  if (progress->step != 4) return fail("identify: " + progress_text(*progress), kExitRejected);
  // Done: the drive builds its model from the result and saves it outside the tick, then goes
  // idle; a record it refuses turns the step to failed (invalid_record). The progress frame
  // follows its heartbeat (a tick or more later), so the first one after an idle heartbeat
  // decides.
  bool idle = false, decided = false;
  receive_until(*bus, 5.0 * o.wait_s, [&](const hal::CanFrame& f) {
    if (const auto state = heartbeat_state(f, node)) {
      idle = *state == firmware::DriveState::idle;
      return false;
    }
    const auto p = decode_identify_progress(f, node);
    if (!p) return false;
    progress = p;
    decided = p->step == 5 || idle;
    return decided;
  });
  if (!decided) return fail("identify: done, but the drive did not go idle on it", kExitNoAnswer);
  if (progress->step != 4) return fail("identify: " + progress_text(*progress), kExitRejected);
  if (progress->failure == 7) {
    std::cerr << "drive_monitor: warning: the rotor did not turn in the rotating step: inertia "
                 "and friction are not measured\n";
  }
  return read_record(session, o.node, bus->name(), o.motor_out);
}

}  // namespace imd::monitor::cli
