#!/bin/sh
# Test job: builds the host preset (Release with assertions) and runs every test tier.
set -eu
cd "$(dirname "$0")/.."
tools/install_deps.sh
cmake --preset host
cmake --build --preset host
ctest --preset host --parallel 2
