#pragma once
/// The arithmetic of what the drive computes from the motor outside the tick: the motor's
/// parameters, the drive's configuration, the discretization's coefficients and the laws'
/// designs. double on the host, where the reference computations and the tests need it; float
/// on the MCU (IMD_DESIGN_IN_FLOAT, set by the Cortex-M build), whose FPU has single precision
/// only: there a double is soft-float code, about 8 KB of flash linked for designs that float
/// computes to well within their purpose (each design's rounding is stated where it matters:
/// control/voltage_fed_model.hpp, control/encoder_observer.hpp). The tick's arithmetic is the
/// drive's template argument T, chosen separately.
namespace imd {

#if defined(IMD_DESIGN_IN_FLOAT) && IMD_DESIGN_IN_FLOAT
using Real = float;
#else
using Real = double;
#endif

}  // namespace imd
