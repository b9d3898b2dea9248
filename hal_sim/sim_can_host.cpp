#include "hal_sim/sim_can_host.hpp"

namespace imd::sim {

std::vector<hal::CanFrame> take_all_sent(SimCan& can) {
  std::vector<hal::CanFrame> out;
  take_all_sent(can, out);
  return out;
}

void take_all_sent(SimCan& can, std::vector<hal::CanFrame>& out) {
  out.clear();
  for (hal::CanFrame frame; can.take_sent(frame);) out.push_back(frame);
}

}  // namespace imd::sim
