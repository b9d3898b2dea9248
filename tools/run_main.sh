#!/bin/sh
# Main job: builds the host preset and prints the exact discretization of the paper-000 motor
# (both papers' models) as JSON.
set -eu
cd "$(dirname "$0")/.."
tools/install_deps.sh
cmake --preset host >/dev/null
cmake --build --preset host --target drive_model
build/bin/drive_model discretize --motor hal_sim/motors/seed000.toml
