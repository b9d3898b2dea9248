#pragma once
/// The float-design build (tests/float_design.cmake) runs the drive's tests on the designs the
/// MCU computes in float. A test that checks an exactness only double designs can reach (a
/// paper's equation to 1e-9, a pole to 1e-12) skips itself there with its reason; the tests of
/// behaviour, the sweeps and the fault matrix run in both builds.
#include <gtest/gtest.h>

#include <type_traits>

#include "control/real.hpp"

/// Whether the designs are in double: a test that checks behaviour and an exactness in one keeps
/// the behaviour's checks in both builds and puts the exactness's under this.
inline constexpr bool kDoubleDesigns = std::is_same_v<::imd::Real, double>;

#define IMD_SKIP_IF_FLOAT_DESIGN(reason)                                   \
  do {                                                                     \
    if constexpr (!std::is_same_v<::imd::Real, double>) {                  \
      GTEST_SKIP() << "float designs (IMD_DESIGN_IN_FLOAT): " << (reason); \
    }                                                                      \
  } while (false)
