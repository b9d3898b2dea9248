#pragma once
/// Runs a scenario: the drive firmware on the simulated board, in lock-step, and the metrics
/// of docs/scenarios.md. Shared by drive_sim and the sim-tier tests.
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "firmware/telemetry.hpp"
#include "hal/can_bus.hpp"
#include "hal_sim/drive/commissioning_watch.hpp"
#include "hal_sim/drive/tick_observer.hpp"
#include "hal_sim/scenario.hpp"

namespace imd::sim {

/// A fault the drive latched (or the plant diverging). Times are tick times; NaN when it did
/// not happen (a fault that was not injected, a PWM that stayed on).
struct FaultEvent {
  std::string code;      ///< the drive's fault code, e.g. "encoder"
  std::string injected;  ///< the injected fault it answered ([[faults]] kind), or empty
  double injected_at_s = std::nan("");
  double detected_at_s = 0.0;
  double pwm_off_at_s = std::nan("");
  /// The stop the first fault took: "sto", "ss1", "dc_brake"; empty for a later fault.
  std::string stop = {};
  /// The detail the drive latched with its first fault (the phase of overcurrent, phase_loss
  /// and adc_offset, else 0); -1 for a later fault.
  int detail = -1;
};

/// A span of time in which a limit held the running drive from its reference
/// (firmware/limitation.hpp). to_s is NaN when it still held at the end of the run.
struct LimitedSpan {
  std::string reason;  ///< "voltage", "current" or "torque"
  double from_s = 0.0;
  double to_s = std::nan("");
};

/// Metrics over t > settle_s from the plant's true state (i_peak_total_A: the whole run). NaN
/// when the run ended before settle_s.
struct Summary {
  double speed_rms_err_rad_s = 0.0, speed_max_err_rad_s = 0.0;
  /// Against the drive's ramped command for the same step, over running ticks (tick_observer.hpp).
  double speed_rms_err_cmd_rad_s = 0.0;
  double flux2_rms_err_Wb2 = 0.0, flux2_max_err_Wb2 = 0.0;
  double load_est_rms_err_Nm = 0.0;
  double torque_rms_err_Nm = 0.0;  ///< iol: torque against the law's command one T0 earlier
  double i_hold_rms_err_A = 0.0;   ///< iol: RMS of |i_AB - i_cmd| over the ticks
  double i_peak_A = 0.0, i_peak_total_A = 0.0;
  /// The ripple at the control rate (f_s / 4 .. f_s / 2) after settle_s, RMS per phase
  /// (hal_sim/drive/tick_observer.hpp).
  double current_ripple_control_rms_A = 0.0, voltage_ripple_rms_V = 0.0;
  /// With the switching inverter, the current's ripple within each period (NaN otherwise).
  double current_ripple_rms_A = 0.0;
  double saturated_fraction = 0.0;
  uint64_t ticks = 0;
  double simulated_s = 0.0, wall_time_s = 0.0;
  double tick_exec_ns_mean = 0.0, tick_exec_ns_max = 0.0;
  /// Each stage's mean execution time (firmware::kStageNames order), over the timed ticks.
  double stage_ns_mean[firmware::kStageCount] = {};
  double running_from_s = -1.0;  ///< first time the drive was running (-1: never)
  /// The rotor resistance the drive ended with, the plant's then, the largest relative error
  /// after settle_s (NaN: none), and how often the model was rebuilt on the estimate.
  double rr_estimate_final_Ohm = 0.0, plant_Rr_final_Ohm = 0.0, rr_rel_err_max = 0.0;
  uint32_t rr_retunes = 0;
  bool rr_tracking = false;  ///< tracking was on (configured, and the board's power stage)
  std::vector<FaultEvent> faults;
  /// The last limitation of the run, if there was one, and the time limited in all.
  std::optional<LimitedSpan> limited;
  double limited_total_s = 0.0;
  /// A commissioning scenario's report (the run ends with the commissioning).
  std::optional<CommissioningReport> commissioning;
};

struct RunCallbacks {
  using Row = std::function<void(const SimRow&)>;
  using Progress = std::function<void(double simulated_s, double wall_s)>;
  using Frame = std::function<void(double t_s, const hal::CanFrame&)>;
  /// A host acting on the board between ticks (frames, faults, load), seeing the drive's status.
  using Host = std::function<void(uint64_t k, double t_s, SimBoard& board,
                                  const firmware::DriveStatus& status)>;
  RunCallbacks(Row row_ = {}, Progress progress_ = {}, Frame can_frame_ = {}, Host host_ = {},
               Frame host_frame_ = {})
      : row(std::move(row_)),
        progress(std::move(progress_)),
        can_frame(std::move(can_frame_)),
        host(std::move(host_)),
        host_frame(std::move(host_frame_)) {}

  Row row;            ///< every tick, if set
  Progress progress;  ///< about once per wall-clock second: simulated time so far
  Frame can_frame;    ///< every frame the firmware sent, with the time of the tick that sent it
  Host host;          ///< before every tick, after the scenario's own frames and faults
  /// every frame of the scenario's [[can_commands]], with the time of the tick it is delivered
  /// before (also when the drive's full receive queue then loses it, as a bus would)
  Frame host_frame;
};

/// Throws std::invalid_argument on a fault SimBoard refuses (fault_parameter_error), which
/// load_scenario never lets through.
Summary run_scenario(const Scenario& scenario, const RunCallbacks& callbacks = {});

}  // namespace imd::sim
