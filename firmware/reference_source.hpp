#pragma once
/// Where the speed and flux references come from: a scenario profile in simulation, commands
/// on CAN on a board. The DSMC law needs the reference one step (or, with PWM latency, two
/// steps) ahead, so references are asked for by tick index.
/// T is the control arithmetic (float on the MCU): the tick converts nothing.
#include <cstdint>

namespace imd::firmware {

template <typename T>
struct Reference {
  T omega_mech_rad_s = T(0);
  T flux2_Wb2 = T(0);         ///< squared rotor-flux modulus (DSMC)
  T torque_Nm = T(0);         ///< torque (IOL without the outer speed loop)
  T stator_flux2_Wb2 = T(0);  ///< squared stator-flux modulus (IOL)
};

template <typename T>
class ReferenceSource {
 protected:
  // Never deleted through the interface (nothing is allocated): no virtual destructor, so
  // no deleting destructor and no operator delete in the vtables of the firmware.
  ~ReferenceSource() = default;

 public:
  /// The reference for tick k. Tick context. The same k gives the same reference: the
  /// supervisor reads the next tick's after this tick's PWM write (Supervisor::prepare).
  virtual Reference<T> at_tick(uint64_t k) const noexcept = 0;
};

}  // namespace imd::firmware
