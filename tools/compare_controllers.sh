#!/bin/sh
# The three control laws side by side (tools/compare_controllers.py): builds drive_sim (host
# preset) and the processor-in-the-loop image (cortex-m4f preset), runs every case with DSMC,
# IOL and IFOC on the simulated board and each law on the emulated Cortex-M4F, and rewrites the
# comparison section of docs/results.md and docs/img/compare_controllers.png. About two minutes,
# most of it the three QEMU runs. Pass --no-pil to leave out the MCU (no instruction counts).
set -eu
cd "$(dirname "$0")/.."
pil=yes
case "${1:-}" in
  --no-pil) pil=no ;;
  '') ;;
  *) echo "compare_controllers: unknown option $1 (known: --no-pil)" >&2; exit 2 ;;
esac
if [ "$pil" = yes ]; then tools/install_deps.sh --plot --cortex-m --qemu; else tools/install_deps.sh --plot; fi
cmake --preset host >/dev/null
cmake --build --preset host --target drive_sim
set -- --drive-sim build/bin/drive_sim --work build/compare_controllers
if [ "$pil" = yes ]; then
  cmake --preset cortex-m4f >/dev/null
  cmake --build --preset cortex-m4f --target drive_pil_mps2_an386
  set -- "$@" --pil-elf build-cortex-m4f/bin/drive_pil_mps2_an386.elf
fi
/usr/bin/python3 tools/compare_controllers.py "$@"
