#pragma once
/// Scenario files: TOML describing a motor, the drive, references, load, sensors, inverter and
/// the simulation, and the events of a run: faults and CAN commands (docs/scenarios.md). Every
/// key is validated; an unknown key is an error.
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "control/motor_parameters.hpp"
#include "hal_sim/fault_injection.hpp"
#include "hal_sim/load_profile.hpp"
#include "hal_sim/sim_board.hpp"
#include "hal_sim/speed_profile.hpp"

namespace imd::sim {

/// A command the host sends the drive over CAN, as the scenario writes it ([[can_commands]]).
/// Generic: the message and field names are checked and encoded by the runner against the
/// protocol table, which names this entry can_commands[index] in its errors.
struct CanCommandScript {
  int index = 0;        ///< position in the file's [[can_commands]]
  double at_s = 0.0;    ///< time of the (first) frame
  std::string message;  ///< message name in the protocol table
  /// Signal values in physical units, by signal name (in key order: TOML tables are unordered).
  std::vector<std::pair<std::string, double>> fields;
  double every_s = 0.0;  ///< > 0: sent again at at_s + n every_s while <= until_s; 0: once
  double until_s = std::numeric_limits<double>::infinity();  ///< end of the repeat
  std::optional<int> counter;  ///< forces the alive counter (0..15): scripts a bad frame
  bool corrupt_crc = false;    ///< sends a wrong CRC
  std::optional<int> length;   ///< forces the DLC (0..8)
};

/// [protection]: the thresholds of the drive's protection checks. An absent value keeps the
/// runner's default.
struct ProtectionSettings {
  std::optional<double> overcurrent_A;    ///< instantaneous phase-current trip
  std::optional<double> bus_min_V;        ///< below: undervoltage
  std::optional<double> bus_max_V;        ///< above: overvoltage (> bus_min_V)
  std::optional<double> overspeed_rad_s;  ///< |estimated speed| trip
  /// Encoder loss: count edges the rotor must have crossed, whatever the load, without a count.
  std::optional<double> encoder_missing_counts;
  /// Encoder: the largest load allowed for, a share of the torque at the current limit, (0, 1).
  std::optional<double> encoder_max_load_share;
  std::optional<int> adc_stuck_ticks;  ///< ticks of identical phase codes that mean stuck, >= 2
  /// Phase loss: the inverter's worst voltage error, a share of V_bus/sqrt(3) in (0, 1), and
  /// the current ADC's rms noise in codes.
  std::optional<double> inverter_voltage_error_share;
  std::optional<double> adc_noise_codes;
  std::optional<double> command_timeout_s;  ///< command watchdog on CAN commands
  std::optional<double> tick_budget_us;     ///< execution-time budget of a tick
  std::optional<double> stop_decel_rad_s2;  ///< deceleration of the stop on a disable command
  /// The stop categories of the faults that may choose (firmware StopPolicy): "sto", "ss1",
  /// "dc_brake".
  std::string command_timeout_stop = "ss1", emergency_stop_stop = "sto", encoder_stop = "dc_brake";
  std::optional<double> dc_brake_current_share;  ///< DC braking's current, (0, 1] of the limit
};

/// [nameplate] and [identify]: a commissioning run (docs/scenarios.md). The drive starts with an
/// empty parameter store, as a new board does; the runner writes the nameplate over CAN at
/// start_s (1 ms apart) and sends the identify command after it. The run ends when the
/// commissioning has ended.
struct CommissioningSettings {
  double rated_voltage_V = 0.0, rated_current_A = 0.0, rated_frequency_Hz = 0.0;
  int pole_pairs = 0;
  bool rotate = true;    ///< the rotating step for inertia and friction
  double start_s = 0.1;  ///< after the ADC calibration
};

/// The laws a scenario may name in drive.controller: the drive's laws by the CAN protocol's
/// names (firmware/protocol/messages.hpp; the simulator's core does not depend on the firmware,
/// so a test checks that the two lists agree).
inline constexpr std::string_view kScenarioControllers[] = {"dsmc", "iol", "ifoc"};

struct Scenario {
  std::string source;  ///< file name, for messages and the summary
  control::MotorParameters motor;  ///< what the controller knows: [motor] or motor_file
  /// The simulated motor: [motor] changed by the keys of [plant] (the same without it).
  control::MotorParameters plant;
  /// [plant] Rs_scale_end, Rr_scale_end: the plant's resistances drift linearly from their
  /// value to this multiple of it over the run (sim::ResistanceDrift).
  double Rs_scale_end = 1.0, Rr_scale_end = 1.0;

