/// The drive firmware on an STM32G431CB motor controller with a 311 V inverter power stage
/// (docs/porting.md). Start-up: 170 MHz clock, the drivers of hal/cortex_m/stm32g4 wired by
/// reference, Drive<float> constructed once, then the tick: TIM1 runs the 10 kHz carrier, its
/// TRGO2 starts the ADC before each peak, the ADC's end of sequence is the sample stage and
/// PendSV the control stage (adc_tick.hpp). The drive takes its references and enable from CAN
/// commands and the enable line. The motor parameters come from the record in the last two
/// flash pages. The main loop moves queued CAN frames to the controller, serves the drive's
/// out-of-tick work (a new motor model, a save) and sleeps.
///
/// Safe state: TIM1 MOE off (every switch off). A processor fault, an unexpected interrupt or
/// a start-up failure goes there, lights the fault line and stops; the reason is kept in
/// g_fatal_fault / g_boot_failure for a debugger.
#include <cstdint>

#include <array>
#include <span>

#include "firmware/cortex_m/stm32g431/board_config.hpp"
#include "firmware/drive.hpp"
#include "firmware/parameters/motor_record.hpp"
#include "hal/cortex_m/stm32g4/flash_pages.hpp"
#include "hal/cortex_m/stm32g4/iwdg.hpp"
#include "hal/storage/page_pair_store.hpp"
#include "hal/cortex_m/armv7m.hpp"
#include "hal/cortex_m/fault_handler.hpp"

namespace imd::firmware::stm32g431 {
namespace {

namespace cm = hal::cortex_m;

enum class BootFailure : uint8_t { none, clock, adc, can, pwm_phase };

volatile BootFailure g_boot_failure = BootFailure::none;
volatile bool g_fatal = false;
volatile cm::FatalFault g_fatal_fault = cm::FatalFault::nmi;

/// Outputs off, fault line on, nothing else: the board waits for a reset.
[[noreturn]] void stop_in_safe_state() noexcept {
  cm::disable_interrupts();
  g4::Tim1Pwm::force_outputs_off();
  const g4::GpioLine& fault = kLines[kLineFault];
  g4::write_pin(fault.port, fault.pin, !fault.active_low);
  for (;;) cm::wait_for_interrupt();  // masked: wakes, but nothing runs
}

[[noreturn]] void halt(BootFailure why) noexcept {
  g_boot_failure = why;
  stop_in_safe_state();
}

/// The drive, built once from the motor record in the parameter pages (the newest whole copy;
/// without one the drive stays unconfigured, as its heartbeat says, until a record is written
/// over CAN). It follows its own CAN-commanded references (commands_over_can). Out of line:
/// the record, its decoded parameters and the configuration are temporaries of the
/// construction, about 700 B, which in main() would stay on the stack under every model
/// rebuild of the main loop, with the tick's interrupts on top.
[[gnu::noinline]] firmware::Drive<float>& build_drive(
    hal::PagePairStore<firmware::kMotorRecordBytes>& store,
    const firmware::DrivePeripherals& peripherals) noexcept {
  std::array<uint8_t, firmware::kMotorRecordBytes> record{};
  const std::size_t record_bytes = store.load(record);
  static firmware::Drive<float> drive(
      firmware::decode_motor_record(std::span<const uint8_t>(record).first(record_bytes)),
      drive_config(), peripherals);
  return drive;
}

}  // namespace
}  // namespace imd::firmware::stm32g431

namespace imd::hal::cortex_m {

void on_fatal_fault(FatalFault fault) noexcept {
  firmware::stm32g431::g_fatal_fault = fault;
  firmware::stm32g431::g_fatal = true;
  firmware::stm32g431::stop_in_safe_state();
}

}  // namespace imd::hal::cortex_m

int main() {
  using namespace imd;
  using namespace imd::firmware::stm32g431;
  namespace cm = hal::cortex_m;

  cm::reg32(cm::kScbVtor) = g4::kFlashBase;
  if (g4::init_system_clock() != g4::ClockStatus::ok) halt(BootFailure::clock);
  g4::enable_peripheral_clocks();
  g4::enable_cycle_counter();
  g4::configure_debug();

  // TIM1 first (outputs at their idle level), then its pins; every other pin.
  static g4::Tim1Pwm pwm(kPwm);
  g4::configure_pins(kPwmPins);
  g4::configure_pins(kOtherPins);
  static g4::BoardGpio gpio(kLines);
  static g4::AdcInjected adc(kAdc);
  if (!adc.ok()) halt(BootFailure::adc);
  static g4::TimEncoder encoder(kEncoder);
  static g4::FdcanClassic can(kCan);
  if (!can.ok()) halt(BootFailure::can);
  static g4::AdcEncoderSample sample(adc, encoder);
  static g4::AdcTick tick(kTick, adc, sample);
  static g4::FlashPagePair flash;
  static hal::PagePairStore<firmware::kMotorRecordBytes> store(flash);
  // The independent watchdog, fed by the control stage only, started once the ticks run (the
  // drive's construction builds the motor model, about 12 ms).
  const hal::ResetCause reset_cause = g4::take_reset_cause();
  static g4::Iwdg watchdog;
  firmware::Drive<float>& drive =
      build_drive(store, {pwm, encoder, adc, tick, &can, &gpio, &store, &watchdog, reset_cause});

  // The carrier (and with it the ADC trigger) starts; the update event must be the peak.
  if (!pwm.start()) halt(BootFailure::pwm_phase);
  g4::bind_adc_tick_interrupts(tick);
  tick.start(drive);
  watchdog.start(kWatchdogTimeout_us);
  for (;;) {
    can.pump();       // frames the last tick queued leave now, outside the tick
    drive.service();  // a parameter write's new model, a save: outside the tick
    cm::wait_for_interrupt();
  }
}
