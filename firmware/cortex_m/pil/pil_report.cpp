#include "firmware/cortex_m/pil/pil_report.hpp"

#include "firmware/protocol/can_signal.hpp"
#include "firmware/protocol/messages.hpp"
#include "firmware/protocol/runtime_messages.hpp"
#include "hal/cortex_m/stack_usage.hpp"
#include "hal/cortex_m/text_line.hpp"

namespace imd::firmware {

using hal::cortex_m::TextLine;

void PilReport::start(const sim::EmbeddedScenario& s, const DriveConfig& drive,
                      uint32_t counts_per_period) noexcept {
  TextLine line;
  line << "pil start scenario " << s.name << " controller "
       << protocol::kControllerValues[static_cast<int>(drive.controller)].name << " duration_s ";
  line.scientific(s.duration_s, 4) << " counts_per_period " << uint64_t(counts_per_period)
                                   << " startup_stack_bytes "
                                   << uint64_t(hal::cortex_m::stack_used_bytes()) << "\n";
  console_.write(line.view());
}

void PilReport::recompute(const RecomputeCost& cost) noexcept {
  // One count of the core clock is 40 ns, 40 instructions under -icount shift=0.
  const uint64_t ns_per_count = 1000000000u / mps2::kCoreClock_Hz;
  TextLine line;
  line << "pil recompute ns_mean "
       << uint64_t(cost.counts_total) * ns_per_count / (cost.runs > 0 ? cost.runs : 1)
       << " stack_bytes " << uint64_t(cost.stack_bytes) << " runs " << uint64_t(cost.runs) << "\n";
  console_.write(line.view());
}

void PilReport::first_heartbeat(const hal::CanFrame& frame) noexcept {
  constexpr protocol::Signal kResetCause =
      protocol::runtime_signal_of(protocol::MessageId::heartbeat, "reset_cause");
  const auto raw = protocol::get_raw(frame.data, kResetCause);
  TextLine line;
  line << "pil first_heartbeat reset_cause "
       << protocol::kResetCauseValues[static_cast<std::size_t>(raw) & 3].name << "\n";
  console_.write(line.view());
}

void PilReport::watchdog(uint32_t interval_max_counts, uint32_t timeout_counts) noexcept {
  TextLine line;
  line << "pil watchdog feed_interval_max_counts " << uint64_t(interval_max_counts)
       << " timeout_counts " << uint64_t(timeout_counts) << "\n";
  console_.write(line.view());
}

void PilReport::stages(const sim::StageTotals& totals, uint32_t clock_Hz) noexcept {
  // Mean counts per tick of each stage, one line each; under QEMU -icount shift=0 with a
  // 25 MHz SysTick one count is 40 instructions.
  for (int i = 0; i < kStageCount; ++i) {
    TextLine line;
    line << "pil stage_" << kStageNames[i] << " mean_counts ";
    line.scientific(totals.ticks ? double(totals.counts[i]) / double(totals.ticks) : 0.0, 5);
    line << " clock_Hz " << uint64_t(clock_Hz) << " timed_ticks " << totals.ticks << "\n";
    console_.write(line.view());
  }
}

void PilReport::metric(const char* name, double value) noexcept {
  TextLine line;
  line << "pil metric " << name << " ";
  line.scientific(value, 7) << "\n";
  console_.write(line.view());
}

int PilReport::finish(const Drive<float>& drive, const hal::cortex_m::TwoStageTick& timer,
                      const sim::TickObserver<float>& observer, uint64_t frames_sent,
                      const ExecutionStats& whole_tick, uint64_t longest_tick) noexcept {
  const sim::RunMetrics& metrics = observer.metrics();
  metric("speed_rms_err_rad_s", observer.speed_rms_err_rad_s());
  metric("speed_max_err_rad_s", observer.speed_max_err_rad_s());
  metric("flux2_rms_err_Wb2", metrics.flux2_rms_err_Wb2());
  metric("flux2_max_err_Wb2", metrics.flux2_max_err_Wb2());
  metric("load_est_rms_err_Nm", metrics.load_est_rms_err_Nm());
  metric("i_peak_A", metrics.i_peak_A());
  metric("i_peak_total_A", metrics.i_peak_total_A());
  metric("saturated_fraction", metrics.saturated_fraction());
  metric("torque_rms_err_Nm", observer.torque_rms_err_Nm());
  metric("i_hold_rms_err_A", observer.i_hold_rms_err_A());
  metric("running_from_s", observer.running_from_s());

  const ExecutionStats& exec = drive.execution();
  TextLine line;
  // The tick's execution time on the SysTick clock; under QEMU -icount shift=0 one
  // instruction takes 1 ns of virtual time, so these are instructions per tick.
  line << "pil tick count " << exec.count << " exec_ns_mean " << exec.mean_whole_ns()
       << " exec_ns_max " << uint64_t(exec.max_ns) << " total_ns " << exec.total_ns << "\n";
  console_.write(line.view());
  line.clear();
  // The same from the control stage's start to its end: the work after the PWM write (the
  // observers' advance, the rotor-resistance tracker, telemetry) and one read of the clock.
  line << "pil tick whole_ns_mean " << whole_tick.mean_whole_ns() << " whole_ns_max "
       << uint64_t(whole_tick.max_ns) << " whole_max_at_tick " << longest_tick << "\n";
  console_.write(line.view());
  line.clear();
  line << "pil tick timer_overruns " << uint64_t(timer.overruns()) << " budget_overruns "
       << exec.overruns << " can_frames_sent " << frames_sent << "\n";
  console_.write(line.view());
  line.clear();
  // The model's rebuild on the tracked rotor resistance, in the main loop (service).
  const uint64_t ns_per_count = 1000000000u / timer.execution_clock_Hz();
  line << "pil retune count " << uint64_t(retunes_) << " ns_mean "
       << (retunes_ > 0 ? retune_counts_total_ * ns_per_count / retunes_ : 0) << " ns_max "
       << uint64_t(retune_counts_max_) * ns_per_count << "\n";
  console_.write(line.view());
  line.clear();
  line << "pil memory stack_used_bytes " << uint64_t(hal::cortex_m::stack_used_bytes())
       << " stack_size_bytes " << uint64_t(hal::cortex_m::stack_size_bytes()) << "\n";
  console_.write(line.view());
  line.clear();
  line << "pil fault code " << fault_name(drive.fault()) << " state " << state_name(drive.state())
       << "\n";
  console_.write(line.view());

  const bool ok = drive.fault() == FaultCode::none && timer.overruns() == 0 &&
                  exec.overruns == 0 && metrics.measured_ticks() > 0;
  line.clear();
  line << "pil end status " << uint64_t(ok ? 0 : 1) << "\n";
  console_.write(line.view());
  return ok ? 0 : 1;
}

}  // namespace imd::firmware
