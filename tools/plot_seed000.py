#!/usr/bin/python3
"""Regenerates Figures 1-5 of paper 000 (Section V) from a drive_sim CSV.

    plot_seed000.py RUN.csv --out FIGURES.png [--separate DIR] [--settle-s S] [--title TEXT]

FIGURES.png (or .pdf, .svg) holds all five figures as panels; --separate also writes fig1.png
.. fig5.png. The drive's states other than running are shaded (plot_states.py). --title names
the run (drive_sim gives the scenario); the CSV's file name by default. Needs Debian's
python3-matplotlib and python3-numpy.
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


def load(path):
    data = np.genfromtxt(path, delimiter=",", names=True)
    if data.size == 0:
        sys.exit(f"plot_seed000: {path}: no rows")
    return data


RUNNING = plot_states.RUNNING


def running_start(d):
    running = np.nonzero(d["state"] == RUNNING)[0]
    return d["t_s"][running[0]] if running.size else d["t_s"][0]


def fig1(axes, d):
    a, b = axes
    a.plot(d["t_s"], d["omega_ref_rad_s"], "k--", lw=1, label="reference")
    a.plot(d["t_s"], d["omega_mech_rad_s"], lw=1, label="motor")
    a.set(title="Fig. 1(a) rotor speed tracking", xlabel="t [s]", ylabel="speed [rad/s]")
    a.legend(loc="upper right")
    b.plot(d["t_s"], d["flux2_ref_Wb2"], "k--", lw=1, label="reference")
    b.plot(d["t_s"], d["flux2_Wb2"], lw=1, label="motor")
    b.set(title="Fig. 1(b) squared rotor-flux modulus", xlabel="t [s]", ylabel="|Phi|^2 [Wb^2]")
    b.set_ylim(0.0, 1.5 * np.max(d["flux2_ref_Wb2"]))  # autoscale would magnify rounding
    b.legend(loc="lower right")


def fig2(axes, d):
    start = running_start(d)
    window = (d["t_s"] >= start - 0.005) & (d["t_s"] <= start + 0.05)
    a, b = axes
    a.plot(d["t_s"][window], d["omega_ref_rad_s"][window], "k--", lw=1, label="reference")
    a.plot(d["t_s"][window], d["omega_mech_rad_s"][window], ".-", ms=2, lw=1, label="motor")
    a.set(title="Fig. 2(a) speed transient", xlabel="t [s]", ylabel="speed [rad/s]")
    a.legend(loc="best")
    b.plot(d["t_s"][window], d["flux2_ref_Wb2"][window], "k--", lw=1, label="reference")
    b.plot(d["t_s"][window], d["flux2_Wb2"][window], ".-", ms=2, lw=1, label="motor")
    b.set(title="Fig. 2(b) flux transient", xlabel="t [s]", ylabel="|Phi|^2 [Wb^2]")
    b.set_ylim(0.0, 1.5 * np.max(d["flux2_ref_Wb2"]))
    b.legend(loc="best")


def fig3(ax, d):
    ax.plot(d["t_s"], d["load_Nm"], "k--", lw=1, label="load torque")
    ax.plot(d["t_s"], d["load_est_Nm"], lw=1, label="estimate")
    ax.set(title="Fig. 3 load estimate", xlabel="t [s]", ylabel="torque [N m]")
    ax.legend(loc="upper right")


def fig4(ax, d):
    window = d["t_s"] <= max(0.5, running_start(d) + 0.3)
    t = d["t_s"][window]
    ax.plot(t, d["flux_A_Wb"][window], "k--", lw=1, label="Phi_A")
    ax.plot(t, d["flux_A_est_Wb"][window], lw=1, label="Phi_A estimate")
    ax.plot(t, d["flux_B_Wb"][window], "k:", lw=1, label="Phi_B")
    ax.plot(t, d["flux_B_est_Wb"][window], lw=1, label="Phi_B estimate")
    ax.set(title="Fig. 4 rotor-flux estimates (rotor frame)", xlabel="t [s]", ylabel="flux [Wb]")
    ax.legend(loc="right")


def fig5(axes, d):
    start = running_start(d)
    window = (d["t_s"] >= start) & (d["t_s"] <= start + 0.02)
    a, b = axes
    a.plot(d["t_s"][window], d["discriminant"][window], ".-", ms=2, lw=1)
    a.set(title="Fig. 5(a) discriminant b_k^2 - 4 a_k c_k", xlabel="t [s]")
    b.plot(d["t_s"][window], d["c_k"][window], ".-", ms=2, lw=1)
    b.set(title="Fig. 5(b) c_k", xlabel="t [s]")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv")
    parser.add_argument("--out", required=True, help="PNG (or PDF, SVG) with all five figures")
    parser.add_argument("--separate", help="directory for fig1.png .. fig5.png")
    parser.add_argument("--settle-s", type=float, default=0.0, help="marked on the time axes")
    parser.add_argument("--title", help="the run's name (default: the CSV's file name)")
    imd_version.add_argument(parser)
    args = parser.parse_args()
    d = load(args.csv)
    runs = plot_states.spans(d)

    fig, grid = plt.subplots(4, 2, figsize=(14, 16))
    fig1(grid[0], d)
    fig2(grid[1], d)
    fig3(grid[2][0], d)
    fig4(grid[2][1], d)
    fig5(grid[3], d)
    for ax in grid.flat:
        ax.grid(True, alpha=0.3)
        plot_states.shade(ax, runs)
    fig.suptitle(args.title or os.path.basename(args.csv))
    plot_states.legend(fig, runs)
    fig.tight_layout(rect=(0, 0, 1, 0.97))  # room for the title and the states' legend
    fig.savefig(args.out, dpi=90)

    if args.separate:
        os.makedirs(args.separate, exist_ok=True)
        for number, draw, shape in ((1, fig1, 2), (2, fig2, 2), (3, fig3, 1), (4, fig4, 1), (5, fig5, 2)):
            single, axes = plt.subplots(1, shape, figsize=(7 * shape, 4))
            draw(axes, d)
            for ax in np.atleast_1d(axes):
                ax.grid(True, alpha=0.3)
                plot_states.shade(ax, runs)
            single.suptitle(args.title or os.path.basename(args.csv))
            single.tight_layout()
            single.savefig(os.path.join(args.separate, f"fig{number}.png"), dpi=90)
            plt.close(single)


if __name__ == "__main__":
    main()
