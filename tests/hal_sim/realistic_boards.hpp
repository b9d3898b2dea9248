#pragma once
// The four motors of tests/test_motors.hpp on their realistic boards (0.75 kW to the paper-001
// machine, one to three pole pairs): the scenario files the sweeps take them from.
namespace imd::sim::test_boards {

inline constexpr const char* kRealistic[] = {"hal_sim/scenarios/seed000_realistic.toml",
                                             "hal_sim/scenarios/seed001_realistic.toml",
                                             "tests/data/scenarios/small_4pole_750W_realistic.toml",
                                             "tests/data/scenarios/six_pole_7kW_realistic.toml"};

}  // namespace imd::sim::test_boards
