#pragma once
/// Host-side helpers of the simulated CAN bus (Linux library only: they allocate).
#include <vector>

#include "hal/can_bus.hpp"
#include "hal_sim/sim_peripherals.hpp"

namespace imd::sim {

/// Takes every frame the firmware sent since the last call, oldest first.
std::vector<hal::CanFrame> take_all_sent(SimCan& can);
/// The same into `out` (cleared first): no allocation once `out` has grown.
void take_all_sent(SimCan& can, std::vector<hal::CanFrame>& out);

}  // namespace imd::sim
