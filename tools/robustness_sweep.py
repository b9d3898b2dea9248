#!/usr/bin/python3
"""Robustness maps: what a mismatch between the motor and the controller's model costs each
control law, with and without the online rotor-resistance tracking (docs/robustness.md).

    robustness_sweep.py [--drive-sim FILE] [--out DIR] [--jobs N] [--quick]

The plant's parameters are the controller's times a ratio (the controller keeps the motor
record): two maps per law, the rotor and stator resistances (Rr 0.5..1.6 x Rs 0.7..1.3) and
the magnetizing inductance and inertia (Lm 0.8..1.1 x J 0.5..3; Ls and Lr move with Lm, the
leakages staying what they are, as when the iron saturates). Each law runs its realistic
scenario: the DSMC hal_sim/scenarios/seed000_realistic.toml (paper 000's motor), the IOL
seed001_realistic.toml and the IFOC seed001_ifoc.toml (paper 001's 37 kW motor, 12 s so that
its slow rotor's estimate settles; metrics from 8 s). drive_sim runs them N at a time (default:
every core) with a progress bar on standard error.

Writes DIR/robustness.csv (one row per run: law, tracking, map, the four plant/model ratios
Rr_ratio, Rs_ratio, Lm_ratio, J_ratio, speed_rms_err_rad_s, flux2_rel (the squared-flux RMS
error over its reference, a fraction), i_peak_A, rr_est_over_plant (the rotor resistance the
drive ended on over the plant's; without tracking the model's), faults) and
DIR/robustness_<law>.png: for each map, with
and without tracking, the speed RMS error, the squared-flux RMS error over its reference and
the peak current, each over the law's matched run (ratio 1 everywhere). A cell with a dot
stays within 2x the matched error on both speed and flux; a cell marked F ended in a fault.
Needs python3-numpy and python3-matplotlib.
"""
import argparse
import concurrent.futures
import csv
import json
import math
import os
import pathlib
import subprocess
import sys
import tempfile
import tomllib

import imd_version

ROOT = pathlib.Path(__file__).resolve().parent.parent
LAWS = {  # law: (scenario, duration_s, settle_s)
    "dsmc": ("hal_sim/scenarios/seed000_realistic.toml", 8.0, 0.5),
    "iol": ("hal_sim/scenarios/seed001_realistic.toml", 12.0, 8.0),
    "ifoc": ("hal_sim/scenarios/seed001_ifoc.toml", 12.0, 8.0),
}
MAPS = {  # map: ((parameter, ratios), (parameter, ratios)), x then y
    "Rr_Rs": (("Rr_Ohm", [0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6]),
              ("Rs_Ohm", [0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3])),
    "Lm_J": (("Lm_H", [0.8, 0.85, 0.9, 0.95, 1.0, 1.05, 1.1]),
             ("J_kgm2", [0.5, 0.75, 1.0, 1.5, 2.0, 3.0])),
}
QUICK = {  # --quick: corners and centre only (a smoke test of the tool)
    "Rr_Rs": (("Rr_Ohm", [0.5, 1.0, 1.6]), ("Rs_Ohm", [0.7, 1.0, 1.3])),
    "Lm_J": (("Lm_H", [0.8, 1.0, 1.1]), ("J_kgm2", [0.5, 1.0, 3.0])),
}
# The CSV's columns for the ratios (plant over model, dimensionless).
RATIO = {"Rr_Ohm": "Rr_ratio", "Rs_Ohm": "Rs_ratio", "Lm_H": "Lm_ratio", "J_kgm2": "J_ratio"}
WITHIN = 2.0  # "stays within 2x its matched error"
METRICS = [("speed_rms_err_rad_s", "speed RMS error"), ("flux2_rel", "squared-flux RMS error"),
           ("i_peak_A", "peak current")]


def motor_of(scenario):
    """The controller's motor: the scenario's motor_file (every shipped scenario has one)."""
    doc = tomllib.loads((ROOT / scenario).read_text())
    path = (ROOT / scenario).parent / doc["motor_file"]
    return tomllib.loads(path.read_text())["motor"]


