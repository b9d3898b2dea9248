#pragma once
/// What this image carries: which control laws, and whether the commissioning. Every build
/// carries all of them unless its CMake target says otherwise; the STM32G431's run image
/// carries one law and no commissioning, and its commissioning image carries everything
/// (firmware/cortex_m/CMakeLists.txt, docs/flashing.md). A law or a commissioning that an
/// image leaves out is not compiled into it: a command that asks for one is refused with
/// `not_in_image`, and nothing else changes.
#include "firmware/drive_config.hpp"

#ifndef IMD_LAW_DSMC
#define IMD_LAW_DSMC 1
#endif
#ifndef IMD_LAW_IOL
#define IMD_LAW_IOL 1
#endif
#ifndef IMD_LAW_IFOC
#define IMD_LAW_IFOC 1
#endif
#ifndef IMD_COMMISSIONING
#define IMD_COMMISSIONING 1
#endif

namespace imd::firmware {

/// Whether this image has the law `kind` (a kind outside the enumeration: no).
constexpr bool law_in_image(ControllerKind kind) noexcept {
  switch (kind) {
    case ControllerKind::dsmc:
      return IMD_LAW_DSMC != 0;
    case ControllerKind::iol:
      return IMD_LAW_IOL != 0;
    case ControllerKind::ifoc:
      return IMD_LAW_IFOC != 0;
  }
  return false;
}

/// The first law of this image in ControllerKind order: a board's default controller.
constexpr ControllerKind first_law_in_image() noexcept {
  for (int i = 0; i < kControllerCount; ++i) {
    if (law_in_image(static_cast<ControllerKind>(i))) return static_cast<ControllerKind>(i);
  }
  return ControllerKind::dsmc;  // unreachable: the assertion below
}
static_assert(IMD_LAW_DSMC || IMD_LAW_IOL || IMD_LAW_IFOC, "an image carries at least one law");

/// Whether this image can identify a motor (firmware/identification/).
inline constexpr bool kCommissioningInImage = IMD_COMMISSIONING != 0;

}  // namespace imd::firmware
