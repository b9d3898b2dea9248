#include "tools/drive_monitor/parameters_cli.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <optional>
#include <thread>

#include "firmware/protocol/commands.hpp"
#include "hal_sim/config_error.hpp"
#include "hal_sim/motor_file.hpp"
#include "tools/drive_monitor/cli_io.hpp"
#include "tools/drive_monitor/parameter_access.hpp"
#include "tools/drive_monitor/parameter_session.hpp"
#include "tools/drive_monitor/send_command.hpp"

namespace imd::monitor::cli {
namespace {

namespace protocol = firmware::protocol;
using firmware::ParameterStatus;
using protocol::ParameterOp;

/// The shortest text that reads back as the same float.
std::string fmt_float(float value) {
  return fmt::format("{}", value);
}

std::string value_text(float value) {
  return std::isnan(value) ? "(none)" : fmt_float(value);
}

}  // namespace

CLI::App* add_parameters_command(CLI::App& app, ParametersOptions& o) {
  CLI::App* c = app.add_subcommand("parameters",
                                   "Read the drive's motor parameters; write, save, export them");
  add_bus_options(*c, o.bus);
  c->add_option("--node", o.node, "Node id of the drive")
      ->check(CLI::Range(0, protocol::kMaxNodeId))
      ->required();
  c->add_option("--set", o.sets,
                "Write a field, KEY=VALUE (repeatable; keys: " + field_names() +
                    "); only while the drive is idle");
  c->add_option("--motor-file", o.motor_file, "Write every field of this motor file");
  c->add_flag("--save", o.save, "Save the record to the drive's storage (after any writes)");
  c->add_option("--motor-out", o.motor_out, "Write what the drive holds as a motor file");
  c->add_option("--wait-s", o.wait_s, "How long to wait for each answer")
      ->check(kSeconds)
      ->capture_default_str();
  c->add_option("--wait-heartbeat-s", o.wait_heartbeat_s,
                "How long to wait for the heartbeat (it gives the alive counter)")
      ->check(kSeconds)
      ->capture_default_str();
  return c;
}

int run_parameters(const ParametersOptions& o) {
  std::vector<Assignment> writes;
  for (const std::string& text : o.sets) {
    std::string error;
    const auto a = parse_assignment(text, error);
    if (!a) return fail("parameters: " + error);
    writes.push_back(*a);
  }
  if (!o.motor_file.empty()) {
    try {
      const control::MotorParameters m = sim::load_motor_file(o.motor_file);
      for (int i = 0; i < firmware::kMotorFieldCount; ++i) {
        const auto f = static_cast<firmware::MotorField>(i);
        writes.push_back({uint8_t(i), float(firmware::field_value(m, f))});
      }
    } catch (const sim::ConfigError& error) {
      return fail(error.what());
    }
  }
  std::string error;
  if (!o.bus.given()) return fail("parameters: give --can IFACE or --socketcand HOST:PORT");
  const auto bus = LiveBus::open(o.bus, error);
  if (!bus) return fail(error);
  const auto node = static_cast<uint8_t>(o.node);
  const StopSignals stop_signals;
  const std::optional<uint8_t> counter = first_counter(*bus, node, bus->name(), o.wait_heartbeat_s);
  if (!counter) return kExitNoAnswer;
  ParameterSession session(*bus, node, *counter, o.wait_s);

  int status = 0;
  // A new motor's inductances may pass through a record without leakage when written one at a
  // time (Lm up before Ls and Lr): a write refused for that is tried again after the others.
  for (int pass = 0; pass < 3 && !writes.empty(); ++pass) {
    std::vector<Assignment> retry;
    for (const Assignment& w : writes) {
      const auto reply = session.access(ParameterOp::write, w.field, w.value);
      if (!reply) return fail("write " + field_name(w.field) + ": no answer", kExitNoAnswer);
      if (reply->status == ParameterStatus::no_leakage && pass < 2) {
        retry.push_back(w);
        continue;
      }
      std::cout << "write " << field_name(w.field) << " = " << fmt_float(w.value) << ": "
                << status_name(reply->status) << '\n';
      if (reply->status != ParameterStatus::ok) status = kExitRejected;
    }
    writes = retry;
  }
  if (o.save) {
    const auto reply = session.access(ParameterOp::save, 0);
    if (!reply) return fail("save: no answer", kExitNoAnswer);
    std::cout << "save: " << status_name(reply->status) << '\n';
    if (reply->status != ParameterStatus::ok) status = kExitRejected;
  }
  const int read_status = read_record(session, o.node, bus->name(), o.motor_out);
  return read_status != 0 ? read_status : status;
}

std::optional<uint8_t> first_counter(LiveBus& bus, uint8_t node, const std::string& can,
                                     double wait_s) {
  std::optional<uint8_t> last;
  receive_until(bus, wait_s, [&](const hal::CanFrame& f) {
    last = heartbeat_command_counter(f, node);
    return last.has_value();
  });
  if (!last) {
    fail("no heartbeat from node " + std::to_string(node) + " on " + can + " within " +
             seconds_text(wait_s) + " s",
         kExitNoAnswer);
    return std::nullopt;
  }
  return static_cast<uint8_t>((*last + 1) & 0x0F);
}

int read_record(ParameterSession& session, int node, const std::string& can,
                const std::string& motor_out) {
  control::MotorParameters read;
  bool complete = false, saved = false;
  for (int i = 0; i < firmware::kRecordFieldCount; ++i) {
    const auto reply = session.access(ParameterOp::read, uint8_t(i));
    if (!reply) return fail("read " + field_name(uint8_t(i)) + ": no answer", kExitNoAnswer);
    std::cout << field_name(uint8_t(i)) << " = " << value_text(reply->value) << '\n';
    if (i < firmware::kMotorFieldCount) {
      firmware::set_field(read, static_cast<firmware::MotorField>(i), double(reply->value));
    }
    complete = reply->complete;  // the motor's fields, as the drive judges them
    saved = reply->saved;
  }
  std::cout << "record: " << (complete ? "complete" : "incomplete") << ", "
            << (saved ? "saved" : "not saved") << '\n';
  if (!motor_out.empty()) {
    if (!complete) return fail("--motor-out: the drive holds no complete record", kExitRejected);
    std::ofstream file(motor_out, std::ios::trunc);
    file << sim::motor_file_text(read, "node " + std::to_string(node) + " on " + can,
                                 "Motor parameters read from the drive (drive_monitor).\n"
                                 "Values are single precision, as the CAN message carries them.");
    if (!file.flush()) return fail(motor_out + ": cannot write", kExitOutputError);
  }
  return 0;
}

}  // namespace imd::monitor::cli
