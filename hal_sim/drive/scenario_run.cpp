#include "hal_sim/drive/scenario_run.hpp"

#include <bit>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "control/current_fed_model.hpp"
#include "control/frames.hpp"
#include "firmware/drive.hpp"
#include "hal_sim/drive/commissioning_watch.hpp"
#include "hal_sim/drive/lockstep_period.hpp"
#include "hal_sim/drive/scenario_config.hpp"
#include "hal_sim/drive/scripted_commands.hpp"
#include "hal_sim/drive/simulated_drive.hpp"
#include "hal_sim/drive/stage_totals.hpp"
#include "hal_sim/fault_schedule.hpp"
#include "hal_sim/run_metrics.hpp"
#include "hal_sim/sim_board.hpp"
#include "hal_sim/sim_can_host.hpp"

namespace imd::sim {
namespace {

template <typename T>
Summary run(const Scenario& s, const RunCallbacks& callbacks) {
  SimBoard board(s.plant, sim::board_config(s));
  sim::prepare_board(board, s);
  const sim::ScenarioReferences<T> references(s);
  const firmware::DriveConfig config = sim::drive_config(s);
  // A commissioning run starts as a new board: no record in its store.
  const std::optional<firmware::MotorRecord> record =
      s.commissioning ? std::nullopt : std::optional<firmware::MotorRecord>(s.motor);
  SimulatedDrive<T> simulated(board, record, config,
                              {s.ideal_sensors, s.inner_feedback, s.current_fed}, &references,
                              board.timer(), &board.can(), &board.gpio());
  firmware::Drive<T>& drive = simulated.drive();
  const std::vector<ScriptedFrame> commands = scripted_frames(s);
  std::size_t next_command = 0;
  std::vector<std::size_t> unanswered;        // injected faults not yet detected (indices)
  std::vector<std::size_t> awaiting_pwm_off;  // detected faults with the PWM still on
  board.timer().start(drive);
  StageTotals stages;  // of the ticks whose stages the drive timed

  Summary summary;
  const auto wall_start = std::chrono::steady_clock::now();
  auto last_progress = wall_start;
  const auto ticks = static_cast<uint64_t>(std::llround(s.duration_s / s.sample_period_s));
  TickObserver<T> observer(observed_run(profiles(s), s.settle_s, s.motor, config));
  FaultSchedule faults(s.faults.data(), s.faults.size());
  std::vector<hal::CanFrame> sent_frames;  // reused: no allocation per tick
  CommissioningWatch commissioning(s.sample_period_s);
  uint16_t last_fault_bits = 0;
  firmware::Limitation last_limited = firmware::Limitation::none;
  bool diverged = false;
  for (uint64_t k = 0; k < ticks; ++k) {
    const double t_s = double(k) * s.sample_period_s;
    // Host and board events due before this tick: scripted command frames and faults.
    for (; next_command < commands.size() && commands[next_command].tick <= k; ++next_command) {
      board.can_side().inject(
          commands[next_command].frame);  // a full queue loses it, as a bus would
      if (callbacks.host_frame) callbacks.host_frame(t_s, commands[next_command].frame);
    }
    faults.inject_due(board, t_s, [&](const FaultInjection& fault, bool accepted) {
      // load_scenario refuses such faults; a scenario built in code may still hold one.
      if (!accepted) throw std::invalid_argument(s.source + ": " + fault_parameter_error(fault));
      unanswered.push_back(summary.faults.size());
      summary.faults.push_back(
          {"none", fault_kind_name(fault.kind), t_s, std::nan(""), std::nan("")});
    });
    if (callbacks.host) callbacks.host(k, t_s, board, drive.status());
    const PlantState& truth = board.plant().state();
    if (!truth.flux_r_alphabeta_Wb.allFinite() || !truth.i_s_alphabeta_A.allFinite() ||
        !std::isfinite(truth.omega_mech_rad_s) || !std::isfinite(truth.theta_mech_rad)) {
      summary.faults.push_back({"plant_diverged", "", std::nan(""), t_s, std::nan("")});
      summary.ticks = k;
      diverged = true;
      break;
    }
    const SimRow& row = lockstep_period(board, drive, observer, t_s, [&board] {
      board.begin_period();
      board.fire_timer();
    });
    drive.service();  // between ticks: where a board's main loop runs
    const firmware::TickRecord<T>& rec = drive.record();
    take_all_sent(board.can_side(), sent_frames);
    if (callbacks.can_frame) {
      for (const hal::CanFrame& frame : sent_frames) callbacks.can_frame(t_s, frame);
    }
    if (rec.stages_timed) stages.add(rec.stage_counts);
    // Faults the drive latched this tick, the first one first; each answers the oldest
    // injected fault still unanswered.
    for (uint16_t fresh = rec.fault_bits & ~last_fault_bits; fresh != 0;) {
      int code = std::countr_zero(fresh);
      if ((fresh & (1u << unsigned(rec.fault))) != 0) code = int(rec.fault);
      fresh = uint16_t(fresh & ~(1u << unsigned(code)));
      std::size_t event = summary.faults.size();
      if (!unanswered.empty()) {
        event = unanswered.front();
        unanswered.erase(unanswered.begin());
      } else {
        summary.faults.push_back({});
      }
      summary.faults[event].code = firmware::fault_name(firmware::FaultCode(code));
      summary.faults[event].detected_at_s = t_s;
      if (code == int(rec.fault)) {
        summary.faults[event].detail = drive.status().fault_detail;
        summary.faults[event].stop = firmware::stop_name(rec.stop);
      }
      awaiting_pwm_off.push_back(event);
    }
    last_fault_bits = rec.fault_bits;
    if (rec.limited != firmware::Limitation::none) summary.limited_total_s += s.sample_period_s;
    if (rec.limited != last_limited) {  // the last span ends; a new one may start
      if (last_limited != firmware::Limitation::none) summary.limited->to_s = t_s;
      if (rec.limited != firmware::Limitation::none) {
        summary.limited = LimitedSpan{firmware::limitation_name(rec.limited), t_s, std::nan("")};
      }
      last_limited = rec.limited;
    }
    if (!board.pwm().enabled()) {
      for (const std::size_t event : awaiting_pwm_off) summary.faults[event].pwm_off_at_s = t_s;
      awaiting_pwm_off.clear();
    }
    if (callbacks.row) callbacks.row(row);
    if (s.commissioning && commissioning.after_tick(drive)) {  // its end ends the run
      summary.ticks = k + 1;
      break;
    }
    if (callbacks.progress && (k & 1023) == 0) {
      const auto now = std::chrono::steady_clock::now();
      if (now - last_progress > std::chrono::seconds(1)) {
        last_progress = now;
        callbacks.progress(t_s, std::chrono::duration<double>(now - wall_start).count());
      }
    }
  }
  if (!diverged && !commissioning.report().ended) summary.ticks = ticks;
  if (s.commissioning) {
    if (!commissioning.report().ended) commissioning.finish();
    commissioning.mechanics_measured(s.commissioning->rotate);
    summary.commissioning = commissioning.report();
  }
  summary.simulated_s = double(summary.ticks) * s.sample_period_s;
  summary.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  // Nothing after settle_s (a run that ended early): the metrics are not defined (null in JSON).
  const RunMetrics& metrics = observer.metrics();
  summary.speed_rms_err_rad_s = observer.speed_rms_err_rad_s();
  summary.speed_max_err_rad_s = observer.speed_max_err_rad_s();
  summary.speed_rms_err_cmd_rad_s = observer.speed_rms_err_cmd_rad_s();
  summary.flux2_rms_err_Wb2 = metrics.flux2_rms_err_Wb2();
  summary.flux2_max_err_Wb2 = metrics.flux2_max_err_Wb2();
  summary.load_est_rms_err_Nm = metrics.load_est_rms_err_Nm();
  summary.i_peak_A = metrics.i_peak_A();
  summary.i_peak_total_A = metrics.i_peak_total_A();
  summary.saturated_fraction = metrics.saturated_fraction();
  summary.i_hold_rms_err_A = observer.i_hold_rms_err_A();
  summary.torque_rms_err_Nm = observer.torque_rms_err_Nm();
  summary.running_from_s = observer.running_from_s();
  summary.rr_estimate_final_Ohm = observer.rr_estimate_final_Ohm();
  summary.plant_Rr_final_Ohm = observer.plant_Rr_final_Ohm();
  summary.rr_rel_err_max = observer.rr_rel_err_max();
  summary.rr_retunes = drive.retunes();
  summary.rr_tracking = drive.tracking_rotor_resistance();
  summary.current_ripple_control_rms_A = observer.current_ripple_control_rms_A();
  summary.voltage_ripple_rms_V = observer.voltage_ripple_rms_V();
  summary.current_ripple_rms_A = observer.current_ripple_rms_A();
  const double ns_per_count = 1e9 / double(drive.execution_clock_Hz());
  for (int i = 0; i < firmware::kStageCount; ++i) {
    summary.stage_ns_mean[i] = stages.ticks
                                   ? double(stages.counts[i]) * ns_per_count / double(stages.ticks)
                                   : std::nan("");
  }
  summary.tick_exec_ns_mean = drive.execution().mean_ns();
  summary.tick_exec_ns_max = drive.execution().max_ns;
  return summary;
}

}  // namespace

Summary run_scenario(const Scenario& scenario, const RunCallbacks& callbacks) {
  return scenario.precision == "float" ? run<float>(scenario, callbacks)
                                       : run<double>(scenario, callbacks);
}

}  // namespace imd::sim
