"""Fast-telemetry samples: the frames the drive sends together each telemetry period, assembled
into one typed sample.

The fast-telemetry messages are the table's `configurable` ones, sent in table order within one
tick; the last of them completes a sample (docs/can/protocol.md). TelemetrySample has `time_s`
(the completing frame's timestamp), every signal of those messages under its own name (with its
unit: speed_rad_s, iA_A, v_bus_V, ...), and the drive's `state` and `first_fault` from the
latest heartbeat (None before the first one, or if the heartbeat stops carrying them).
"""
import dataclasses

from . import frames, table

FAST_MESSAGES = tuple(m for m in table.MESSAGES if m.timing == "configurable")
# From the heartbeat, by name: the typed API's fallback is None when a table lacks one.
HEARTBEAT_FIELDS = ("state", "first_fault")


def _sample_fields():
    fields = [("time_s", float)]
    seen = {"time_s"}
    for m in FAST_MESSAGES:
        for s in m.signals:
            name = frames.field_name(s.name)
            if name in seen:
                raise ValueError(f"protocol table: fast telemetry signal {s.name} of {m.name} "
                                 f"appears twice in a sample")
            seen.add(name)
            fields.append((name, frames._field_type(s)))
    for name in HEARTBEAT_FIELDS:
        if name not in seen:
            fields.append((name, object))
    return fields


TelemetrySample = dataclasses.make_dataclass(
    "TelemetrySample", _sample_fields(), frozen=True,
    namespace={"__module__": __name__, "__doc__": "One fast-telemetry sample: " +
               ", ".join(m.name for m in FAST_MESSAGES) + ", and the latest heartbeat's " +
               " and ".join(HEARTBEAT_FIELDS) + "."})


class TelemetryAssembler:
    """Takes decoded frames; returns a TelemetrySample when the last frame of one arrives.

    A completing frame before every other part of a sample was ever seen is counted in
    `incomplete`; one whose other parts are from an earlier sample (a frame was lost) still
    gives a sample, counted in `stale`, as drive_monitor does."""

    def __init__(self):
        self._parts = {}
        self._fresh = set()
        self._heartbeat = None
        self.samples = 0
        self.incomplete = 0
        self.stale = 0

    def feed(self, frame):
        name = frame.MESSAGE.name
        if name == "heartbeat":
            self._heartbeat = frame
            return None
        if frame.MESSAGE.timing != "configurable" or not FAST_MESSAGES:
            return None
        self._parts[name] = frame
        self._fresh.add(name)
        if name != FAST_MESSAGES[-1].name:
            return None
        if any(m.name not in self._parts for m in FAST_MESSAGES):
            self.incomplete += 1
            self._fresh.clear()
            return None
        if any(m.name not in self._fresh for m in FAST_MESSAGES):
            self.stale += 1
        self._fresh.clear()
        values = {"time_s": frame.time_s}
        for m in FAST_MESSAGES:
            part = self._parts[m.name]
            for s in m.signals:
                key = frames.field_name(s.name)
                values[key] = getattr(part, key)
        for key in HEARTBEAT_FIELDS:
            if key not in values:
                values[key] = getattr(self._heartbeat, key, None)
        self.samples += 1
        return TelemetrySample(**values)
