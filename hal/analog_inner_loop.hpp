#pragma once
/// The analog part of the preliminary feedback (2) of paper 000, as a device:
///   u(t) = sigma p w(t) J (I(t) + beta Phi(t)) + e^{p th(t) J} v~_k,
/// evaluated continuously by an analog circuit, with v~_k = e^{-p th_k J} v_k written by the
/// firmware once per period. The paper's hybrid scheme needs it; real boards run (2) digitally
/// through the PWM instead, and only the simulated board provides this device (in double, so
/// that the paper's exactness can be checked).
namespace imd::hal {

class AnalogInnerLoop {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~AnalogInnerLoop() = default;

 public:
  /// Sets v~ (rotor-aligned frame) for the next period. Tick context.
  virtual void set_input_AB_V(double v_A_V, double v_B_V) noexcept = 0;
  /// The same from a single-precision drive: the device converts, so that the drive's tick
  /// converts nothing (the MCU has no double-precision FPU).
  virtual void set_input_AB_V(float v_A_V, float v_B_V) noexcept = 0;
};

}  // namespace imd::hal
