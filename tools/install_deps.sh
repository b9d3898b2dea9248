#!/bin/sh
# Installs the Debian 12 packages the build and the tests need (with --plot, those the main
# job's plots need; with --cortex-m, the bare-metal Cortex-M4F toolchain; with --fuzz, clang and
# its libFuzzer runtime) if any is missing.
# Idempotent: when everything is present it changes nothing and needs no network.
set -eu
packages="g++ cmake ninja-build libeigen3-dev libtomlplusplus-dev libcli11-dev nlohmann-json3-dev
libfmt-dev libgtest-dev libbenchmark-dev python3"
for option in "$@"; do
  case "$option" in
    --plot) packages="$packages python3 python3-numpy python3-matplotlib" ;;
    --cortex-m) packages="$packages gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib" ;;
    --fuzz) packages="$packages clang-14 libclang-rt-14-dev" ;;
    *) echo "install_deps: unknown option $option (known: --plot, --cortex-m, --fuzz)" >&2; exit 2 ;;
  esac
done

# The third-party DBC check (tools/dbc_check) runs on Node.js: Debian's nodejs and npm, unless a
# node and an npm are already on the PATH.
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  packages="$packages nodejs npm"
fi

missing=""
for package in $packages; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing="$missing $package"
  fi
done
if [ -n "$missing" ]; then
  echo "install_deps: installing$missing"
  if [ "$(id -u)" -eq 0 ]; then sudo=""; else sudo="sudo"; fi
  $sudo apt-get update -qq
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $missing
fi

# ...and on the npm packages its package-lock.json pins.
dbc_check="$(cd "$(dirname "$0")" && pwd)/dbc_check"
if [ ! -f "$dbc_check/node_modules/candied/package.json" ]; then
  echo "install_deps: npm ci in $dbc_check"
  npm ci --prefix "$dbc_check" --no-audit --no-fund
fi
