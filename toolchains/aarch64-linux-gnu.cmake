# Cross build for a 64-bit Arm Linux controller board (Raspberry-Pi class) with Debian's
# g++-aarch64-linux-gnu. Header-only dependencies (Eigen) come from the build machine; libraries
# are searched in the aarch64 trees only: the cross toolchain's /usr/aarch64-linux-gnu and, through
# the root "/" and CMAKE_LIBRARY_ARCHITECTURE, Debian's multiarch /usr/lib/aarch64-linux-gnu
# (where libgpiod-dev:arm64 puts libgpiod).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH /usr/aarch64-linux-gnu /)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
