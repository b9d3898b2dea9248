#!/usr/bin/python3
"""Wake-up latency of drive_hil's control loop beside cyclictest's, on this machine.

usage: latency_benchmark.py [--drive-hil PATH] [--scenario TOML] [--duration-s 60]
                            [--period-us 100] [--priority 80]

Runs drive_hil (without a CAN bus: the scenario's profile drives the motor) for the duration,
then cyclictest (rt-tests) for the same duration with the same period, SCHED_FIFO priority and
memory locking, one after the other so that they do not disturb each other, and prints a
Markdown table: p50, p99, p99.9 and max wake-up latency, and the wake-ups at least one period
late. Both histograms have 1 us bins. A benchmark, not a test: the figures depend on the
machine and on what else runs on it (docs/performance.md).
"""
import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import imd_version

ROOT = Path(__file__).resolve().parent.parent


def quantile_us(bins, overflow_max_us, q):
    """Upper edge of the 1 us bin holding the q-quantile (the convention of drive_hil's
    histogram): bins maps us -> count; samples beyond the histogram report their maximum."""
    total = sum(bins.values())
    rank = int(q * (total - 1)) + 1
    seen = 0
    for us in sorted(bins):
        seen += bins[us]
        if seen >= rank:
            return us + 1
    return overflow_max_us


def run_drive_hil(args, report):
    command = [str(args.drive_hil), str(args.scenario), "--can", "none",
               "--duration-s", str(args.duration_s), "--priority", str(args.priority),
               "--latency-report", str(report)]
    subprocess.run(command, check=True)
    r = json.loads(report.read_text())
    w = r["wakeup_latency"]
    return {"samples": w["samples"], "p50": w["p50_us"], "p99": w["p99_us"],
            "p99.9": w["p99_9_us"], "max": w["max_us"], "late": w["at_least_one_period"],
            "missed": r["missed_periods"], "period_us": r["period_us"]}


def run_cyclictest(args, histfile):
    command = ["cyclictest", "-t1", f"-p{args.priority}", f"-i{args.period_us}",
               f"-D{args.duration_s}", "-m", "-q", "-h", "10000", f"--histfile={histfile}"]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    bins, max_us, overflows = {}, 0, 0
    for line in histfile.read_text().splitlines():
        if line.startswith("# Max Latencies:"):
            max_us = int(line.split(":")[1])
        elif line.startswith("# Histogram Overflows:"):
            overflows = int(line.split(":")[1])
        elif line and not line.startswith("#"):
            us, count = line.split()[:2]
            if int(count):
                bins[int(us)] = int(count)
    if overflows:
        bins[10**9] = overflows  # beyond the histogram: only their maximum is known
    late = sum(count for us, count in bins.items() if us >= args.period_us)
    return {"samples": sum(bins.values()), "p50": quantile_us(bins, max_us, 0.5),
            "p99": quantile_us(bins, max_us, 0.99), "p99.9": quantile_us(bins, max_us, 0.999),
            "max": max_us, "late": late, "missed": None}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--drive-hil", type=Path, default=ROOT / "build/bin/drive_hil")
    parser.add_argument("--scenario", type=Path,
                        default=ROOT / "hal_sim/scenarios/seed000_realistic.toml")
    parser.add_argument("--duration-s", type=int, default=60)
    parser.add_argument("--period-us", type=int, default=100)
    parser.add_argument("--priority", type=int, default=80)
    imd_version.add_argument(parser)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        hil = run_drive_hil(args, Path(tmp) / "report.json")
        if hil["period_us"] != args.period_us:
            sys.exit(f"latency_benchmark: the scenario's period is {hil['period_us']} us, "
                     f"not {args.period_us} us")
        cyc = run_cyclictest(args, Path(tmp) / "cyclictest.hist")
    print(f"| {args.duration_s} s, {args.period_us} us period, SCHED_FIFO {args.priority} "
          f"| samples | p50 | p99 | p99.9 | max | wake-ups >= 1 period late | missed periods |")
    print("|---|---|---|---|---|---|---|---|")
    for name, r in (("drive_hil", hil), ("cyclictest", cyc)):
        missed = "-" if r["missed"] is None else str(r["missed"])
        print(f"| {name} | {r['samples']} | {r['p50']:.0f} us | {r['p99']:.0f} us "
              f"| {r['p99.9']:.0f} us | {r['max']:.0f} us | {r['late']} | {missed} |")


if __name__ == "__main__":
    main()
