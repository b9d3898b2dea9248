"""Shades the drive's states on the time axes of a drive_sim plot, so that a transient reads
against what the drive was doing: magnetizing, stopping, a latched fault (with its stop
category), identifying. Running, the state the figures are about, is left clear.

The CSV's `state` column is the heartbeat's (docs/scenarios.md), `stop` the latched fault's
stop category.
"""
import matplotlib.patches as mpatches
import numpy as np

# firmware/drive_state.hpp's numbers (the CAN protocol's).
STATE_NAMES = ("calibrating", "idle", "magnetizing", "running", "stopping", "fault",
               "unconfigured", "identifying")
RUNNING, FAULT = 3, 5
STOP_NAMES = ("none", "sto", "ss1", "dc_brake")
COLOURS = {0: "0.6", 1: "0.85", 2: "gold", 4: "tab:blue", 5: "tab:red", 6: "0.6",
           7: "tab:purple"}
ALPHA = 0.15


def spans(d):
    """(start_s, end_s, state, stop) for each run of one state other than running."""
    t, state = d["t_s"], d["state"].astype(int)
    stop = d["stop"].astype(int) if "stop" in d.dtype.names else np.zeros_like(state)
    starts = np.concatenate(([0], np.flatnonzero(np.diff(state)) + 1))
    ends = np.append(starts[1:], len(t) - 1)  # a run lasts until the next one starts
    return [(t[b], t[e], int(state[b]), int(stop[b]))
            for b, e in zip(starts, ends) if state[b] != RUNNING]


def label(state, stop):
    name = STATE_NAMES[state] if 0 <= state < len(STATE_NAMES) else f"state {state}"
    if state == FAULT and 0 < stop < len(STOP_NAMES):
        return f"{name} ({STOP_NAMES[stop]})"
    return name


def shade(ax, runs):
    """Shades the runs on a time axis without widening its limits."""
    limits = ax.get_xlim()
    for start, end, state, _ in runs:
        ax.axvspan(start, end, color=COLOURS.get(state, "0.5"), alpha=ALPHA, lw=0, zorder=0)
    ax.set_xlim(limits)


def legend(fig, runs):
    """One legend for the figure: the states that occur."""
    seen = {}
    for _, _, state, stop in runs:
        seen.setdefault(label(state, stop), COLOURS.get(state, "0.5"))
    if seen:
        handles = [mpatches.Patch(color=colour, alpha=3 * ALPHA, label=name)
                   for name, colour in seen.items()]
        fig.legend(handles=handles, loc="upper right", ncol=len(handles), fontsize="small",
                   title="drive state (shaded)", title_fontsize="small")
