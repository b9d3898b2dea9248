#pragma once
/// What recomputing the exact discretization in float costs on the MCU: the model's coefficients
/// for a new rotor resistance, as the service loop needs them outside the tick. Timed on the
/// free-running timer (the core clock's counts: 40 ns, i.e. 40 instructions under QEMU's
/// -icount shift=0) over a few runs, and its stack measured by painting the stack below the
/// caller's frame and finding the deepest word that changed. Runs before the tick starts, so
/// that no interrupt nests on top. PIL image only.
#include <cstdint>

#include "control/voltage_fed_model.hpp"
#include "firmware/cortex_m/pil/mps2_an386.hpp"
#include "hal/cortex_m/stack_usage.hpp"

namespace imd::firmware {

struct RecomputeCost {
  uint32_t runs = 0;
  uint32_t counts_total = 0;  ///< timer counts of all runs
  uint32_t stack_bytes = 0;   ///< deepest stack of one run below the caller's frame
};

namespace recompute_detail {

/// Bytes below the caller's frame that are painted: twice what the discretization takes, and
/// within the start-up's high-water mark, which the paint would otherwise hide from the
/// end-of-run report (stack_used_bytes). A result of kProbeBytes means the probe overflowed.
inline constexpr uint32_t kProbeBytes = 2048;
/// Left alone just below the caller's frame: the painting function's own frame.
inline constexpr uint32_t kGuardBytes = 64;

[[gnu::noinline]] inline uint32_t stack_pointer() noexcept {
  uint32_t sp;
  asm volatile("mov %0, sp" : "=r"(sp));
  return sp;
}

[[gnu::noinline]] inline void paint(volatile uint32_t* from, volatile uint32_t* to) noexcept {
  for (volatile uint32_t* word = from; word < to; ++word) *word = hal::cortex_m::kStackPaint;
}

/// One recompute of the voltage-fed coefficients.
[[gnu::noinline]] inline void recompute(const control::MotorParameters& motor,
                                        Real delta_s) noexcept {
  const control::VoltageFedCoefficients c = control::discretize_voltage_fed<float>(motor, delta_s);
  asm volatile("" : : "r"(&c) : "memory");  // keep the result
}

}  // namespace recompute_detail

/// Measures `runs` recomputes of the voltage-fed discretization in float at sample period
/// `delta_s`, each for a rotor resistance 1 % apart. Not for tick context.
inline RecomputeCost measure_recompute(const mps2::FreeRunningTimer& clock,
                                       const control::MotorParameters& motor, Real delta_s,
                                       uint32_t runs) noexcept {
  namespace d = recompute_detail;
  RecomputeCost cost;
  cost.runs = runs;
  const uint32_t sp = d::stack_pointer();
  auto* const bottom = reinterpret_cast<volatile uint32_t*>(sp - d::kProbeBytes);
  auto* const top = reinterpret_cast<volatile uint32_t*>(sp - d::kGuardBytes);
  d::paint(bottom, top);
  d::recompute(motor, delta_s);
  volatile uint32_t* word = bottom;
  while (word < top && *word == hal::cortex_m::kStackPaint) ++word;
  cost.stack_bytes = sp - static_cast<uint32_t>(reinterpret_cast<uintptr_t>(word));
  control::MotorParameters m = motor;
  for (uint32_t k = 0; k < runs; ++k) {
    m.Rr_Ohm = motor.Rr_Ohm * (1 + Real(0.01) * Real(k));
    const uint32_t start = clock.counts();
    d::recompute(m, delta_s);
    cost.counts_total += clock.counts() - start;
  }
  return cost;
}

}  // namespace imd::firmware
