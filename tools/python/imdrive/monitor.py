"""Follows one drive's frames without I/O: decodes them, assembles telemetry samples, keeps the
latest frame of each message, checks the protocol its version frame names and counts its
restarts (startup.py). The client feeds it from its receive thread; the command line feeds it
from a log or a bus."""
from . import frames as frames_
from . import startup
from .telemetry import TelemetryAssembler


class Monitor:
    def __init__(self, node_id):
        self.decoder = frames_.FrameDecoder(node_id)
        self.assembler = TelemetryAssembler()
        self.latest = {}  # message name -> its latest frame object
        self.counts = {}  # message name -> frames decoded
        self.protocol_error = None  # the first ProtocolMismatch a version frame showed
        self._restarts = startup.RestartDetector()

    @property
    def node_id(self):
        return self.decoder.node_id

    @property
    def skipped(self):
        return self.decoder.skipped

    @property
    def restarts(self):
        """How many times the drive was seen to start again."""
        return self._restarts.restarts

    def feed(self, message):
        """Takes a python-can Message; returns (frame object or None, TelemetrySample or None)."""
        frame = self.decoder.decode(message)
        if frame is None:
            return None, None
        name = frame.MESSAGE.name
        self.latest[name] = frame
        self.counts[name] = self.counts.get(name, 0) + 1
        if name == "version" and self.protocol_error is None:
            self.protocol_error = startup.protocol_mismatch(frame)
        self._restarts.feed(frame)
        return frame, self.assembler.feed(frame)

    def heartbeat(self):
        return self.latest.get("heartbeat")

    def version(self):
        """The latest Version frame, or None."""
        return self.latest.get("version")
