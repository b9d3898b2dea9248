"""A candump -L log replayed as a python-can bus (read-only).

One frame a line, as tools/can_log/candump_log.hpp writes and reads them:
    (SECONDS.MICROS) IFACE ID#HEXDATA[ DIRECTION]
with 6 digits after the point, or 9 (nanoseconds, as candump -N writes).
ID is 3 hex digits (11-bit) or 8 (29-bit; with bit 29 set, an error frame); `ID#R` or `ID#R<n>`
is a remote frame, `ID##<flags><data>` a CAN FD frame, and `_<digit>` after 8 data bytes their
raw DLC of 9..15 (`ID#R8_X` for a remote frame). IFACE may be padded with spaces on its left;
DIRECTION (candump -x) is R or T. `DROPCOUNT: dropped N CAN frames on 'ARG' socket (total
drops M)` lines (candump -d) are counted in `dropped`; ARG is candump's argument as given, which
Debian 12's can-utils writes with its filters (`'can0,020:7E0,7FF:7FF'`), so anything up to
`' socket (total drops` is taken.
With `node_id` the bus hands out only
that drive's frames of the protocol and counts the others by reason in `skipped` (error frames,
remote, FD and 29-bit frames, other nodes, unknown messages, wrong lengths); without it, every
frame. A line that is none of these raises LogFormatError naming the file, the line and what is
wrong. Blank lines are skipped and a trailing '\\r' is ignored.
"""
import collections
import re
import time

import can

from .frames import FrameDecoder

CAN_ERR_FLAG = 0x20000000
_LINE_RE = re.compile(r"^\((\d{1,12})\.(\d{6}|\d{9})\) +(\S{1,15}) (\S+)(?: ([RT]))?$")
_FD_LENGTHS = (0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64)
_HEX_RE = re.compile(r"^(?:[0-9A-Fa-f]{2})*$")
_DROPCOUNT_RE = re.compile(
    r"^DROPCOUNT: dropped (\d+) CAN frames? on '(.*)' socket \(total drops \d+\)$")


class LogFormatError(ValueError):
    """A line of a log file is not a candump -L frame."""


def parse_line(text):
    """A python-can Message from one candump -L line; ValueError says what is wrong."""
    match = _LINE_RE.match(text)
    if not match:
        raise ValueError(f"expected '(SECONDS.MICROS) IFACE ID#DATA' (6 or 9 digits after the "
                         f"point), got {text[:60]!r}")
    seconds, fraction, iface, frame, direction = match.groups()
    timestamp = int(seconds) + int(fraction) / 10 ** len(fraction)
    id_text, hash_, data_text = frame.partition("#")
    if not hash_:
        raise ValueError(f"bad frame {frame!r}: expected ID#DATA (no '#' found)")
    if len(id_text) not in (3, 8) or not re.fullmatch(r"[0-9A-Fa-f]+", id_text):
        raise ValueError(f"bad identifier {id_text!r}: expected 3 hex digits (or 8 for an "
                         f"extended identifier)")
    can_id = int(id_text, 16)
    extended = len(id_text) == 8
    if not extended and can_id > 0x7FF:
        raise ValueError(f"identifier {id_text!r} is above 7FF (11 bits)")
    fields = dict(timestamp=timestamp, channel=iface, is_extended_id=extended,
                  is_rx=direction != "T")
    if extended and can_id & CAN_ERR_FLAG:
        return can.Message(arbitration_id=can_id & 0x1FFFFFFF, is_error_frame=True,
                           data=_hex_bytes(data_text, 8), **fields)
    if extended and can_id > 0x1FFFFFFF:
        raise ValueError(f"identifier {id_text!r} is above 1FFFFFFF (29 bits)")
    if data_text.startswith("#"):  # FD: one flags digit, then up to 64 bytes
        if len(data_text) < 2 or data_text[1] not in "0123456789ABCDEFabcdef":
            raise ValueError(f"bad CAN FD frame {frame!r}: expected ID##<flags><data>")
        data = _hex_bytes(data_text[2:], 64)
        if len(data) not in _FD_LENGTHS:
            raise ValueError(f"CAN FD frame {frame!r}: {len(data)} bytes is not an FD length")
        return can.Message(arbitration_id=can_id, is_fd=True, data=data,
                           bitrate_switch=bool(int(data_text[1], 16) & 1), **fields)
    if data_text.startswith("R"):
        rest = data_text[1:]
        if re.fullmatch(r"8_[0-9A-Fa-f]", rest):  # 8 with a raw DLC of 9..15
            if int(rest[2], 16) < 9:
                raise ValueError(f"bad raw DLC in {frame!r}: '_X' follows R8, X in 9..F")
            rest = rest[0]
        if rest and not (len(rest) == 1 and rest in "012345678"):
            raise ValueError(f"bad remote frame {data_text!r}: expected R or R<length 0..8>")
        return can.Message(arbitration_id=can_id, is_remote_frame=True,
                           dlc=int(rest) if rest else 0, **fields)
    if re.search(r"_[0-9A-Fa-f]$", data_text):  # 8 bytes sent with a raw DLC of 9..15
        if len(data_text) != 18 or int(data_text[-1], 16) < 9:
            raise ValueError(f"bad raw DLC in {frame!r}: '_X' follows 8 data bytes, X in 9..F")
        data_text = data_text[:-2]
    return can.Message(arbitration_id=can_id, data=_hex_bytes(data_text, 8), **fields)


