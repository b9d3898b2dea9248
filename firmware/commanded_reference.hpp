#pragma once
/// The references set by CAN commands (set_speed, set_flux): constant until the next command.
/// The speed ramp of the tick limits how fast a new speed is approached.
#include "firmware/reference_source.hpp"

namespace imd::firmware {

template <typename T>
class CommandedReference final : public ReferenceSource<T> {
 public:
  CommandedReference(T flux2_Wb2, T stator_flux2_Wb2) noexcept {
    reference_.flux2_Wb2 = flux2_Wb2;
    reference_.stator_flux2_Wb2 = stator_flux2_Wb2;
  }
  Reference<T> at_tick(uint64_t) const noexcept override { return reference_; }
  void set_speed(T omega_mech_rad_s) noexcept { reference_.omega_mech_rad_s = omega_mech_rad_s; }
  void set_flux2(T flux2_Wb2) noexcept { reference_.flux2_Wb2 = flux2_Wb2; }
  void set_stator_flux2(T flux2_Wb2) noexcept { reference_.stator_flux2_Wb2 = flux2_Wb2; }

 private:
  Reference<T> reference_;
};

}  // namespace imd::firmware
