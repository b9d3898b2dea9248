# Bare-metal build for a Cortex-M4F motor-control MCU with Debian's gcc-arm-none-eabi, newlib
# and libstdc++: Thumb-2, single-precision FPU with the hard-float ABI, no exceptions, no RTTI,
# one section per function so that the linker drops what the firmware does not use.
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(CMAKE_C_COMPILER arm-none-eabi-gcc)
set(CMAKE_CXX_COMPILER arm-none-eabi-g++)
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)  # no startup code for test programs

set(IMD_MCU_FLAGS "-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16")
set(CMAKE_C_FLAGS_INIT "${IMD_MCU_FLAGS} -ffunction-sections -fdata-sections")
# -Wno-psabi: GCC notes that the parameter passing of some Eigen types changed in GCC 7.1, which
# matters only when linking with objects built by GCC < 7.1; none are.
set(CMAKE_CXX_FLAGS_INIT
    "${IMD_MCU_FLAGS} -ffunction-sections -fdata-sections -fno-exceptions -fno-rtti -fno-threadsafe-statics -Wno-psabi")
set(CMAKE_EXE_LINKER_FLAGS_INIT "${IMD_MCU_FLAGS} -Wl,--gc-sections --specs=nano.specs")

# Headers of the build machine (Eigen) are used as they are; nothing is searched for libraries.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
