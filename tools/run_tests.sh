#!/bin/sh
# Test job: builds the host preset (Release with assertions) and runs every test tier, the
# qemu tier included (QEMU, the aarch64 and Cortex-M4F cross toolchains and Debian's kernels:
# see tests/qemu).
set -eu
cd "$(dirname "$0")/.."
tools/install_deps.sh --tests --qemu --aarch64 --cortex-m --plot
cmake --preset host
cmake --build --preset host
ctest --preset host --parallel 2
