#pragma once
/// An ideal stator current source, as paper 001 assumes ("current-fed"): the current written,
/// in the rotor-aligned frame, is imposed exactly and held there until the next write. Real
/// boards reach the current-fed mode through an inner current loop on the PWM instead; only the
/// simulated board provides this device, in double so that the paper's exactness can be checked
/// to 1e-9.
namespace imd::hal {

class CurrentSource {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~CurrentSource() = default;

 public:
  /// Sets the rotor-frame stator current from the next period on. Tick context.
  virtual void set_current_AB_A(double iA_A, double iB_A) noexcept = 0;
  /// The same from a single-precision drive: the device converts, so that the drive's tick
  /// converts nothing (the MCU has no double-precision FPU).
  virtual void set_current_AB_A(float iA_A, float iB_A) noexcept = 0;
};

}  // namespace imd::hal