def flux2_ref(scenario, law):
    doc = tomllib.loads((ROOT / scenario).read_text())
    key = "stator_flux2_Wb2" if law == "iol" else "flux2_Wb2"
    return doc["reference"]["flux"][key]


def run(job):
    """One drive_sim run; returns the job with its figures (NaN where it faulted)."""
    drive_sim, law, tracking, name, ratios, work = job
    scenario, duration_s, settle_s = LAWS[law]
    motor = motor_of(scenario)
    sets = [f"simulation.duration_s={duration_s}", f"metrics.settle_s={settle_s}",
            f"drive.rotor_resistance_tracking={'true' if tracking else 'false'}"]
    for key, ratio in ratios.items():
        sets.append(f"plant.{key}={motor[key] * ratio!r}")
        if key == "Lm_H":  # a magnetizing inductance off (saturation): the leakages stay
            for self_key in ("Ls_H", "Lr_H"):
                sets.append(f"plant.{self_key}={motor[self_key] + (ratio - 1) * motor['Lm_H']!r}")
    fd, summary = tempfile.mkstemp(suffix=".json", dir=work)
    os.close(fd)
    args = [drive_sim, str(ROOT / scenario), "--summary-json", summary]
    for s in sets:
        args += ["--set", s]
    done = subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    row = {"law": law, "tracking": tracking, "map": name}
    row.update({RATIO[key]: ratios.get(key, 1.0) for key in RATIO})
    try:
        d = json.loads(pathlib.Path(summary).read_text())
    except (OSError, json.JSONDecodeError):
        raise SystemExit(f"robustness_sweep: drive_sim failed on {args}:\n{done.stderr}")
    finally:
        pathlib.Path(summary).unlink(missing_ok=True)
    faults = [f["code"] for f in d["faults"]]
    nan = float("nan")

    def number(key):
        return nan if faults or d[key] is None else float(d[key])
    row["speed_rms_err_rad_s"] = number("speed_rms_err_rad_s")
    row["flux2_rel"] = number("flux2_rms_err_Wb2") / flux2_ref(scenario, law)
    row["i_peak_A"] = number("i_peak_A")
    est, plant = d.get("rr_estimate_final_Ohm"), d.get("plant_Rr_final_Ohm")
    row["rr_est_over_plant"] = est / plant if est and plant else nan
    row["faults"] = " ".join(faults)
    return row


def jobs_for(drive_sim, maps, work):
    jobs = []
    for law in LAWS:
        for tracking in (True, False):
            jobs.append((drive_sim, law, tracking, "matched", {}, work))
            for name, ((px, xs), (py, ys)) in maps.items():
                for x in xs:
                    for y in ys:
                        if x == 1.0 and y == 1.0:
                            continue  # the matched run
                        jobs.append((drive_sim, law, tracking, name, {px: x, py: y}, work))
    return jobs


def progress(done, total, width=40):
    filled = int(width * done / total)
    sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total} runs")
    sys.stderr.flush()


