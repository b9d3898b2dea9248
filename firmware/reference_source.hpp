#pragma once
/// Where the speed and flux references come from: a scenario profile in simulation, commands
/// on CAN on a board. The DSMC law needs the reference one step (or, with PWM latency, two
/// steps) ahead, so references are asked for by tick index.
#include <cstdint>

namespace imd::firmware {

struct Reference {
  double omega_mech_rad_s = 0.0;
  double flux2_Wb2 = 0.0;         ///< squared rotor-flux modulus (DSMC)
  double torque_Nm = 0.0;         ///< torque (IOL without the outer speed loop)
  double stator_flux2_Wb2 = 0.0;  ///< squared stator-flux modulus (IOL)
};

class ReferenceSource {
 public:
  virtual ~ReferenceSource() = default;
  /// The reference for tick k. Tick context.
  virtual Reference at_tick(uint64_t k) const noexcept = 0;
};

}  // namespace imd::firmware
