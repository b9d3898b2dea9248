#!/usr/bin/env python3
"""Runs every scenario of hal_sim/scenarios/ in double and in float and compares the summaries
with those of another build (a refactoring must leave the behaviour unchanged).

    compare_summaries.py run DRIVE_SIM OUT_DIR [--scenarios DIR]
    compare_summaries.py compare BEFORE_DIR AFTER_DIR [--markdown]

`run` writes OUT_DIR/<scenario>.<precision>.json with drive_sim's --summary-json (the
seed000_hil scenario is left out: it is the real-time run's configuration and takes its speed
from CAN). `compare` prints, for every metric, the value before and after and the relative
difference |after - before| / max(|before|, 1e-300); wall-clock figures are not compared.
Exit status: 0 when every double metric is within 1e-9 relative and the fault events are the
same, 1 otherwise (float runs are reported, not judged: a last-bit difference changes which
side of a quantization step a float sample falls).
"""
import argparse
import json
import math
import pathlib
import subprocess
import sys

import imd_version

SKIP = {"seed000_hil"}  # the real-time scenario: CAN-commanded, no profile to run here
NOT_COMPARED = {"wall_time_s", "tick_exec_ns_mean", "tick_exec_ns_max", "realtime_factor",
                "stage_ns", "scenario", "source", "controller", "motor", "plant",
                "simulated_s_per_wall_s"}
DOUBLE_TOLERANCE = 1e-9


def run(args):
    out = pathlib.Path(args.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    scenarios = sorted(pathlib.Path(args.scenarios).glob("*.toml"))
    for path in scenarios:
        if path.stem in SKIP:
            continue
        for precision in ("double", "float"):
            target = out / f"{path.stem}.{precision}.json"
            cmd = [args.drive_sim, str(path), "--summary-json", str(target),
                   "--set", f"drive.precision={precision}"]
            result = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                    text=True)
            if result.returncode != 0:
                sys.exit(f"compare_summaries: {' '.join(cmd)} failed:\n{result.stderr}")
            print(f"compare_summaries: {target.name}", flush=True)


def numbers(summary, prefix=""):
    """The summary's numeric leaves, by dotted name (fault events compared separately)."""
    for key, value in summary.items():
        name = prefix + key
        if key in NOT_COMPARED or key == "faults":
            continue
        if isinstance(value, dict):
            yield from numbers(value, name + ".")
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            yield name, float(value)
        elif value is None:
            yield name, math.nan


def relative(before, after):
    if math.isnan(before) and math.isnan(after):
        return 0.0
    if math.isnan(before) or math.isnan(after):
        return math.inf
    return abs(after - before) / max(abs(before), 1e-300)


def compare(args):
    before_dir, after_dir = pathlib.Path(args.before), pathlib.Path(args.after)
    ok = True
    rows = []
    for before_path in sorted(before_dir.glob("*.json")):
        after_path = after_dir / before_path.name
        stem, precision = before_path.stem.rsplit(".", 1)
        if not after_path.exists():
            print(f"missing: {after_path}")
            ok = False
            continue
        before = json.loads(before_path.read_text())
        after = json.loads(after_path.read_text())
        after_numbers = dict(numbers(after))
        worst = 0.0
        for name, value in numbers(before):
            if name not in after_numbers:
                print(f"{stem} {precision}: {name} missing after")
                ok = False
                continue
            d = relative(value, after_numbers[name])
            worst = max(worst, d)
            rows.append((stem, precision, name, value, after_numbers[name], d))
        faults_same = [(f.get("code"), f.get("detected_at_s")) for f in before.get("faults", [])] == \
                      [(f.get("code"), f.get("detected_at_s")) for f in after.get("faults", [])]
        verdict = "same" if worst == 0 else f"max rel diff {worst:.2e}"
        if precision == "double" and (worst > DOUBLE_TOLERANCE or not faults_same):
            ok = False
            verdict += "  <-- exceeds 1e-9" if worst > DOUBLE_TOLERANCE else ""
        if not faults_same:
            verdict += "  <-- fault events differ"
        print(f"{stem:22s} {precision:6s} {verdict}")
    if args.markdown:
        print("\n| scenario | precision | metric | before | after | rel. diff |")
        print("|---|---|---|---|---|---|")
        for stem, precision, name, b, a, d in rows:
            print(f"| {stem} | {precision} | {name} | {b:.9g} | {a:.9g} | {d:.1e} |")
    print("compare_summaries: " + ("unchanged" if ok else "CHANGED"))
    return 0 if ok else 1


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run")
    r.add_argument("drive_sim")
    r.add_argument("out_dir")
    r.add_argument("--scenarios", default=str(pathlib.Path(__file__).resolve().parent.parent /
                                              "hal_sim" / "scenarios"))
    c = sub.add_parser("compare")
    c.add_argument("before")
    c.add_argument("after")
    c.add_argument("--markdown", action="store_true")
    imd_version.add_argument(parser)
    args = parser.parse_args()
    if args.command == "run":
        run(args)
        return 0
    return compare(args)


if __name__ == "__main__":
    sys.exit(main())