def plot(rows, maps, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    for law in LAWS:
        matched = {t: next(r for r in rows if r["law"] == law and r["tracking"] == t
                           and r["map"] == "matched") for t in (True, False)}
        columns = [(name, t) for name in maps for t in (True, False)]
        fig, axes = plt.subplots(len(METRICS), len(columns), figsize=(4.2 * len(columns), 10),
                                 squeeze=False)
        for col, (name, tracking) in enumerate(columns):
            (px, xs), (py, ys) = maps[name]
            base = matched[tracking]
            grid = {m: np.full((len(ys), len(xs)), np.nan) for m, _ in METRICS}
            good = np.zeros((len(ys), len(xs)), bool)
            faulted = np.zeros((len(ys), len(xs)), bool)
            for r in rows:
                if r["law"] != law or r["tracking"] != tracking:
                    continue
                if r["map"] == name:
                    i, j = ys.index(r[RATIO[py]]), xs.index(r[RATIO[px]])
                elif r["map"] == "matched":
                    i, j = ys.index(1.0), xs.index(1.0)
                else:
                    continue
                faulted[i, j] = bool(r["faults"])
                for m, _ in METRICS:
                    grid[m][i, j] = r[m] / base[m]
                good[i, j] = (not faulted[i, j] and grid["speed_rms_err_rad_s"][i, j] <= WITHIN
                              and grid["flux2_rel"][i, j] <= WITHIN)
            for row_index, (m, label) in enumerate(METRICS):
                ax = axes[row_index][col]
                image = ax.imshow(np.log2(grid[m]), origin="lower", cmap="RdYlGn_r", vmin=-1,
                                  vmax=4, aspect="auto")
                ax.set_xticks(range(len(xs)), [f"{x:g}" for x in xs], fontsize=7)
                ax.set_yticks(range(len(ys)), [f"{y:g}" for y in ys], fontsize=7)
                ax.set_xlabel(f"plant/model {px}", fontsize=8)
                ax.set_ylabel(f"plant/model {py}", fontsize=8)
                ax.set_title(f"{label}\n{name}, tracking {'on' if tracking else 'off'}",
                             fontsize=9)
                for i in range(len(ys)):
                    for j in range(len(xs)):
                        if faulted[i, j]:
                            ax.text(j, i, "F", ha="center", va="center", fontsize=8)
                        elif good[i, j]:
                            ax.plot(j, i, "k.", markersize=4)
                fig.colorbar(image, ax=ax, label="log2(x matched)", shrink=0.8)
        fig.suptitle(f"{law}: errors over the matched run (dot: speed and flux within "
                     f"{WITHIN:g}x matched; F: fault)")
        fig.tight_layout()
        fig.savefig(out / f"robustness_{law}.png", dpi=80)
        plt.close(fig)


def main():
    p = argparse.ArgumentParser(
        description="Robustness maps: each law's errors against plant/model parameter ratios, "
        "with and without rotor-resistance tracking (docs/robustness.md).",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    p.add_argument("--drive-sim", default=str(ROOT / "build/bin/drive_sim"),
                   help="the drive_sim binary")
    p.add_argument("--out", default=None,
                   help="where the CSV and PNGs go (default: docs/img, or with --quick "
                   "/tmp/robustness_quick, so that a smoke test leaves the committed maps alone)")
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="runs at a time")
    p.add_argument("--quick", action="store_true",
                   help="3 x 3 ratios per map (the corners, the edges' middles and the centre): "
                   "a smoke test")
    imd_version.add_argument(p)
    a = p.parse_args()
    if a.out is None:
        a.out = "/tmp/robustness_quick" if a.quick else str(ROOT / "docs/img")
    if not pathlib.Path(a.drive_sim).exists():
        raise SystemExit(f"robustness_sweep: no drive_sim at {a.drive_sim}: build it first "
                         "(cmake --build --preset host)")
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    maps = QUICK if a.quick else MAPS
    with tempfile.TemporaryDirectory() as work:
        jobs = jobs_for(a.drive_sim, maps, work)
        rows = []
        progress(0, len(jobs))
        with concurrent.futures.ProcessPoolExecutor(max_workers=a.jobs) as pool:
            for row in pool.map(run, jobs):
                rows.append(row)
                progress(len(rows), len(jobs))
        sys.stderr.write("\n")
    with open(out / "robustness.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    plot(rows, maps, out)
    for law in LAWS:
        for tracking in (True, False):
            mine = [r for r in rows if r["law"] == law and r["tracking"] == tracking]
            base = next(r for r in mine if r["map"] == "matched")
            good = [r for r in mine if not r["faults"]
                    and r["speed_rms_err_rad_s"] <= WITHIN * base["speed_rms_err_rad_s"]
                    and r["flux2_rel"] <= WITHIN * base["flux2_rel"]]
            faults = sum(1 for r in mine if r["faults"])
            print(f"{law:5s} tracking {'on ' if tracking else 'off'}: {len(good)}/{len(mine)} "
                  f"cells within {WITHIN:g}x matched, {faults} faulted; matched speed "
                  f"{base['speed_rms_err_rad_s']:.4g} rad/s, flux2 {100 * base['flux2_rel']:.3g} %")
    print(f"wrote {out / 'robustness.csv'} and {out}/robustness_<law>.png")
    return 0 if all(math.isfinite(r["i_peak_A"]) or r["faults"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
