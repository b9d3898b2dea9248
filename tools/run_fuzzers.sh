#!/bin/sh
# run_fuzzers.sh [SECONDS]: builds the libFuzzer harnesses (fuzz preset, clang, ASan + UBSan)
# and runs each for SECONDS (default 60) on its corpus under build-fuzz/corpus/, seeded from
# the shipped CAN logs, motor files and scenarios. Prints per harness the executions, the crashes found and the corpus size;
# exits non-zero if any harness crashed (the reproducer is under build-fuzz/artifacts/).
set -eu
duration_s=${1:-60}
case "$duration_s" in
  '' | *[!0-9]*) echo "run_fuzzers: SECONDS must be a whole number, got $duration_s" >&2; exit 2 ;;
esac
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

# clang and its libFuzzer/sanitizer runtimes with the rest, installed if missing.
"$root/tools/install_deps.sh" --fuzz

cmake --preset fuzz >/dev/null
cmake --build --preset fuzz

build="$root/build-fuzz"
status=0
summary=""
for harness in fuzz_command_decoder fuzz_candump_parser fuzz_motor_record fuzz_motor_file \
    fuzz_scenario; do
  corpus="$build/corpus/$harness"
  artifacts="$build/artifacts/$harness"
  log="$build/$harness.log"
  mkdir -p "$corpus" "$artifacts"
  seeds=""
  case "$harness" in
    fuzz_candump_parser) seeds="$root/tests/data/can" ;;
    fuzz_motor_file) seeds="$root/tests/data/motors $root/hal_sim/motors" ;;
    fuzz_scenario) seeds="$root/hal_sim/scenarios $root/tests/data/scenarios" ;;
  esac
  before=$(find "$artifacts" -type f | wc -l)
  echo "run_fuzzers: $harness for ${duration_s} s (log: $log)"
  set +e
  "$build/bin/$harness" -max_total_time="$duration_s" -print_final_stats=1 -timeout=10 \
    -artifact_prefix="$artifacts/" "$corpus" $seeds >"$log" 2>&1
  code=$?
  set -e
  executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  crashes=$(($(find "$artifacts" -type f | wc -l) - before))
  if [ "$code" -ne 0 ] && [ "$crashes" -eq 0 ]; then crashes=1; fi
  corpus_size=$(find "$corpus" -type f | wc -l)
  line=$(printf '%-22s executions %-10s crashes %-3s corpus %s files' "$harness" \
    "${executions:-?}" "$crashes" "$corpus_size")
  summary="$summary$line
"
  if [ "$crashes" -ne 0 ]; then
    status=1
    echo "run_fuzzers: $harness crashed (exit $code); see $log and $artifacts" >&2
    tail -n 30 "$log" >&2
  fi
done
printf '\n%s' "$summary"
exit $status
