"""Follows one drive's frames without I/O: decodes them, assembles telemetry samples and keeps
the latest frame of each message. The client feeds it from its receive thread; the command
line feeds it from a log."""
from . import frames as frames_
from .telemetry import TelemetryAssembler


class Monitor:
    def __init__(self, node_id):
        self.decoder = frames_.FrameDecoder(node_id)
        self.assembler = TelemetryAssembler()
        self.latest = {}  # message name -> its latest frame object
        self.counts = {}  # message name -> frames decoded

    @property
    def node_id(self):
        return self.decoder.node_id

    @property
    def skipped(self):
        return self.decoder.skipped

    def feed(self, message):
        """Takes a python-can Message; returns (frame object or None, TelemetrySample or None)."""
        frame = self.decoder.decode(message)
        if frame is None:
            return None, None
        name = frame.MESSAGE.name
        self.latest[name] = frame
        self.counts[name] = self.counts.get(name, 0) + 1
        return frame, self.assembler.feed(frame)

    def heartbeat(self):
        return self.latest.get("heartbeat")
