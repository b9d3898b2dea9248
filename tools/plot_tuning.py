#!/usr/bin/python3
"""Gain sweeps for docs/tuning.md: runs drive_sim on the realistic paper-000 scenario with one
setting at three values, and plots speed, speed error and squared rotor flux against time.

    plot_tuning.py [--drive-sim PATH] [--out DIR] [--work DIR] [--duration-s S]

Writes DIR/tuning_ifoc_speed_bandwidth.png, DIR/tuning_dsmc_speed_bandwidth.png and
DIR/tuning_encoder_bandwidth.png (default DIR: docs/img), and prints each run's summary
metrics as a Markdown table. The runs go one at a time; each CSV is kept in --work (default: a
temporary directory, removed at the end). Needs Debian's python3-matplotlib and python3-numpy.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import imd_version  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENARIO = "hal_sim/scenarios/seed000_realistic.toml"

# One figure per sweep: the key, its three values (the middle one is the default rule's value
# on this board), the settings every run of the sweep shares, and the time window plotted.
# The realistic scenario's load steps from 0 to 1 N m at 1.5 s and back at 2.0 s, while the
# speed reference (a 100 rad/s, 0.25 Hz sine) passes 71 rad/s on its way down.
SWEEPS = [
    {
        "name": "tuning_ifoc_speed_bandwidth",
        "title": "IFOC: drive.ifoc_speed_bandwidth_rad_s",
        "key": "drive.ifoc_speed_bandwidth_rad_s",
        "unit": "rad/s",
        "values": [30, 100, 300],
        "common": ["drive.controller=ifoc"],
    },
    {
        "name": "tuning_dsmc_speed_bandwidth",
        "title": "DSMC (torque channel): drive.dsmc_speed_bandwidth_rad_s",
        "key": "drive.dsmc_speed_bandwidth_rad_s",
        "unit": "rad/s",
        "values": [30, 100, 300],
        "common": [],
    },
    {
        "name": "tuning_encoder_bandwidth",
        "title": "DSMC, speed loop 100 rad/s: observers.encoder_bandwidth_rad_s",
        "key": "observers.encoder_bandwidth_rad_s",
        "unit": "rad/s",
        "values": [100, 400, 1600],
        "common": ["drive.dsmc_speed_bandwidth_rad_s=100"],
    },
]
WINDOW_S = (1.45, 1.75)
METRICS = ["speed_rms_err_rad_s", "speed_max_err_rad_s", "flux2_rms_err_Wb2",
           "current_ripple_control_rms_A", "voltage_ripple_rms_V", "limited_total_s"]


def run(drive_sim, settings, csv, summary, duration_s):
    args = [drive_sim, SCENARIO, "--duration-s", str(duration_s), "--csv", csv,
            "--summary-json", summary]
    for s in settings:
        args += ["--set", s]
    done = subprocess.run(args, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                          text=True)
    if done.returncode != 0:
        sys.exit(f"plot_tuning: {' '.join(args)}: exit {done.returncode}: {done.stderr.strip()}")
    with open(summary) as f:
        return json.load(f)


def load(path):
    d = np.genfromtxt(path, delimiter=",", names=True,
                      usecols=("t_s", "omega_mech_rad_s", "omega_ref_rad_s", "flux2_Wb2",
                               "flux2_ref_Wb2", "load_Nm"))
    w = (d["t_s"] >= WINDOW_S[0]) & (d["t_s"] <= WINDOW_S[1])
    return d[w]


def plot(sweep, runs, out_dir):
    fig, (a, b, c) = plt.subplots(3, 1, figsize=(6.4, 6.2), sharex=True)
    colours = ["tab:blue", "tab:orange", "tab:green"]
    first = runs[0][1]
    a.plot(first["t_s"], first["omega_ref_rad_s"], "k--", lw=1, label="reference")
    c.plot(first["t_s"], first["flux2_ref_Wb2"], "k--", lw=1, label="reference")
    for (value, d), colour in zip(runs, colours):
        label = f"{value} {sweep['unit']}"
        a.plot(d["t_s"], d["omega_mech_rad_s"], lw=1, color=colour, label=label)
        b.plot(d["t_s"], d["omega_mech_rad_s"] - d["omega_ref_rad_s"], lw=0.8, color=colour,
               label=label)
        c.plot(d["t_s"], d["flux2_Wb2"], lw=0.8, color=colour, label=label)
    for ax in (a, b, c):
        for step in (1.5,):
            ax.axvline(step, color="0.6", lw=0.6, ls=":")
        ax.grid(True, lw=0.3)
    a.set(ylabel="speed [rad/s]", title=sweep["title"])
    b.set(ylabel="speed error [rad/s]")
    c.set(ylabel="|Phi_r|^2 [Wb^2]", xlabel="t [s] (load 0 -> 1 N m at 1.5 s)")
    a.legend(loc="upper right", fontsize=8)
    b.legend(loc="lower left", fontsize=8)
    fig.tight_layout()
    path = os.path.join(out_dir, sweep["name"] + ".png")
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--drive-sim", default=os.path.join(ROOT, "build", "bin", "drive_sim"))
    p.add_argument("--out", default=os.path.join(ROOT, "docs", "img"))
    p.add_argument("--work", help="keep the CSV and summaries here")
    p.add_argument("--duration-s", type=float, default=3.0)
    imd_version.add_argument(p)
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    work = a.work or tempfile.mkdtemp(prefix="plot_tuning_")
    os.makedirs(work, exist_ok=True)
    print("| setting | value | " + " | ".join(METRICS) + " |")
    print("|---|---|" + "---|" * len(METRICS))
    for sweep in SWEEPS:
        runs = []
        for value in sweep["values"]:
            stem = os.path.join(work, f"{sweep['name']}_{value}")
            settings = sweep["common"] + [f"{sweep['key']}={value}"]
            summary = run(a.drive_sim, settings, stem + ".csv", stem + ".json", a.duration_s)
            runs.append((value, load(stem + ".csv")))
            if summary.get("faults"):
                print(f"plot_tuning: {sweep['key']}={value}: faults {summary['faults']}",
                      file=sys.stderr)
            cells = []
            for m in METRICS:
                v = summary.get(m)
                cells.append("null" if v is None else f"{v:.4g}")
            print(f"| `{sweep['key']}` | {value} | " + " | ".join(cells) + " |")
            if not a.work:
                os.remove(stem + ".csv")
                os.remove(stem + ".json")
        path = plot(sweep, runs, a.out)
        print(f"plot_tuning: wrote {path} ({os.path.getsize(path) // 1024} KiB)", file=sys.stderr)
    if not a.work:
        os.rmdir(work)


if __name__ == "__main__":
    main()
