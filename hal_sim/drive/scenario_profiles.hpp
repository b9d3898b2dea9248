#pragma once
/// A scenario's reference profiles: speed, rotor flux, torque and stator flux as functions of
/// time, evaluated in double (the scenario's arithmetic). No heap: the processor-in-the-loop
/// image computes them on the MCU, outside the tick.
#include "firmware/reference_source.hpp"
#include "hal_sim/load_profile.hpp"
#include "hal_sim/speed_profile.hpp"

namespace imd::sim {

struct ScenarioProfiles {
  SpeedProfile speed;
  double flux2_Wb2 = 0.2;         ///< squared rotor flux (dsmc)
  LoadProfile torque;             ///< torque reference (iol without the outer speed loop)
  double stator_flux2_Wb2 = 0.0;  ///< squared stator flux (iol)

  firmware::Reference<double> at(double t_s) const noexcept {
    return {speed.at(t_s), flux2_Wb2, torque.at(t_s), stator_flux2_Wb2};
  }
};

/// The reference a drive of arithmetic T sees at tick k: the profiles at k * period, rounded
/// once to T.
template <typename T>
firmware::Reference<T> reference_at_tick(const ScenarioProfiles& profiles, double period_s,
                                         uint64_t k) noexcept {
  const firmware::Reference<double> r = profiles.at(double(k) * period_s);
  return {T(r.omega_mech_rad_s), T(r.flux2_Wb2), T(r.torque_Nm), T(r.stator_flux2_Wb2)};
}

}  // namespace imd::sim
