#!/usr/bin/python3
"""Regenerates Figures 3 and 4 of paper 001 (Section 5) from a drive_sim CSV of an iol run.

    plot_seed001.py RUN.csv --out FIGURES.png [--settle-s S] [--title TEXT]

Panels: torque and its reference v1, the second output y2 and its reference v2, the squared
stator flux and its target, and the speed. Values are taken at the T0 boundaries, where the
law acts (held in between, as the paper shows them). The drive's states other than running are
shaded (plot_states.py). --title names the run (drive_sim gives the scenario); the CSV's file
name by default. Needs Debian's python3-matplotlib.
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import imd_version  # noqa: E402
import plot_states  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv")
    parser.add_argument("--out", required=True)
    parser.add_argument("--settle-s", type=float, default=0.0)
    parser.add_argument("--title", help="the run's name (default: the CSV's file name)")
    imd_version.add_argument(parser)
    args = parser.parse_args()
    d = np.genfromtxt(args.csv, delimiter=",", names=True)
    boundary = np.nonzero(d["iol_boundary"] > 0)[0]
    if boundary.size < 2:
        sys.exit(f"plot_seed001: {args.csv}: no T0 boundary (not an iol run?)")
    b = d[boundary]
    t = b["t_s"]

    fig, grid = plt.subplots(2, 2, figsize=(14, 9))
    ax = grid[0][0]
    ax.step(t, b["torque_Nm"], where="post", lw=1, label="torque")
    ax.step(t[1:], b["torque_ref_Nm"][:-1], "k--", where="post", lw=1, label="v1, one T0 earlier")
    ax.set(title="torque and v1", xlabel="t [s]", ylabel="torque [N m]")
    ax.legend(loc="best")
    ax = grid[0][1]
    ax.step(t, b["y2"], where="post", lw=1, label="y2")
    ax.step(t[1:], b["y2_ref"][:-1], "k--", where="post", lw=1, label="v2, one T0 earlier")
    ax.set(title="second output y2 and v2", xlabel="t [s]", ylabel="y2 [Wb^2]")
    ax.legend(loc="best")
    ax = grid[1][0]
    ax.plot(d["t_s"], d["stator_flux2_Wb2"], lw=1, label="|phi_s|^2")
    ax.plot(d["t_s"], d["stator_flux2_ref_Wb2"], "k--", lw=1, label="target")
    ax.set(title="squared stator flux", xlabel="t [s]", ylabel="[Wb^2]")
    ax.set_ylim(0.0, 1.5 * np.max(d["stator_flux2_ref_Wb2"]))
    ax.legend(loc="lower right")
    ax = grid[1][1]
    ax.plot(d["t_s"], d["omega_mech_rad_s"], lw=1, label="speed")
    if np.any(d["omega_ref_rad_s"] != 0):
        ax.plot(d["t_s"], d["omega_ref_rad_s"], "k--", lw=1, label="reference")
    ax2 = ax.twinx()
    ax2.plot(d["t_s"], d["load_Nm"], "r:", lw=1, label="load")
    ax2.set_ylabel("load [N m]")
    ax.set(title="speed and load", xlabel="t [s]", ylabel="speed [rad/s]")
    ax.legend(loc="upper left")
    runs = plot_states.spans(d)
    for a in grid.flat:
        a.grid(True, alpha=0.3)
        plot_states.shade(a, runs)
    fig.suptitle(args.title or os.path.basename(args.csv))
    plot_states.legend(fig, runs)
    fig.tight_layout(rect=(0, 0, 1, 0.96))  # room for the title and the states' legend
    fig.savefig(args.out, dpi=90)


if __name__ == "__main__":
    main()
