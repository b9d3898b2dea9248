#!/bin/sh
# Builds the host preset and runs the benchmarks whose figures docs/performance.md reports.
# A benchmark that measured nothing (a drive not running, a plant that did not move) makes its
# program exit with status 1, which stops this script (tools/bench/bench_main.hpp). Arguments
# go to every program, e.g. --benchmark_filter='DriveSim|Integrator'; the before/after ratios
# are printed at the end of each program's output.
set -eu
cd "$(dirname "$0")/.."
tools/install_deps.sh
cmake --preset host >/dev/null
cmake --build --preset host --target bench_plant bench_drive bench_control
for bench in bench_plant bench_drive bench_control; do
  build/bin/$bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
    --benchmark_min_time=0.2 "$@"
done
