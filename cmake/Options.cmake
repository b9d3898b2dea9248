# Every build option of the project, in one place (the presets in CMakePresets.json set them).
option(IMD_BUILD_TESTS "Build the GoogleTest tiers (off: aarch64 and cortex-m4f presets)" ON)
option(IMD_BUILD_BENCHMARKS "Build the Google Benchmark programs (off: all presets but host)" ON)
# Static programs run in a bare initramfs or on a board without the build's shared libraries.
option(IMD_STATIC_LINK "Link the programs statically (the aarch64 preset)" OFF)
option(IMD_QEMU_TIER
       "Build the static programs of the qemu test tier and register its tests (off: asan, fuzz)"
       ON)
# Off in the asan preset: its run is the libraries' tests and the soak, and the programs'
# command lines are compiled and run by the host preset (and their parsers fuzzed).
option(IMD_BUILD_HOST_TOOLS
       "Build the host programs (drive_sim, drive_monitor, drive_hil, ...) and their tests"
       ON)
# Off in the asan preset: the sweeps run the drive's code the shorter tests take through the
# sanitizers, over many more cases (the host and float-design presets run them).
option(IMD_BUILD_SWEEPS "Build the protections' sweeps over motors, loads and references" ON)
option(IMD_BUILD_FUZZERS "Build the libFuzzer harnesses (clang: the fuzz preset)" OFF)
# Off by default, so that a user's newer compiler with new warnings still builds; the presets
# CI builds turn it on.
option(IMD_WARNINGS_AS_ERRORS "Compile with -Werror (every preset CI or the qemu tier builds)" OFF)
# The design arithmetic (control/real.hpp): float on the MCU, whose FPU has no double; a host
# build with it on runs the tests on the designs the MCU computes (the float-design preset).
option(IMD_DESIGN_IN_FLOAT "Compute the designs in float, as the MCU does (always on there)" OFF)
if(IMD_QEMU_TIER AND IMD_BUILD_TESTS AND NOT IMD_BUILD_HOST_TOOLS)
  message(FATAL_ERROR "IMD_QEMU_TIER needs IMD_BUILD_HOST_TOOLS: its tests run drive_sim")
endif()
