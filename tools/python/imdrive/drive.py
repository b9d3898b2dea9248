"""The client: one drive on a python-can bus (SocketCAN, a socketcand server such as drive_hil
--can socketcand:PORT through SocketcandBus, the `virtual` interface, a log replay).

A receive thread feeds every frame to a Monitor; commands are sent from the caller's thread
with the next alive counter and wait for their command_ack. The counter is learnt from the
heartbeat's command_counter before the first command, and learnt again when the drive rejects
a frame for its counter (another host sent in between, frames were lost): the frame is then
sent once more with the counter the next heartbeat gives. It is learnt again too when the drive
restarts (startup.py says how a restart shows). The counter state is shared by the caller and
the keep-alive thread: it is read and written under the drive's lock, one thread learns it at a
time, and a frame is encoded and sent under one lock, so that frames leave in counter order.

A version frame whose protocol is not the client's table makes every later command and wait
raise ProtocolMismatch: the drive's frames would decode wrongly.

While the drive is enabled from CAN, its command watchdog trips (command_timeout) unless a
valid command comes every command_timeout_s (0.2 s by default): enable() therefore starts a
keep-alive that repeats the latest set_speed (KeepAlive); disable(), emergency_stop() and
stop_keep_alive() end it.
"""
import collections
import math
import threading
import time

import can

from . import table
from .commands import CommandEncoder
from .errors import CommandRejected, DriveError, NoAnswer, ProtocolMismatch
from .keepalive import KeepAlive
from .monitor import Monitor
from .service import ParameterService

COUNTER_RESULTS = ("repeated_counter", "stale_counter")


