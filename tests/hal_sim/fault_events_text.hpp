#pragma once
// A run's fault events as one line, for the sweeps' failure messages.
#include <string>

#include "hal_sim/drive/scenario_run.hpp"

namespace imd::sim {

inline std::string faults_text(const Summary& r) {
  std::string text;
  for (const FaultEvent& f : r.faults) text += f.code + " at " + std::to_string(f.detected_at_s) + " ";
  return text;
}

}  // namespace imd::sim
