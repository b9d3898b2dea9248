#include "firmware/cortex_m/pil/pil_report.hpp"

#include "hal/cortex_m/stack_usage.hpp"
#include "hal/cortex_m/text_line.hpp"

namespace imd::firmware {

using hal::cortex_m::TextLine;

sim::MetricsSample tracking_sample(const sim::EmbeddedScenario& s, const sim::PlantState& truth,
                              double load_Nm, const TickRecord<float>& record,
                              double t_s) noexcept {
  sim::MetricsSample m;
  m.t_s = t_s;
  m.speed_err_rad_s = truth.omega_mech_rad_s - s.references.speed.at(t_s);
  // |Phi|^2 is the same in every frame: no rotation into the rotor frame needed.
  m.flux2_err_Wb2 = truth.flux_r_alphabeta_Wb.squaredNorm() - s.references.flux2_Wb2;
  m.load_err_Nm = double(record.load_est_Nm) - load_Nm;
  m.current_A = truth.i_s_alphabeta_A.norm();
  m.saturated = record.law.speed_saturated || record.law.flux_saturated || record.voltage_clipped;
  return m;
}

void PilReport::start(const sim::EmbeddedScenario& s, uint32_t counts_per_period) noexcept {
  TextLine line;
  line << "pil start scenario " << s.name << " duration_s ";
  line.scientific(s.duration_s, 4) << " counts_per_period " << uint64_t(counts_per_period)
                                   << " startup_stack_bytes "
                                   << uint64_t(hal::cortex_m::stack_used_bytes()) << "\n";
  console_.write(line.view());
}

void PilReport::stages(const StageTotals& totals, uint32_t clock_Hz) noexcept {
  // Mean counts per tick of each stage, one line each; under QEMU -icount shift=0 with a
  // 25 MHz SysTick one count is 40 instructions.
  for (int i = 0; i < kStageCount; ++i) {
    TextLine line;
    line << "pil stage " << kStageNames[i] << " clock_Hz " << uint64_t(clock_Hz) << " mean_counts ";
    line.scientific(totals.ticks ? double(totals.counts[i]) / double(totals.ticks) : 0.0, 5);
    line << "\n";
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
                      const sim::RunMetrics& metrics, double running_from_s,
                      uint64_t frames_sent) noexcept {
  metric("speed_rms_err_rad_s", metrics.speed_rms_err_rad_s());
  metric("speed_max_err_rad_s", metrics.speed_max_err_rad_s());
  metric("flux2_rms_err_Wb2", metrics.flux2_rms_err_Wb2());
  metric("flux2_max_err_Wb2", metrics.flux2_max_err_Wb2());
  metric("load_est_rms_err_Nm", metrics.load_est_rms_err_Nm());
  metric("i_peak_A", metrics.i_peak_A());
  metric("i_peak_total_A", metrics.i_peak_total_A());
  metric("saturated_fraction", metrics.saturated_fraction());
  metric("running_from_s", running_from_s);

  const ExecutionStats& exec = drive.execution();
  TextLine line;
  // The tick's execution time on the SysTick clock; under QEMU -icount shift=0 one
  // instruction takes 1 ns of virtual time, so these are instructions per tick.
  line << "pil tick count " << exec.count << " exec_ns_mean " << exec.mean_whole_ns()
       << " exec_ns_max " << uint64_t(exec.max_ns) << " total_ns " << exec.total_ns << "\n";
  console_.write(line.view());
  line.clear();
  line << "pil tick timer_overruns " << uint64_t(timer.overruns()) << " budget_overruns "
       << exec.overruns << " can_frames_sent " << frames_sent << "\n";
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
