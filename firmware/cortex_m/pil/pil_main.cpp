/// Processor in the loop: the drive firmware on an emulated Cortex-M4F (QEMU mps2-an386)
/// against the simulated board, compiled for the MCU too. The tick, at the scenario's period,
/// runs from SysTick in its two stages (hal/cortex_m/two_stage_tick.hpp): the sample stage
/// latches the simulated sensors, the control stage runs Drive<float>. The timer is in
/// lock-step: after each tick time stands still while the main loop advances the plant by one
/// period (in double, which this FPU does not have, so it is far slower than real time) and
/// fills the references ahead. The scenarios are compiled in (seed000_realistic_scenario.cpp,
/// seed001_realistic_scenario.cpp, and seed000_realistic_20kHz_scenario.cpp, the first at
/// 20 kHz); the emulator's command line chooses one and may change its law (pil_options.hpp).
/// At the end the summary goes to the UART and the run ends through semihosting with the exit
/// status:
///   0 the run completed with no fault and no overrun, 1 it did not, 2 a bad command line,
///   3 a processor fault.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "firmware/cortex_m/pil/mps2_an386.hpp"
#include "firmware/cortex_m/pil/pil_options.hpp"
#include "firmware/cortex_m/pil/pil_report.hpp"
#include "firmware/cortex_m/pil/recompute_probe.hpp"
#include "firmware/drive.hpp"
#include "hal_sim/drive/embedded_scenario.hpp"
#include "hal_sim/drive/lookahead_references.hpp"
#include "hal/cortex_m/armv7m.hpp"
#include "hal/cortex_m/cmsdk_uart.hpp"
#include "hal/cortex_m/cmsdk_watchdog.hpp"
#include "hal/cortex_m/reset_record.hpp"
#include "hal/cortex_m/fault_handler.hpp"
#include "hal/cortex_m/semihosting.hpp"
#include "hal/cortex_m/two_stage_tick.hpp"
#include "hal_sim/drive/lockstep_period.hpp"
#include "hal_sim/drive/simulated_drive.hpp"
#include "hal_sim/sim_board.hpp"

namespace imd::firmware {

extern const sim::EmbeddedScenario kSeed000Realistic;
extern const sim::EmbeddedScenario kSeed001Realistic;
extern const sim::EmbeddedScenario kSeed000Realistic20kHz;

namespace {

namespace cm = hal::cortex_m;

/// The watchdog's period, in its clock's counts (the core clock's, 25 MHz of virtual time:
/// QEMU -icount shift=0 runs an instruction per ns). 0.2 s covers the lock-step's plant work
/// between two ticks (the report gives the largest interval seen) many times over.
constexpr uint32_t kWatchdogTimeoutCounts = mps2::kCoreClock_Hz / 5;

/// The sample stage: the simulated ADC and encoder latch the plant's state at t_k.
class SimulatedSensors final : public cm::SampleStage {
 public:
  explicit SimulatedSensors(sim::SimBoard& board) : board_(board) {}
  void sample() noexcept override { board_.begin_period(); }

 private:
  sim::SimBoard& board_;
};

cm::CmsdkUart* g_console = nullptr;
cm::CmsdkWatchdog* g_watchdog = nullptr;

/// The control stage as the timer runs it: the drive's tick, which hangs at `stall_tick` (a
/// stalled control stage: only the watchdog gets the board out). It times the whole tick, the
/// work after the PWM write included, which the drive's own figure (to the write) leaves out:
/// the share of the processor the tick takes is this one.
class ControlStage final : public hal::TickHandler {
 public:
  ControlStage(Drive<float>& drive, const hal::ControlTimer& timer, uint64_t stall_tick) noexcept
      : drive_(drive), timer_(timer), stall_tick_(stall_tick),
        ns_per_count_(uint32_t(1000000000u / timer.execution_clock_Hz())) {}
  void on_tick() noexcept override {
    if (timer_.tick_count() == stall_tick_) {
      for (volatile bool hung = true; hung;) {
      }
    }
    const uint32_t start = timer_.execution_counts();
    drive_.on_tick();
    const uint32_t ns = (timer_.execution_counts() - start) * ns_per_count_;
    if (ns > whole_.max_ns) longest_tick_ = timer_.tick_count();
    whole_.add(ns);
  }
  const ExecutionStats& whole_tick() const noexcept { return whole_; }
  uint64_t longest_tick() const noexcept { return longest_tick_; }

