"""The motor record and the commissioning over CAN, as methods of Drive (docs/can/protocol.md,
"Motor parameters"): each parameter_access is answered by a parameter_value; a busy drive (still
applying the last write) is asked again until the wait runs out.
"""
import math
import time

from . import table
from .errors import IdentifyFailed, NoAnswer, ParameterRefused

# identify_progress steps that end a run (the table's names; see IdentifyProgress.step).
END_STEPS = ("done", "failed")


def field_names():
    """The record's fields, as parameter_access's `field` value table names them."""
    field = table.find_signal(table.message("parameter_access"), "field")
    return [name for _, name in field.values] if field is not None else []


class ParameterService:
    """Mixed into Drive: needs send(), wait_for_frame(), node_id and answer_timeout_s."""

    BUSY_RETRY_S = 0.02

    def _access(self, op, field, value, wait_s):
        wait_s = wait_s or max(self.answer_timeout_s, 2.0)
        deadline = time.monotonic() + wait_s
        while True:
            start_marker = self._frame_seq
            self.send("parameter_access", op=op, field=field, value=value)
            reply = self._reply_after(start_marker, op, field, wait_s)
            if reply.status != "busy" or time.monotonic() >= deadline:
                return reply
            time.sleep(self.BUSY_RETRY_S)

    def _reply_after(self, start, op, field, wait_s):
        def found():
            for f in self.frames_after(start):
                if (f.MESSAGE.name == "parameter_value" and f.op == op
                        and (op == "save" or f.field == field)):
                    return f
            return None
        return self.wait(found, wait_s, f"no parameter_value for {op} {field}")

    def _checked(self, reply, op, field):
        if reply.status != "ok":
            what = f"{op} {field}" if op != "save" else "save"
            raise ParameterRefused(f"node {self.node_id}: parameter {what}: {reply.status}",
                                   op, field, reply.status)
        return reply

    def read_parameter(self, field, wait_s=None):
        """The value of a record field by name (e.g. 'Rs_Ohm'), in its SI unit."""
        reply = self._access("read", field, 0.0, wait_s)
        return self._checked(reply, "read", field).value

    def write_parameter(self, field, value, wait_s=None):
        """Writes a field (the drive must be idle or unconfigured); returns the value the
        drive holds after the write. ParameterRefused names the rule the value breaks."""
        if not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ValueError(f"{field}: {value!r} is not a finite number")
        reply = self._access("write", field, float(value), wait_s)
        return self._checked(reply, "write", field).value

    def save_parameters(self, wait_s=None):
        """Stores the record in the drive's non-volatile storage; returns the reply frame."""
        return self._checked(self._access("save", field_names()[0], 0.0, wait_s), "save", None)

    def read_parameters(self, wait_s=None):
        """Every field: {name: value}, NaN for a field without a value."""
        values = {}
        for name in field_names():
            reply = self._access("read", name, 0.0, wait_s)
            if reply.status not in ("ok", "not_set"):
                self._checked(reply, "read", name)
            values[name] = reply.value if reply.status == "ok" else math.nan
        return values

    def identify(self, rotate=False, timeout_s=120.0, progress=None):
        """Commissions the motor from the nameplate the drive holds. `progress(frame)` is called
        with every IdentifyProgress frame (step, fraction, failure, seconds). Returns the last
        frame (step 'done'); IdentifyFailed names the failure, NoAnswer a run that did not end
        (a disable is then sent, which aborts it)."""
        start = self._frame_seq
        self.send("identify", rotate="rotate" if rotate else "standstill")
        deadline = time.monotonic() + timeout_s
        seen = start
        last = None
        while True:
            try:
                frame, seen = self._next_progress(seen, max(deadline - time.monotonic(), 0.01))
            except NoAnswer:
                self.send("disable", wait_ack=False)
                raise NoAnswer(f"node {self.node_id}: identify did not end within "
                               f"{timeout_s:g} s; disable sent, which aborts the run") from None
            last = frame
            if progress is not None:
                progress(frame)
            if frame.step == "failed":
                raise IdentifyFailed(f"node {self.node_id}: identify failed: {frame.failure} "
                                     f"({frame.seconds:.1f} s)", frame.failure, frame)
            if frame.step in END_STEPS:
                return last

    def _next_progress(self, after, timeout_s):
        def found():
            for number, f in self.numbered_frames_after(after):
                if f.MESSAGE.name == "identify_progress":
                    return number, f
            return None
        number, frame = self.wait(found, timeout_s, "no identify_progress")
        return frame, number