def _hex_bytes(text, most):
    if not _HEX_RE.match(text):
        raise ValueError(f"bad data {text!r}: expected pairs of hex digits")
    if len(text) // 2 > most:
        raise ValueError(f"data {text!r} has {len(text) // 2} bytes: at most {most}")
    return bytes.fromhex(text)


def parse_dropcount(text):
    """The frames a DROPCOUNT line says the capture lost, or None if it is not one."""
    if not text.startswith("DROPCOUNT:"):
        return None
    match = _DROPCOUNT_RE.match(text)
    if not match:
        raise ValueError(f"bad DROPCOUNT line {text[:80]!r}: expected \"DROPCOUNT: dropped N "
                         f"CAN frames on 'ARG' socket (total drops M)\"")
    return int(match.group(1))


def read_log(path, on_dropped=None):
    """Yields every frame of a log as python-can Messages; LogFormatError on a bad line.
    `on_dropped(n)` is called for each DROPCOUNT line."""
    try:
        stream = open(path, encoding="ascii", errors="replace")
    except OSError as error:
        raise LogFormatError(f"{path}: cannot open file ({error.strerror})") from None
    with stream:
        for number, line in enumerate(stream, 1):
            line = line.rstrip("\n").rstrip("\r")
            if not line:
                continue
            try:
                dropped = parse_dropcount(line)
                if dropped is None:
                    yield parse_line(line)
                elif on_dropped is not None:
                    on_dropped(dropped)
            except ValueError as error:
                raise LogFormatError(f"{path}:{number}: {error}") from None


class LogReplayBus(can.BusABC):
    """A log as a bus: recv() returns its frames in order; at the end of the log it returns
    None at once, whatever its timeout (None too: a log has nothing more to wait for), and sets
    `ended`. `for message in bus:` ends there as well. With `realtime`, each frame waits until
    its time after the first, as it came on the bus."""

    def __init__(self, path, node_id=None, realtime=False, **kwargs):
        super().__init__(channel=str(path), **kwargs)
        self.channel_info = f"candump -L log {path}"
        self.dropped = 0  # frames the capture lost (its DROPCOUNT lines)
        self._frames = read_log(path, on_dropped=self._count_dropped)
        self._decoder = FrameDecoder(node_id) if node_id is not None else None
        self._realtime = realtime
        self._start = None
        self.frames = 0
        self.skipped = collections.Counter()
        self.ended = False

    def _count_dropped(self, frames):
        self.dropped += frames

    def recv(self, timeout=None):
        # python-can's recv asks _recv_internal again while the timeout lasts (forever with
        # None), which at the end of a log would never return.
        while True:
            message, _ = self._recv_internal(timeout)
            if message is None or self._matches_filters(message):
                return message

    def __iter__(self):
        # python-can's __iter__ polls forever; a log ends.
        return iter(self.recv, None)

    def _recv_internal(self, timeout):
        for message in self._frames:
            self.frames += 1
            if self._decoder is not None:
                reason = self._decoder.skip_reason(message)
                if reason is not None:
                    self.skipped[reason] += 1
                    continue
            if self._realtime:
                self._pace(message.timestamp)
            return message, False
        self.ended = True
        return None, False

    def _pace(self, timestamp):
        now = time.monotonic()
        if self._start is None:
            self._start = (now, timestamp)
        due = self._start[0] + (timestamp - self._start[1])
        if due > now:
            time.sleep(due - now)

    def send(self, msg, timeout=None):
        raise can.CanOperationError("a log replay is read-only: commands need a live bus")

    def skipped_text(self):
        """'12 other_node, 1 error_frame' or 'none'."""
        return ", ".join(f"{n} {reason}" for reason, n in sorted(self.skipped.items())) or "none"