 private:
  Drive<float>& drive_;
  const hal::ControlTimer& timer_;
  uint64_t stall_tick_;
  uint32_t ns_per_count_;
  ExecutionStats whole_;
  uint64_t longest_tick_ = 0;
};

/// Sleeps until the control stage of this tick has finished. Interrupts are masked around the
/// test so that the end of the tick cannot slip in between the test and the sleep (WFI still
/// wakes on a pending interrupt).
void wait_for_tick(const cm::TwoStageTick& timer) noexcept {
  for (;;) {
    cm::disable_interrupts();
    if (timer.paused()) break;
    cm::wait_for_interrupt();
    cm::enable_interrupts();
  }
  cm::enable_interrupts();
}

/// The plant of the scenario, its rotor resistance at `rr_percent` % of the scenario's.
control::MotorParameters plant_of(const sim::EmbeddedScenario& s, int rr_percent) noexcept {
  control::MotorParameters plant = s.plant;
  plant.Rr_Ohm = plant.Rr_Ohm * Real(rr_percent) / 100;
  return plant;
}

int run(const sim::EmbeddedScenario& s, const PilOptions& options, hal::ResetCause reset_cause,
        cm::CmsdkUart& console) {
  const DriveConfig& drive_config = options.drive;
  static sim::SimBoard board(plant_of(s, options.plant_rr_percent), s.board);
  board.set_load_profile(s.load);
  board.plant().set_state(s.initial_state);
  static sim::LookaheadReferences<float> references(s.references, s.drive.sample_period_s);
  static SimulatedSensors sensors(board);
  static cm::TwoStageTick timer(
      {mps2::kCoreClock_Hz, static_cast<uint32_t>(s.board.period_s * 1e9 + 0.5), true}, sensors);
  // The realistic board: the drive's own sensing, estimation and SVPWM, no substitutes.
  static sim::SimulatedDrive<float> simulated(board, s.motor, drive_config, {}, &references, timer,
                                              &board.can(), &board.gpio(), nullptr, g_watchdog,
                                              reset_cause);
  Drive<float>& drive = simulated.drive();
  // After a watchdog reset the run goes on without the stall that caused it.
  const bool stall = options.stall_at_ms >= 0 && reset_cause != hal::ResetCause::watchdog;
  static ControlStage control(
      drive, timer,
      stall ? static_cast<uint64_t>(double(options.stall_at_ms) * 1e-3 / s.board.period_s + 0.5)
            : UINT64_MAX);
  // The same rows and metrics as drive_sim's (hal_sim/drive/tick_observer.hpp).
  static sim::TickObserver<float> observer(
      sim::observed_run(s.references, s.settle_s, s.motor, drive_config));
  PilReport report(console);
  static const mps2::FreeRunningTimer service_clock;
  report.start(s, drive_config, timer.counts_per_period());  // with the stack used so far: the start-up's
  // What the tracker's retune costs in the discretization alone, before the tick starts.
  report.recompute(measure_recompute(service_clock, s.motor, drive_config.sample_period_s, 8));

  const double duration_s =
      options.duration_ms > 0 ? double(options.duration_ms) * 1e-3 : s.duration_s;
  const auto ticks = static_cast<uint64_t>(duration_s / s.board.period_s + 0.5);
  bool heartbeat_seen = false;
  uint32_t feed_interval_max = 0, last_feed_counts = service_clock.counts();
  uint64_t frames_sent = 0;
  sim::StageTotals stage_totals;
  hal::CanFrame frame;
  references.fill_from(0);
  cm::bind_tick_interrupts(timer);
  timer.start(control);
  for (uint64_t k = 0; k < ticks; ++k) {
    const double t_s = double(k) * s.board.period_s;
    // The tick runs from the timer's interrupts; then time stands still while the plant
    // advances over [t_k, t_k+1] and the row is observed.
    const sim::SimRow& row = sim::lockstep_period(board, drive, observer, t_s, [&] {
      if (k > 0) timer.resume();
      wait_for_tick(timer);
      // The watchdog's period must cover the lock-step's plant work between ticks.
      const uint32_t now = service_clock.counts();
      feed_interval_max = std::max(feed_interval_max, now - last_feed_counts);
      last_feed_counts = now;
    });
    const uint32_t retunes = drive.retunes();
    const uint32_t service_start = service_clock.counts();
    drive.service();  // the main loop's out-of-tick work, between ticks
    if (drive.retunes() != retunes) report.retuned(service_clock.counts() - service_start);
    const TickRecord<float>& rec = drive.record();
    while (board.can_side().take_sent(frame)) {  // the host side reads the bus
      ++frames_sent;
      if (!heartbeat_seen && frame.id == protocol::can_id(drive_config.node_id,
                                                          protocol::MessageId::heartbeat)) {
        heartbeat_seen = true;
        report.first_heartbeat(frame);
      }
    }
    if (rec.stages_timed) stage_totals.add(rec.stage_counts);
    references.fill_from(k + 1);
    if (!std::isfinite(row.i_alpha_A) || !std::isfinite(row.i_beta_A)) break;
  }
  timer.stop();
  report.watchdog(feed_interval_max, kWatchdogTimeoutCounts);
  report.stages(stage_totals, timer.execution_clock_Hz());
  return report.finish(drive, timer, observer, frames_sent, control.whole_tick(),
                       control.longest_tick());
}

}  // namespace

}  // namespace imd::firmware