class Drive(ParameterService):
    """Commands and watches the drive `node_id` on `bus` (a python-can BusABC).

    answer_timeout_s: how long a command waits for its command_ack (and the first command for
    a heartbeat). Use as a context manager, or call close()."""

    RECEIVE_POLL_S = 0.05
    SAMPLE_QUEUE = 4096  # about 40 s of samples at the default 100 Hz

    def __init__(self, bus, node_id=1, answer_timeout_s=0.5, keep_alive_hz=20.0):
        if not isinstance(node_id, int) or not 0 <= node_id <= table.MAX_NODE_ID:
            raise ValueError(f"node id {node_id!r}: must be an integer in 0..{table.MAX_NODE_ID}")
        if not answer_timeout_s > 0:
            raise ValueError(f"answer_timeout_s {answer_timeout_s!r}: must be > 0")
        self.bus = bus
        self.node_id = node_id
        self.answer_timeout_s = answer_timeout_s
        self.monitor = Monitor(node_id)
        self._encoder = CommandEncoder(node_id)
        self._synced = False  # whether the encoder's counter is the drive's; under _changed
        self._changed = threading.Condition()  # the lock of everything the threads share
        self._learning = threading.Lock()  # one thread learns the counter at a time
        self._sending = threading.Lock()  # encode and send as one step: frames in counter order
        # (message id, counter) -> the slot ([command_ack frame or None]) of the command that
        # waits for it. Each send has its own slot: the counter wraps at 16, and a sender
        # starved after its ack came must still find its ack once another sender reuses the key.
        self._waiting = {}
        self._samples = collections.deque(maxlen=self.SAMPLE_QUEUE)
        self._frames = collections.deque(maxlen=self.SAMPLE_QUEUE)
        self._frame_seq = 0
        self._heartbeats = 0
        self._bus_error = None
        self._stop = threading.Event()
        self.keep_alive = KeepAlive(self, keep_alive_hz)
        self._thread = threading.Thread(target=self._receive, name=f"imdrive-rx-{node_id}",
                                        daemon=True)
        self._thread.start()

    # --- life cycle

    def close(self):
        """Stops the keep-alive and the receive thread (the bus stays open: it is the caller's)."""
        self.keep_alive.stop()
        self._stop.set()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(timeout=2.0)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # --- receiving

    def _receive(self):
        while not self._stop.is_set():
            try:
                message = self.bus.recv(timeout=self.RECEIVE_POLL_S)
            except Exception as error:  # a dead interface: every waiter must hear of it
                with self._changed:
                    self._bus_error = error
                    self._changed.notify_all()
                return
            if message is None:
                if getattr(self.bus, "ended", False):  # a log replay at its end
                    return
                continue
            restarts = self.monitor.restarts
            frame, sample = self.monitor.feed(message)
            if frame is None:
                continue
            with self._changed:
                if self.monitor.restarts != restarts:
                    self._synced = False  # the drive started again: learn the counter anew
                self._dispatch(frame, sample)
                self._changed.notify_all()

    def _dispatch(self, frame, sample):
        name = frame.MESSAGE.name
        self._frame_seq += 1
        self._frames.append((self._frame_seq, frame))
        if sample is not None:
            self._samples.append(sample)
        if name == "heartbeat":
            self._heartbeats += 1
        elif name == "command_ack":
            key = (_raw_message_id(frame), frame.counter)
            slot = self._waiting.pop(key, None)
            if slot is not None:
                slot[0] = frame
            else:
                self.keep_alive.on_ack(frame)

    def _check_bus(self):
        """Raises what makes waiting pointless: a dead bus, a drive on another protocol."""
        if self._bus_error is not None:
            raise DriveError(f"node {self.node_id}: the bus failed: {self._bus_error}")
        mismatch = self.monitor.protocol_error
        if mismatch is not None:
            raise ProtocolMismatch(str(mismatch), mismatch.drive, mismatch.client)

    def wait(self, predicate, timeout_s, what):
        """Waits until predicate() (called under the lock) is true; NoAnswer(what) on timeout."""
        deadline = time.monotonic() + timeout_s
        with self._changed:
            while True:
                result = predicate()
                if result:
                    return result
                self._check_bus()
                left = deadline - time.monotonic()
                if left <= 0 or not self._thread.is_alive():
                    raise NoAnswer(f"node {self.node_id}: {what} within {timeout_s:g} s")
                self._changed.wait(min(left, 0.1))

    @property
    def heartbeat(self):
        """The latest Heartbeat frame, or None."""
        return self.monitor.heartbeat()

    def wait_heartbeat(self, timeout_s=None):
        """The next heartbeat after this call."""
        seen = self._heartbeats
        return self.wait(lambda: self._heartbeats > seen and self.monitor.heartbeat(),
                         timeout_s or max(self.answer_timeout_s, 0.5), "no heartbeat")

    @property
    def state(self):
        """The drive state's name from the latest heartbeat, or None."""
        return getattr(self.heartbeat, "state", None)

    @property
    def version(self):
        """The latest Version frame (protocol_version, firmware_major, ...), or None."""
        return self.monitor.version()

    @property
    def restarts(self):
        """How many times the drive was seen to start again since the client started."""
        return self.monitor.restarts

    # --- telemetry

    @property
    def latest_sample(self):
        return self._samples[-1] if self._samples else None

    def samples(self, timeout_s=None):
        """Yields telemetry samples as they arrive (those received since the last call first);
        ends after `timeout_s` s without one (None: never)."""
        while True:
            with self._changed:
                if not self._samples:
                    self._check_bus()
                    if not self._changed.wait_for(lambda: self._samples or self._bus_error
                                                  or not self._thread.is_alive(), timeout_s):
                        return
                    if not self._samples:
                        self._check_bus()
                        return
                sample = self._samples.popleft()
            yield sample

    def wait_for_sample(self, predicate, timeout_s, what="no telemetry sample as asked"):
        """The first telemetry sample from now on for which predicate(sample) holds."""
        with self._changed:
            self._samples.clear()
        deadline = time.monotonic() + timeout_s
        while True:
            for sample in self.samples(timeout_s=max(deadline - time.monotonic(), 0.0)):
                if predicate(sample):
                    return sample
                if time.monotonic() >= deadline:
                    break
            raise NoAnswer(f"node {self.node_id}: {what} within {timeout_s:g} s")

    def wait_for_frame(self, message_name, predicate=lambda f: True, timeout_s=1.0):
        """The first frame of `message_name` received from now on for which predicate holds."""
        table.message(message_name)
        with self._changed:
            start = self._frame_seq

        def found():
            for f in self.frames_after(start):
                if f.MESSAGE.name == message_name and predicate(f):
                    return f
            return None
        return self.wait(found, timeout_s, f"no {message_name} frame as asked")

    def frames_after(self, seq):
        """The frames received after frame number `seq` (self._frame_seq), oldest first; call
        under the lock. Walks back from the newest, so a wait costs what arrived since."""
        return [f for _, f in self.numbered_frames_after(seq)]

    def numbered_frames_after(self, seq):
        """Like frames_after, as (frame number, frame) pairs."""
        newer = []
        for item in reversed(self._frames):
            if item[0] <= seq:
                break
            newer.append(item)
        newer.reverse()
        return newer

    # --- commands

    def forget_counter(self):
        """Makes the next command learn the alive counter from a heartbeat first."""
        with self._changed:
            self._synced = False

    def learn_counter(self):
        """Unless known, learns the alive counter: the command_counter of the next heartbeat
        + 1. One thread learns; one that waited meanwhile finds it learnt."""
        with self._learning:
            with self._changed:
                if self._synced:
                    return
                seen = self._heartbeats
            hb = self.wait(lambda: self._heartbeats > seen and self.monitor.heartbeat(),
                           max(self.answer_timeout_s, 0.5), "no heartbeat")
            counter = getattr(hb, "command_counter", None)
            with self._changed:
                # A table without command_counter: start anywhere; a rejection tells the truth.
                self._encoder.next_counter = (counter + 1) if isinstance(counter, int) else 0
                self._synced = True

    def send(self, message_name, wait_ack=True, **values):
        """Sends command `message_name` with `values` (by signal name) and, with wait_ack,
        returns its command_ack frame; CommandRejected names the result, NoAnswer a timeout.
        A counter rejection is retried once on the counter the next heartbeat gives."""
        return self._send(message_name, wait_ack, values)

    def _send(self, message_name, wait_ack, values, cancelled=None):
        """send(); with `cancelled` (a function), nothing goes out once it returns True: False."""
        with self._changed:
            self._check_bus()  # a drive on another protocol gets no command
        for attempt in (1, 2):
            self.learn_counter()
            ack = self._send_once(message_name, wait_ack, values, cancelled)
            if ack in (None, False) or ack.result == "accepted":
                return ack
            if ack.result in COUNTER_RESULTS and attempt == 1:
                self.forget_counter()  # the next heartbeat carries the drive's reference
                continue
            raise CommandRejected(
                f"node {self.node_id}: {message_name} {_values_text(values)}rejected: "
                f"{ack.result}", message_name, ack.counter, ack.result)

    def _send_once(self, message_name, wait_ack, values, cancelled=None):
        with self._sending:
            if cancelled is not None and cancelled():
                return False
            frame = self._encoder.encode(message_name, **values)
            key = (table.message_id_of(frame.arbitration_id), frame.data[1] & 0x0F)
            slot = [None]
            if wait_ack:  # else its ack goes to the keep-alive (on_ack), not to a slot
                with self._changed:
                    self._waiting[key] = slot
            try:
                self.bus.send(frame)
            except can.CanError as error:
                with self._changed:
                    self._forget_slot(key, slot)
                raise DriveError(
                    f"node {self.node_id}: cannot send {message_name}: {error}") from None
        if not wait_ack:
            return None
        try:
            return self.wait(lambda: slot[0], self.answer_timeout_s,
                             f"no command_ack for {message_name} (counter {key[1]})")
        finally:
            with self._changed:
                self._forget_slot(key, slot)

    def _forget_slot(self, key, slot):
        """Stops waiting on `slot` unless a later command with the same key holds `key` now."""
        if self._waiting.get(key) is slot:
            del self._waiting[key]

    def enable(self, keep_alive=True, calibration_timeout_s=5.0):
        """idle -> magnetizing -> running; starts the keep-alive (set_speed 0 until set_speed).
        A drive that has just started measures its ADC offsets first (state calibrating, with
        the PWM off) and refuses enable meanwhile: a script started with the drive would race
        it, so this waits for a heartbeat past calibrating, up to calibration_timeout_s."""
        self.wait(lambda: self.heartbeat is not None and self.state != "calibrating",
                  calibration_timeout_s, "still calibrating its ADC offsets (state calibrating)")
        ack = self.send("enable")
        if keep_alive:
            self.keep_alive.start()
        return ack

    def disable(self):
        self.keep_alive.stop()
        return self.send("disable")

    def emergency_stop(self):
        """PWM off at once, latched as fault emergency_stop. The drive obeys it whatever its
        counter (firmware/protocol/commands.cpp) and takes that counter as its reference, so it
        goes out at once with the counter the client holds, learnt or not: no heartbeat is
        waited for. The keep-alive is told to stop first (no frame of it follows the stop) but
        not waited for. Then the ack is awaited; without one the stop is sent once more."""
        self.keep_alive.signal_stop()
        try:
            ack = self._send_once("emergency_stop", True, {})
        except NoAnswer:
            ack = self._send_once("emergency_stop", True, {})
        if ack.result != "accepted":  # only a garbled frame can be refused
            raise CommandRejected(f"node {self.node_id}: emergency_stop rejected: {ack.result}",
                                  "emergency_stop", ack.counter, ack.result)
        with self._changed:
            self._synced = True  # the drive's reference is the stop's counter now
        self.keep_alive.stop()
        return ack

    def clear_faults(self):
        return self.send("clear_faults")

    def set_speed(self, speed_rad_s):
        """The speed reference (rad/s); the keep-alive repeats it from now on."""
        ack = self.send("set_speed", speed_ref_rad_s=speed_rad_s)
        self.keep_alive.speed_rad_s = speed_rad_s
        return ack

    def set_flux(self, flux2_Wb2):
        return self.send("set_flux", flux2_ref_Wb2=flux2_Wb2)

    def select_controller(self, controller):
        """'dsmc', 'iol' or 'ifoc' (the table's names), only while idle."""
        return self.send("select_controller", controller=controller)

    def set_telemetry_rate(self, rate_Hz):
        return self.send("set_telemetry_rate", rate_Hz=rate_Hz)

    def stop_keep_alive(self):
        self.keep_alive.stop()

    def wait_state(self, state, timeout_s):
        """Waits for a heartbeat in `state` (a name); returns it."""
        return self.wait(lambda: self.state == state and self.heartbeat, timeout_s,
                         f"not in state {state} (last: {self.state})")


def _raw_message_id(ack):
    """command_ack's `message` as a number (it reads as a name when the table names it)."""
    m = ack.message
    if isinstance(m, str):
        return table.message(m).id
    return m


def _values_text(values):
    parts = [f"{k}={v:g}" if isinstance(v, float) and math.isfinite(v) else f"{k}={v}"
             for k, v in values.items()]
    return " ".join(parts) + " " if parts else ""
