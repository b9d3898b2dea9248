#pragma once
/// The arithmetic of what the drive computes from the motor outside the tick: the motor's
/// parameters, the drive's configuration, the discretization's coefficients and the laws'
/// designs. double on the host, where the reference computations and the tests need it; float
/// on the MCU (IMD_DESIGN_IN_FLOAT, set by the Cortex-M build and the float-design preset),
/// whose FPU has single precision only: there a double is soft-float code, which took 11 KB of
/// the board image's flash (6.2 KB of runtime and the code that calls it) for designs that
/// float computes well within their purpose (docs/performance-designs.md). The double
/// references and the simulated plant compute in double whatever Real is. The tick's
/// arithmetic is the drive's template argument T, chosen separately.
namespace imd {

#if defined(IMD_DESIGN_IN_FLOAT) && IMD_DESIGN_IN_FLOAT
using Real = float;
#else
using Real = double;
#endif

}  // namespace imd