  // [drive]
  double sample_period_s = 1e-4;
  std::string controller = "dsmc";  ///< one of kScenarioControllers
  std::string precision = "double";  ///< control arithmetic: "double" or "float"
  double max_accel_rad_s2 = 0.0;     ///< speed reference ramp; inf: none
  /// Where the speed reference comes from: "profile" ([reference.speed]) or "can" (only from
  /// CAN commands; [reference.speed] is then absent).
  std::string command_source = "profile";
  bool compensate_latency = true;    ///< predict over the PWM latency
  double speed_reaching_pole = 0.0;  ///< 0: the paper's deadbeat law
  double flux_reaching_pole = 0.0;
  /// The DSMC's speed channel: "torque" (through the next step's torque) or "paper" (the
  /// paper's, which sets the next speed directly; speed_reaching_pole applies to it).
  std::string dsmc_speed_channel = "torque";
  double dsmc_speed_bandwidth_rad_s = 0.0;  ///< torque channel; 0: the rule (docs/control.md)
  /// Track the rotor resistance online (docs/robustness.md); the adaptation's time constant
  /// at slip tangent 1 (0: four rotor time constants).
  bool rotor_resistance_tracking = true;
  double rr_convergence_time_constant_s = 0.0;
  double rr_retune_share = 0.005;  ///< rebuild the model when the estimate moved this much

  // [reference.speed], [reference.flux]
  SpeedProfile speed;
  double flux2_Wb2 = 0.2;         ///< squared rotor flux (dsmc)
  double stator_flux2_Wb2 = 0.0;  ///< squared stator flux (iol)
  LoadProfile torque;             ///< torque reference (iol without the outer speed loop)

  // [drive] for the iol controller
  double iol_period_s = 1e-3;
  bool outer_speed_loop = false, outer_flux_loop = false;
  double speed_loop_bandwidth_rad_s = 30.0, torque_limit_Nm = 240.0;
  double flux_loop_time_constant_s = 0.01;
  // [drive] for the ifoc controller; 0: the rules of docs/ifoc.md
  double ifoc_current_bandwidth_rad_s = 0.0, ifoc_speed_bandwidth_rad_s = 0.0;
  double magnetized_fraction = 0.95;
  double magnetizing_current_A = 0.0;  ///< 0: the current that holds the flux target

  LoadProfile load;
  HoldingBrake brake;  ///< [brake]: a holding brake on the shaft (none by default)

  // [sensors]
  bool ideal_sensors = false;
  uint32_t encoder_cpr = 8192;
  AdcModelConfig adc;

  // [inverter]
  double v_bus_V = 311.0;
  double i_max_A = 0.0;       ///< inf: no current limit
  bool limit_voltage = true;  ///< false: the law ignores the bus (the paper states no limit)
  InverterNonideality inverter;  ///< dead_time_s, device_drop_V
  bool switching_inverter = false;  ///< [inverter] model = "switching" (else "average")
  bool dead_time_compensation = true;  ///< [drive]: the firmware adds the dead time back

  // [observers]
  bool section_iv = false;  ///< paper's flux observer and load estimator on the ideal speed
  double encoder_bandwidth_rad_s = 400.0;
  double load_estimator_pole = 0.99;

  // [simulation]
  double duration_s = 1.0;
  int substeps = 10;  ///< RK4 steps per period (rk4, and where rk6 falls back to RK4)
  /// The sixth-order steps where the plant is smooth (hal_sim/plant_integrator.hpp): as
  /// accurate as RK4 at 10 us (tests/hal_sim/test_plant_integrator.cpp), several times faster.
  PlantIntegrator integrator = PlantIntegrator::rk6;
  InnerFeedback inner_feedback = InnerFeedback::digital;
  int pwm_latency_ticks = 1;
  uint64_t seed = 1;
  double initial_flux2_Wb2 = 0.0;       ///< start magnetized at rest with this squared flux
  double initial_theta_mech_rad = 0.0;  ///< rotor position at the start
  bool current_fed = false;             ///< the ideal current source drives the motor (paper 001)

  // [metrics]
  double settle_s = 0.5;

  // [can]
  int can_node_id = 1;             ///< 0..63
  int telemetry_rate_Hz = 100;  ///< fast telemetry, 10..1000, whole hertz

  ProtectionSettings protection;               ///< [protection]
  std::vector<FaultInjection> faults;          ///< [[faults]], sorted by at_s (stable)
  std::vector<CanCommandScript> can_commands;  ///< [[can_commands]], in file order
  std::optional<CommissioningSettings> commissioning;  ///< [nameplate], [identify]
};

/// Loads a scenario. `overrides` are "table.key=VALUE" strings (VALUE in TOML syntax; a bare
/// word is taken as a string), applied after any motor_file has been merged in. `model_file`:
/// a motor file the controller is given instead of the scenario's motor, which stays the
/// simulated one (an identified motor on the true plant). Throws ConfigError naming the file
/// that holds the key (the scenario, a motor file it names, `model_file`) or the override that
/// set it ("--set table.key=VALUE"), then the key and the value.
Scenario load_scenario(const std::filesystem::path& path,
                       const std::vector<std::string>& overrides = {},
                       const std::optional<std::filesystem::path>& model_file = std::nullopt);

/// An override and the command-line text that gave it, which messages name as its key's origin:
/// {"simulation.duration_s=0.3", "--duration-s 0.3"}. load_scenario's are "--set ASSIGNMENT".
struct ScenarioOverride {
  std::string assignment;  ///< table.key=VALUE
  std::string flag;        ///< as the user wrote it
};

/// load_scenario for a tool whose options besides --set change keys (drive_sim --duration-s).
Scenario load_scenario_with_flags(const std::filesystem::path& path,
                                  const std::vector<ScenarioOverride>& overrides,
                                  const std::optional<std::filesystem::path>& model_file);

}  // namespace imd::sim
