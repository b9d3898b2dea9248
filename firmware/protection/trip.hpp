#pragma once
/// The faults a tick's checks found: every code that tripped, and the first one (which the
/// drive latches as its fault, with its detail, e.g. the phase). Tick context.
#include <cstdint>

#include "firmware/drive_state.hpp"

namespace imd::firmware {

/// The detail of an `overcurrent` that the power stage's hardware trip (the timer's break input)
/// found rather than a phase's measurement.
inline constexpr uint8_t kHardwareTripDetail = 3;

struct Trip {
  uint16_t bits = 0;  ///< bit n: code n tripped
  FaultCode first = FaultCode::none;
  uint8_t detail = 0;  ///< of the first: a phase index, or 0

  bool any() const noexcept { return bits != 0; }
  void add(FaultCode code, uint8_t detail_of_code = 0) noexcept {
    if (!any()) {
      first = code;
      detail = detail_of_code;
    }
    bits = static_cast<uint16_t>(bits | (1u << unsigned(code)));
  }
};

}  // namespace imd::firmware
