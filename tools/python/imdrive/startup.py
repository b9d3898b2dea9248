"""What the drive's frames say about its start: the version frame (the protocol the drive speaks
and its firmware) and the signs that it started again.

At each start (power-on or any reset) the firmware sends `version` as its very first frame,
starts in state `calibrating` (it announces no state_change into it: it starts there) and counts
its heartbeats in `counter` from 0, one per heartbeat, wrapping at 256. It also sends `version`
once a second with every tenth heartbeat, so a version frame alone is no restart: the
heartbeats tell. A heartbeat after an earlier one shows a restart when

* it is a start's first heartbeat: counter 0 in state calibrating (the version frame before
  it is not required: a start whose version frame was lost is still a start); or
* its counter went back (serial-number arithmetic mod 256: a step of 0, or of 128 and more),
  for a start whose first heartbeat was lost. 128 steps are 12.8 s of heartbeats: a gap that
  long is worth learning the counter again anyway.

A running drive's counter also passes 0 every 25.6 s, but in state calibrating only when it happens
to calibrate again at that moment. A false alarm costs little: the client learns the command
counter again from a heartbeat. A start missed (its first heartbeats lost, the counter above 127
before) costs little too: after a start the drive takes any counter from the first command.
"""
from . import table
from .errors import ProtocolMismatch

HEARTBEAT_COUNTER_MODULO = 256  # heartbeat.counter has 8 bits
FIRST_HEARTBEAT_COUNTER = 0
START_STATE = "calibrating"


def firmware_text(version):
    """'0.1.0+ga2e14617.dirty' from a Version frame, as drive_monitor shows it ('+gunknown':
    a firmware built outside a git checkout sends a hash of 0)."""
    commit = f"{version.git_hash:08x}" if version.git_hash else "unknown"
    return (f"{version.firmware_major}.{version.firmware_minor}.{version.firmware_patch}"
            f"+g{commit}{'.dirty' if version.dirty else ''}")


def protocol_mismatch(version):
    """A ProtocolMismatch naming both versions when the drive's protocol is not the table's,
    else None."""
    if version.protocol_version == table.PROTOCOL_VERSION:
        return None
    return ProtocolMismatch(
        f"node {version.node_id} speaks protocol {version.protocol_version} (firmware "
        f"{firmware_text(version)}), this client protocol {table.PROTOCOL_VERSION}: its frames "
        f"would decode wrongly; use the imdrive of the drive's firmware",
        version.protocol_version, table.PROTOCOL_VERSION)


class RestartDetector:
    """Fed every decoded frame of one drive; counts the restarts it sees in `restarts`."""

    def __init__(self):
        self.restarts = 0
        self._last = None  # the last heartbeat

    def feed(self, frame):
        """True when this frame shows that the drive started again."""
        if frame.MESSAGE.name != "heartbeat":
            return False
        last, self._last = self._last, frame
        if last is None:  # the first heartbeat seen: nothing to compare with
            return False
        step = (frame.counter - last.counter) % HEARTBEAT_COUNTER_MODULO
        started = frame.counter == FIRST_HEARTBEAT_COUNTER and frame.state == START_STATE
        if started or step == 0 or step >= HEARTBEAT_COUNTER_MODULO // 2:
            self.restarts += 1
            return True
        return False
