#pragma once
/// drive_sim's summary: the metrics of a run as the JSON document docs/scenarios.md describes.
#include <nlohmann/json.hpp>

#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/scenario.hpp"

namespace imd::tools {

nlohmann::ordered_json summary_json(const imd::sim::Scenario& s, const imd::sim::Summary& r);

}  // namespace imd::tools
