"""The keep-alive: repeats the latest set_speed at a fixed rate while the drive is enabled from
CAN, so that its command watchdog (command_timeout_s, 0.2 s by default) stays fed.

Frames go out without waiting for their acks (a stop-and-wait at 20 Hz would stall on one lost
ack); the acks that come back are tallied by result in `results`. A counter rejection makes the
client learn the counter again from the next heartbeat before the next frame. Once told to stop
(signal_stop, stop) it sends no further frame: the emergency stop relies on it."""
import collections
import threading

from .errors import DriveError


class KeepAlive:
    def __init__(self, drive, rate_Hz):
        if not 1.0 <= rate_Hz <= 1000.0:
            raise ValueError(f"keep-alive rate {rate_Hz!r} Hz: must be in 1..1000 Hz (the "
                             f"watchdog wants a frame every 0.2 s by default)")
        self._drive = drive
        self.period_s = 1.0 / rate_Hz
        self.speed_rad_s = 0.0
        self.results = collections.Counter()
        self.sent = 0
        self.error = None  # why the keep-alive stopped by itself
        self._stop = threading.Event()
        self._thread = None

    @property
    def running(self):
        return self._thread is not None and self._thread.is_alive()

    def start(self):
        if self.running:
            return
        self._stop.clear()
        self.error = None
        self._thread = threading.Thread(target=self._run, daemon=True,
                                        name=f"imdrive-keepalive-{self._drive.node_id}")
        self._thread.start()

    def signal_stop(self):
        """Stops it without waiting for its thread: no frame of it goes out after this call."""
        self._stop.set()

    def stop(self):
        """Stops it and waits for its thread to end."""
        self._stop.set()
        if self.running and self._thread is not threading.current_thread():
            self._thread.join(timeout=2.0)

    def on_ack(self, ack):
        """A command_ack nobody waited for (called under the drive's lock)."""
        self.results[ack.result] += 1
        if ack.result in ("repeated_counter", "stale_counter"):
            self._drive.forget_counter()

    def _run(self):
        while not self._stop.wait(self.period_s):
            try:
                # The drive checks the stop under its send lock, after any wait for a heartbeat.
                sent = self._drive._send("set_speed", False, {"speed_ref_rad_s": self.speed_rad_s},
                                         cancelled=self._stop.is_set)
            except DriveError as error:
                self.error = error
                return
            if sent is False:
                return
            self.sent += 1
