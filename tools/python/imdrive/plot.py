"""The live plot: speed, flux, currents and state of one drive against time, from a bus
(animated with matplotlib) or a log; `save_png` draws it headless (Agg) for reports and tests."""
import collections

from . import table

# (axis title, y label, [(sample field, legend)]): the fields are the fast telemetry's signal
# names; one the table no longer has is left out of its axis rather than failing the plot.
PANELS = (
    ("speed", "rad/s", [("speed_rad_s", "speed"), ("speed_ref_rad_s", "reference")]),
    ("flux", "Wb^2", [("flux2_Wb2", "flux^2"), ("flux2_ref_Wb2", "reference")]),
    ("currents (rotor frame)", "A", [("iA_A", "i_A"), ("iB_A", "i_B")]),
)
STATE_FIELD = "state"


def state_names():
    s = table.find_signal(table.message("heartbeat"), STATE_FIELD)
    return dict(s.values) if s is not None else {}


class TelemetryPlot:
    """A figure of four axes (three panels and the state) over a window of samples."""

    def __init__(self, figure, window=None):
        from .telemetry import TelemetrySample
        fields = set(TelemetrySample.__dataclass_fields__)
        self.figure = figure
        self.samples = collections.deque(maxlen=window)
        axes = figure.subplots(len(PANELS) + 1, 1, sharex=True)
        self.lines = []  # (line, field)
        for ax, (title, unit, curves) in zip(axes, PANELS):
            ax.set_title(title, fontsize=9)
            ax.set_ylabel(unit)
            for field, label in curves:
                if field in fields:
                    (line,) = ax.plot([], [], label=label, linewidth=1)
                    self.lines.append((line, field))
            ax.legend(loc="upper right", fontsize=7)
            ax.grid(True, alpha=0.3)
        self.state_axis = axes[-1]
        names = state_names()
        self._codes = {name: code for code, name in names.items()}
        self.state_axis.set_title("state", fontsize=9)
        self.state_axis.set_yticks(sorted(names), [names[c] for c in sorted(names)], fontsize=7)
        (self.state_line,) = self.state_axis.step([], [], where="post", linewidth=1)
        self.state_axis.set_xlabel("time (s)")
        self.axes = list(axes)
        figure.tight_layout()

    def add(self, sample):
        self.samples.append(sample)

    def redraw(self):
        """Puts the samples held on the lines and rescales; returns the artists changed."""
        if not self.samples:
            return []
        t0 = self.samples[0].time_s
        t = [s.time_s - t0 for s in self.samples]
        for line, field in self.lines:
            line.set_data(t, [getattr(s, field) for s in self.samples])
        self.state_line.set_data(t, [self._codes.get(getattr(s, STATE_FIELD, None), -1)
                                     for s in self.samples])
        for ax in self.axes:
            ax.relim()
            ax.autoscale_view()
        return [line for line, _ in self.lines] + [self.state_line]


def save_png(samples, path, title=""):
    """Draws every sample into a PNG with the Agg backend (no display needed); returns the
    TelemetryPlot, whose figure and lines say what was drawn."""
    from matplotlib.figure import Figure
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    figure = Figure(figsize=(9, 8))
    FigureCanvasAgg(figure)
    plot = TelemetryPlot(figure)
    for s in samples:
        plot.add(s)
    plot.redraw()
    if title:
        figure.suptitle(title, fontsize=10)
        figure.tight_layout()
    figure.savefig(path, format="png", dpi=90)
    return plot


def animate(sample_source, window=2000, interval_ms=100, title=""):
    """Shows a live window; `sample_source()` returns the samples that arrived since the last
    call. Returns when the window is closed."""
    import matplotlib.pyplot as plt
    from matplotlib.animation import FuncAnimation

    figure = plt.figure(figsize=(9, 8))
    plot = TelemetryPlot(figure, window=window)
    if title:
        figure.suptitle(title, fontsize=10)

    def update(_frame):
        for s in sample_source():
            plot.add(s)
        return plot.redraw()

    animation = FuncAnimation(figure, update, interval=interval_ms, cache_frame_data=False)
    plt.show()
    return animation
