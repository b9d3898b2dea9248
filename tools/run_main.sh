#!/bin/sh
# Main job: builds the host preset and runs the seed-000 paper scenario (paper 000, Section V)
# on the simulated board. Prints the summary and writes, into build/seed000_paper/, the summary
# (summary.json), the per-tick CSV (run.csv) and the paper's Figures 1-5 (figures.png).
set -eu
cd "$(dirname "$0")/.."
tools/install_deps.sh --plot
cmake --preset host >/dev/null
cmake --build --preset host --target drive_sim
out=build/seed000_paper
mkdir -p "$out"
build/bin/drive_sim hal_sim/scenarios/seed000_paper.toml --csv "$out/run.csv" \
  --summary-json "$out/summary.json" --plot "$out/figures.png"
echo "run_main: summary, CSV and figures in $out/"
