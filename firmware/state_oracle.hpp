#pragma once
/// The true motor state, in the rotor-aligned frame, as only a simulated board can provide it.
/// With an oracle the drive runs on "ideal sensors" (paper 000's Section III hypothesis); the
/// Section IV observers can still replace the flux and load. T is the drive's arithmetic.
namespace imd::firmware {

template <typename T>
struct TrueState {
  T flux_r_A_Wb = T(0), flux_r_B_Wb = T(0);
  T iA_s_A = T(0), iB_s_A = T(0);
  T omega_mech_rad_s = T(0);
  T theta_mech_rad = T(0);
  T load_Nm = T(0);
};

template <typename T>
class StateOracle {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~StateOracle() = default;

 public:
  /// The state at the start of the present tick. Tick context.
  virtual TrueState<T> true_state() const noexcept = 0;
};

}  // namespace imd::firmware
