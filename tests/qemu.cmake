# The qemu tier: drive_hil and drive_monitor on Debian's own kernels under QEMU, over vcan, and
# on aarch64 with the virt machine's PL061 GPIO (tests/qemu/hil_test.py). The guests run a bare
# busybox initramfs, so the host build also builds the two programs statically: natively for
# the x86_64 guest and with the aarch64 cross toolchain for the aarch64 guest, each in its own
# tree under the build directory. Debian's kernel packages are cached in build/qemu-cache.
include(ExternalProject)
set(IMD_QEMU_PROGRAMS drive_hil drive_monitor)
set(IMD_QEMU_CACHE ${CMAKE_BINARY_DIR}/qemu-cache)

function(imd_qemu_programs ARCH)
  ExternalProject_Add(qemu_programs_${ARCH}
    SOURCE_DIR ${PROJECT_SOURCE_DIR}
    BINARY_DIR ${CMAKE_BINARY_DIR}/qemu-${ARCH}
    CMAKE_ARGS -DCMAKE_BUILD_TYPE=Release -DIMD_BUILD_TESTS=OFF -DIMD_BUILD_BENCHMARKS=OFF
               -DIMD_STATIC_LINK=ON ${ARGN}
    BUILD_COMMAND ${CMAKE_COMMAND} --build <BINARY_DIR> --target ${IMD_QEMU_PROGRAMS}
    INSTALL_COMMAND ""
    BUILD_ALWAYS ON)  # the sources are this project's: let its own build decide what changed
endfunction()

imd_qemu_programs(x86_64)
find_program(IMD_AARCH64_CXX aarch64-linux-gnu-g++)
if(IMD_AARCH64_CXX)
  imd_qemu_programs(aarch64
    -DCMAKE_TOOLCHAIN_FILE=${PROJECT_SOURCE_DIR}/toolchains/aarch64-linux-gnu.cmake)
else()
  # The test below then fails and says how to get the cross toolchain.
  message(WARNING "aarch64-linux-gnu-g++ not found: the qemu_hil_aarch64 test will fail "
                  "(tools/install_deps.sh --aarch64 installs it)")
endif()

foreach(arch x86_64 aarch64)
  add_test(NAME qemu_hil_${arch}
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/qemu/hil_test.py
                   --arch ${arch} --bin-dir ${CMAKE_BINARY_DIR}/qemu-${arch}/bin
                   --source-dir ${PROJECT_SOURCE_DIR} --cache ${IMD_QEMU_CACHE}
                   --work ${CMAKE_BINARY_DIR}/qemu-work-${arch})
  # Alone on the machine: each QEMU keeps one core busy, and the guest's loop is timed. The
  # limit covers the first run's kernel download as well as the guest's own 115 s limit.
  set_tests_properties(qemu_hil_${arch} PROPERTIES LABELS qemu RUN_SERIAL ON TIMEOUT 400)
endforeach()
