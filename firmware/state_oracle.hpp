#pragma once
/// The true motor state, in the rotor-aligned frame, as only a simulated board can provide it.
/// With an oracle the drive runs on "ideal sensors" (paper 000's Section III hypothesis); the
/// Section IV observers can still replace the flux and load.
namespace imd::firmware {

struct TrueState {
  double flux_r_A_Wb = 0.0, flux_r_B_Wb = 0.0;
  double i_s_A_A = 0.0, i_s_B_A = 0.0;
  double omega_mech_rad_s = 0.0;
  double theta_mech_rad = 0.0;
  double load_Nm = 0.0;
};

class StateOracle {
 public:
  virtual ~StateOracle() = default;
  /// The state at the start of the present tick. Tick context.
  virtual TrueState true_state() const noexcept = 0;
};

}  // namespace imd::firmware
