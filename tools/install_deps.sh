#!/bin/sh
# Installs the Debian 12 packages the build needs, if any is missing. Options add:
#   --tests     what only the tests need: python3-can and pytest (the Python client's suite),
#               and Node.js with the npm packages of the third-party DBC check (tools/dbc_check)
#   --plot      the main job's plots
#   --cortex-m  the bare-metal Cortex-M4F toolchain
#   --fuzz      clang and its libFuzzer runtime
#   --aarch64   the aarch64 Linux cross toolchain and libgpiod for arm64 (multiarch)
#   --qemu      QEMU for x86_64 and aarch64 and the tools the qemu test tier boots with
#   --rt        cyclictest (rt-tests), for the latency comparison
# Idempotent: when everything is present it changes nothing and needs no network.
set -eu
packages="g++ cmake ninja-build libeigen3-dev libtomlplusplus-dev libcli11-dev nlohmann-json3-dev
libfmt-dev libgtest-dev libbenchmark-dev libgpiod-dev python3"
arm64=no
tests=no
for option in "$@"; do
  case "$option" in
    --tests) packages="$packages python3-can python3-pytest"; tests=yes ;;
    --plot) packages="$packages python3 python3-numpy python3-matplotlib" ;;
    --cortex-m) packages="$packages gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib" ;;
    --fuzz) packages="$packages clang-14 libclang-rt-14-dev" ;;
    --aarch64) packages="$packages g++-aarch64-linux-gnu libgpiod-dev:arm64"; arm64=yes ;;
    # The guests' kernels and busybox are Debian packages fetched with apt-get download (the
    # arm64 ones need the arm64 architecture known to dpkg), cached in the build tree.
    --qemu) packages="$packages qemu-system-x86 qemu-system-arm busybox-static"; arm64=yes ;;
    --rt) packages="$packages rt-tests" ;;
    *) echo "install_deps: unknown option $option (known: --tests, --plot, --cortex-m, --fuzz, --aarch64, --qemu, --rt)" >&2; exit 2 ;;
  esac
done

# The third-party DBC check (tools/dbc_check) runs on Node.js: Debian's nodejs and npm, unless a
# node and an npm are already on the PATH.
if [ "$tests" = yes ] && { ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; }; then
  packages="$packages nodejs npm"
fi

if [ "$(id -u)" -eq 0 ]; then sudo=""; else sudo="sudo"; fi
updated=no
if [ "$arm64" = yes ] && ! dpkg --print-foreign-architectures | grep -qx arm64; then
  echo "install_deps: adding the arm64 architecture to dpkg"
  $sudo dpkg --add-architecture arm64
  $sudo apt-get update -qq
  updated=yes
fi

missing=""
for package in $packages; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing="$missing $package"
  fi
done
if [ -n "$missing" ]; then
  echo "install_deps: installing$missing"
  if [ "$updated" = no ]; then $sudo apt-get update -qq; fi
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $missing
fi

# ...and on the npm packages its package-lock.json pins.
dbc_check="$(cd "$(dirname "$0")" && pwd)/dbc_check"
if [ "$tests" = yes ] && [ ! -f "$dbc_check/node_modules/candied/package.json" ]; then
  echo "install_deps: npm ci in $dbc_check"
  npm ci --prefix "$dbc_check" --no-audit --no-fund
fi
