"""A simulated drive on python-can's virtual bus, for the client's unit tests: it checks command
frames as firmware/protocol/commands.cpp does (length, CRC, alive counter, ranges), answers each
with a command_ack, runs a small state machine (idle, magnetizing, running, fault) with the
command watchdog, and sends heartbeats and fast telemetry. It is a stand-in for the protocol's
behaviour, not for the motor: the speed follows its reference with a first-order lag.

It starts as firmware/telemetry.cpp does: a version frame first, then heartbeats whose counter
runs from 0 (+1 each, wrapping at 256), in state calibrating, which it leaves for idle with a
state_change (there is none into calibrating: it starts there); a version frame again with
every tenth heartbeat. restart() starts it again the same way."""
import math
import threading
import time

import can

from imdrive import e2e, frames, table

TICK_S = 0.005
HEARTBEAT_S = 0.1
TELEMETRY_S = 0.01
WATCHDOG_S = 0.2
MAGNETIZING_S = 0.05
CALIBRATING_S = 0.05       # a stand-in for the firmware's ADC offset calibration
HEARTBEATS_PER_VERSION = 10  # the version frame's 1 s over the heartbeat's 0.1 s
SPEED_TAU_S = 0.05
PLANT_FLUX2_WB2 = 0.2


class FakeDrive:
    def __init__(self, channel, node_id=1, watchdog=True, protocol_version=None):
        self.bus = can.Bus(interface="virtual", channel=channel)
        self.node_id = node_id
        self.watchdog = watchdog
        self.protocol_version = table.PROTOCOL_VERSION if protocol_version is None \
            else protocol_version
        self.silent = False        # no acks, no frames at all
        self.heartbeats = True     # False: its heartbeats are lost (the rest still comes)
        self.refuse = None         # a result name every valid command gets instead of accepted
        self.first_fault = "none"
        self.speed_ref = 0.0
        self.speed = 0.0
        self.controller = "dsmc"
        self.last_counter = None
        self.last_valid_s = time.monotonic()
        self.record = {name: math.nan for _, name in table.find_signal(
            table.message("parameter_access"), "field").values}
        self.saved = False
        self.identify_start = None
        self.received = []         # (message name, result) of every command frame
        self.arrivals = []         # (time.monotonic(), message name, counter) of each one
        self._stop = threading.Event()
        self._lock = threading.Lock()
        with self._lock:
            self._start()
        self._threads = [threading.Thread(target=self._receive, daemon=True),
                         threading.Thread(target=self._run, daemon=True)]
        for t in self._threads:
            t.start()

    def close(self):
        self._stop.set()
        for t in self._threads:
            t.join(timeout=2)
        self.bus.shutdown()

    def restart(self):
        """A power cycle: no counter reference, faults cleared, calibrating, then idle."""
        with self._lock:
            self._start()

    def _start(self):
        self.last_counter = None
        self.state, self.first_fault, self.speed_ref, self.speed = "calibrating", "none", 0.0, 0.0
        self.calibrated_at = time.monotonic() + CALIBRATING_S
        self.hb_counter = self.since_version = 0
        self.next_hb = time.monotonic()  # the first heartbeat at once, after the version
        self._version()

    def _version(self):
        self._send("version", protocol_version=self.protocol_version, firmware_major=0,
                   firmware_minor=1, firmware_patch=0, dirty=False, git_hash=0x1234ABCD)

    def wait_idle(self, timeout_s=2.0):
        """Waits until it has calibrated (the tests start on a drive that has)."""
        deadline = time.monotonic() + timeout_s
        while self.state == "calibrating" and time.monotonic() < deadline:
            time.sleep(TICK_S)
        assert self.state == "idle", f"the fake drive is still {self.state}"

    def _send(self, name, **values):
        if not self.silent:
            self.bus.send(frames.encode_message(name, self.node_id, **values))

    def _ack(self, msg, counter, result):
        self.received.append((msg.name, result))
        self._send("command_ack", message=msg.id, counter=counter, result=result,
                   rejected_total=sum(1 for _, r in self.received if r != "accepted"))

    def _receive(self):
        while not self._stop.is_set():
            m = self.bus.recv(timeout=0.05)
            if m is None or m.is_extended_id or table.node_of(m.arbitration_id) != self.node_id:
                continue
            msg = table.message_by_id(table.message_id_of(m.arbitration_id))
            if msg is None or not table.is_command(msg):
                continue
            with self._lock:
                self._command(msg, m)

    def _command(self, msg, m):
        data = bytearray(m.data).ljust(8, b"\0")
        counter = e2e.e2e_counter(data)
        self.arrivals.append((time.monotonic(), msg.name, counter))
        if m.dlc != msg.length:
            return self._ack(msg, counter, "wrong_length")
        if not e2e.e2e_check(m.arbitration_id, data, m.dlc):
            return self._ack(msg, counter, "bad_crc")
        if self.last_counter is not None and msg.name != "emergency_stop":
            step = (counter - self.last_counter) % 16
            if step == 0:
                return self._ack(msg, counter, "repeated_counter")
            if step > table.MAX_COUNTER_STEP:
                return self._ack(msg, counter, "stale_counter")
        self.last_counter = counter
        self.last_valid_s = time.monotonic()
        values = {s.name: frames.signal_value(data, s) for s in msg.signals}
        for s in msg.signals:
            v = values[s.name]
            if s.minimum is not None and not s.values and not s.minimum <= v <= s.maximum:
                return self._ack(msg, counter, "out_of_range")
        if self.refuse:
            return self._ack(msg, counter, self.refuse)
        self._ack(msg, counter, self._apply(msg.name, values))

    def _apply(self, name, v):
        if name == "enable":
            if self.state != "idle":
                return "not_allowed"
            self._go("magnetizing", "enable")
            self.enabled_at = time.monotonic()
        elif name == "disable":
            self.speed_ref = 0.0
            if self.state in ("running", "magnetizing"):
                self._go("idle", "disable")
            self.identify_start = None
        elif name == "emergency_stop":
            self._trip("emergency_stop")
        elif name == "clear_faults":
            if self.state == "fault":
                self.first_fault = "none"
                self._go("idle", "clear_faults")
        elif name == "set_speed":
            self.speed_ref = v["speed_ref_rad_s"]
        elif name == "select_controller":
            if self.state != "idle":
                return "not_allowed"
            self.controller = v["controller"]
        elif name == "parameter_access":
            self._parameter(v["op"], v["field"], v["value"])
        elif name == "identify":
            if self.state != "idle":
                return "not_allowed"
            self.identify_start = time.monotonic()
        return "accepted"

    def _parameter(self, op, field, value):
        status = "ok"
        if op == "write":
            if self.state != "idle":
                status = "not_idle"
            elif not value > 0:
                status = "not_positive"
            else:
                self.record[field] = value
                self.saved = False
        elif op == "read" and math.isnan(self.record[field]):
            status = "not_set"
        elif op == "save":
            self.saved = True
        self._send("parameter_value", field=field, op=op, status=status,
                   value=self.record.get(field, math.nan),
                   complete=not any(math.isnan(x) for x in self.record.values()),
                   saved=self.saved)

    def _go(self, state, reason):
        self._send("state_change", **{"from": self.state, "to": state, "reason": reason})
        self.state = state

    def _trip(self, fault):
        if self.state != "fault":
            self.first_fault = fault
            self.speed_ref = 0.0
            self._go("fault", "fault")

    def _run(self):
        next_tm = time.monotonic()
        while not self._stop.wait(TICK_S):
            now = time.monotonic()
            with self._lock:
                self._step(now)
                if now >= next_tm:
                    next_tm += TELEMETRY_S
                    self._telemetry()
                if now >= self.next_hb:
                    self.next_hb += HEARTBEAT_S
                    self._heartbeat()

    def _heartbeat(self):
        # The table's one-bit fault signals: fault_<name> (none for code 0).
        bits = {f"fault_{self.first_fault}": True} if self.first_fault != "none" else {}
        if self.heartbeats:
            self._send("heartbeat", state=self.state, first_fault=self.first_fault,
                       counter=self.hb_counter, command_counter=self.last_counter or 0,
                       controller=self.controller, **bits)
        self.hb_counter = (self.hb_counter + 1) % 256
        self.since_version += 1
        if self.since_version >= HEARTBEATS_PER_VERSION:
            self.since_version = 0
            self._version()

    def _step(self, now):
        if self.state == "calibrating" and now >= self.calibrated_at:
            self._go("idle", "calibrated")
        if self.state == "magnetizing" and now - self.enabled_at > MAGNETIZING_S:
            self._go("running", "magnetized")
        if self.state in ("magnetizing", "running") and self.watchdog and \
                now - self.last_valid_s > WATCHDOG_S:
            self._trip("command_timeout")
        target = self.speed_ref if self.state == "running" else 0.0
        self.speed += (target - self.speed) * min(1.0, TICK_S / SPEED_TAU_S)
        if self.identify_start is not None:
            self._identify(now - self.identify_start)

    def _identify(self, elapsed_s):
        steps = ["low_level", "high_level", "transient_inductance", "ramp_down", "done"]
        index = min(int(elapsed_s / 0.1), len(steps) - 1)
        if steps[index] == "done":
            self.identify_start = None
        self._send("identify_progress", step=steps[index], fraction=(elapsed_s % 0.1) / 0.1,
                   failure="none", seconds=elapsed_s)

    def _telemetry(self):
        self._send("telemetry_speed_flux", speed_rad_s=self.speed,
                   speed_ref_rad_s=self.speed_ref, flux2_Wb2=PLANT_FLUX2_WB2,
                   flux2_ref_Wb2=PLANT_FLUX2_WB2)
        self._send("telemetry_current", iA_A=1.0, iB_A=0.1 * self.speed, load_Nm=0.0,
                   v_bus_V=311.0)
        self._send("telemetry_voltage", u_alpha_V=0.0, u_beta_V=0.0, sample=0, rr_scale=1.0)
