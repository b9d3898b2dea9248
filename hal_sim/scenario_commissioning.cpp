// [nameplate] and [identify]: a commissioning run as a host would start it over CAN.
#include <fmt/format.h>

#include "hal_sim/scenario.hpp"
#include "hal_sim/scenario_reader.hpp"

namespace imd::sim::detail {

namespace {

// The motor record's field numbers (firmware/protocol/messages.hpp, kMotorFieldValues; the
// simulator's core does not depend on the firmware: scripted_frames checks the names).
constexpr double kFieldPolePairs = 6, kFieldRatedVoltage = 8, kFieldRatedCurrent = 9,
                 kFieldRatedFrequency = 10;
constexpr double kOpWrite = 1;

}  // namespace

void read_commissioning(Reader& r, Scenario& s) {
  if (!r.present("nameplate")) {
    if (r.present("identify")) r.fail("identify", "needs a [nameplate] to plan the test from");
    return;
  }
  CommissioningSettings c;
  c.rated_voltage_V = r.positive("nameplate.rated_voltage_V", std::nullopt);
  c.rated_current_A = r.positive("nameplate.rated_current_A", std::nullopt);
  c.rated_frequency_Hz = r.positive("nameplate.rated_frequency_Hz", std::nullopt);
  if (!r.present("nameplate.pole_pairs")) r.fail("nameplate.pole_pairs", "missing key");
  c.pole_pairs = static_cast<int>(r.integer("nameplate.pole_pairs", 0, 1, 32));
  c.rotate = r.boolean("identify.rotate", true);
  c.start_s = r.positive("identify.start_s", 0.1);
  if (c.start_s + 0.005 >= s.duration_s) {
    r.fail_with("identify.start_s", "simulation.duration_s",
                fmt::format("= {}: must leave time before simulation.duration_s ({})", c.start_s,
                            s.duration_s));
  }
  // The nameplate writes 1 ms apart (each is served outside the tick before the next), then
  // the command.
  const std::pair<double, double> writes[] = {{kFieldRatedVoltage, c.rated_voltage_V},
                                              {kFieldRatedCurrent, c.rated_current_A},
                                              {kFieldRatedFrequency, c.rated_frequency_Hz},
                                              {kFieldPolePairs, double(c.pole_pairs)}};
  double at_s = c.start_s;
  for (const auto& [field, value] : writes) {
    CanCommandScript w;
    w.index = static_cast<int>(s.can_commands.size());
    w.at_s = at_s;
    w.message = "parameter_access";
    w.fields = {{"op", kOpWrite}, {"field", field}, {"value", value}};
    s.can_commands.push_back(w);
    at_s += 1e-3;
  }
  CanCommandScript identify;
  identify.index = static_cast<int>(s.can_commands.size());
  identify.at_s = at_s;
  identify.message = "identify";
  identify.fields = {{"rotate", c.rotate ? 1.0 : 0.0}};
  s.can_commands.push_back(identify);
  s.commissioning = c;
}

}  // namespace imd::sim::detail