namespace imd::hal::cortex_m {

void on_fatal_fault(FatalFault fault) noexcept {
  // The watchdog's first expiry: record why the reset that follows happens, and wait for it.
  if (fault == FatalFault::nmi && imd::firmware::g_watchdog != nullptr &&
      imd::firmware::g_watchdog->expired()) {
    record_reset_cause(imd::hal::ResetCause::watchdog);
    if (imd::firmware::g_console != nullptr) {
      imd::firmware::g_console->write("pil watchdog expired: the board resets\n");
    }
    for (;;) {
    }
  }
  // Nothing drives a power stage here; report and end the emulation.
  if (imd::firmware::g_console != nullptr) {
    imd::firmware::g_console->write("pil fatal_fault ");
    imd::firmware::g_console->write(fatal_fault_name(fault));
    imd::firmware::g_console->write("\n");
  }
  semihosting_exit(3);
}

}  // namespace imd::hal::cortex_m

int main() {
  using namespace imd;
  static hal::cortex_m::CmsdkUart console(firmware::mps2::kUart0, firmware::mps2::kCoreClock_Hz,
                                          firmware::mps2::kUartBaud_Hz);
  firmware::g_console = &console;
  const hal::ResetCause reset_cause = hal::cortex_m::take_reset_cause();
  console.write("pil reset_cause ");
  console.write(firmware::protocol::kResetCauseValues[static_cast<int>(reset_cause)].name);
  console.write("\n");
  // Fed by the control stage only: a stalled tick ends in its NMI, then a reset.
  static hal::cortex_m::CmsdkWatchdog watchdog(firmware::mps2::kWatchdog,
                                               firmware::kWatchdogTimeoutCounts);
  firmware::g_watchdog = &watchdog;
  static char command_line[128];
  if (!hal::cortex_m::semihosting_command_line(command_line, sizeof command_line)) {
    command_line[0] = '\0';
  }
  static const sim::EmbeddedScenario* const scenarios[] = {
      &firmware::kSeed000Realistic, &firmware::kSeed001Realistic,
      &firmware::kSeed000Realistic20kHz};
  static firmware::PilOptions options = firmware::parse_pil_options(command_line, scenarios);
  if (options.error != nullptr) {
    console.write("pil error ");
    console.write(options.error);
    console.write(" in the command line: ");
    console.write(command_line);
    console.write("\n");
    hal::cortex_m::semihosting_exit(2);
  }
  hal::cortex_m::semihosting_exit(
      firmware::run(*options.scenario, options, reset_cause, console));
}
