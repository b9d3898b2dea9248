"""SocketcandBus: a python-can bus over TCP in the socketcand protocol's raw mode
(github.com/linux-can/socketcand, doc/protocol.md), the way to reach `drive_hil --can
socketcand:PORT` on a machine without SocketCAN (a container, WSL, macOS, CI).

    with imdrive.SocketcandBus("127.0.0.1", 29536) as bus, imdrive.Drive(bus, 1) as drive:
        drive.enable()

The stream has no line ends: every message is `< WORDS >`, and TCP cuts it anywhere. The
bytes are therefore kept until a whole message has arrived, whatever the reads' boundaries,
and the handshake (`< hi >`, `< open CHANNEL >` -> `< ok >`, `< rawmode >` -> `< ok >`) reads
messages the same way, so frames that follow an `< ok >` in the same read are kept.
`< error ... >` from the server is counted (`errors_received`) and its text kept in
`server_errors`; it ends nothing.
"""
import collections
import logging
import select
import socket
import threading
import time

import can

log = logging.getLogger(__name__)

DEFAULT_PORT = 29536  # socketcand's own default port
MAX_MESSAGE_BYTES = 256  # the longest frame message is 45 bytes


class SocketcandError(can.CanInitializationError):
    """The bus could not be opened: nothing listens, the server is busy, the handshake failed."""


class MessageReader:
    """Cuts a byte stream into the words of its `< ... >` messages."""

    def __init__(self):
        self._buffer = bytearray()
        self.garbage = 0  # stretches of bytes that were not a message, skipped

    def feed(self, data):
        self._buffer += data

    def next(self):
        """The words of the next whole message (str, trimmed), or None until more is fed."""
        while True:
            start = self._buffer.find(b"<")
            if start < 0:
                if self._buffer.strip():
                    self.garbage += 1
                self._buffer.clear()
                return None
            if self._buffer[:start].strip():
                self.garbage += 1
            del self._buffer[:start]
            end = self._buffer.find(b">", 1)
            reopen = self._buffer.find(b"<", 1)
            if 0 < reopen and (end < 0 or reopen < end):  # a message cut short: skip it
                self.garbage += 1
                del self._buffer[:reopen]
                continue
            if end < 0:
                if len(self._buffer) > MAX_MESSAGE_BYTES:
                    self.garbage += 1
                    self._buffer.clear()
                return None
            words = bytes(self._buffer[1:end]).decode("ascii", "replace").strip()
            del self._buffer[:end + 1]
            return words


def parse_frame(words, channel=None):
    """`frame ID SECONDS.MICROS [HEXDATA ..]` -> can.Message; ValueError if malformed. An
    identifier of 8 hex digits is a 29-bit one (socketcand writes 3 or 8). The data is one
    contiguous word (what socketcand writes) or a word per byte (what its protocol description
    shows, `< frame 123 23.424242 11 22 33 44 >`): the words are joined, each of whole bytes."""
    parts = words.split()
    if len(parts) < 3 or parts[0] != "frame":
        raise ValueError(f"not a frame message: '< {words} >'")
    if any(len(word) % 2 for word in parts[3:]):
        raise ValueError(f"data not in whole hex bytes: '< {words} >'")
    data = bytes.fromhex("".join(parts[3:]))
    if len(data) > 8:
        raise ValueError(f"more than 8 data bytes: '< {words} >'")
    return can.Message(timestamp=float(parts[2]), arbitration_id=int(parts[1], 16),
                       is_extended_id=len(parts[1]) == 8, data=data, channel=channel)


def format_send(message):
    """can.Message -> `< send ID LEN B0 .. >`; CanOperationError for what the protocol
    cannot carry."""
    if message.is_remote_frame or message.is_error_frame or message.is_fd or message.dlc > 8:
        raise can.CanOperationError("socketcand sends classic data frames of 0..8 bytes only")
    can_id = f"{message.arbitration_id:08X}" if message.is_extended_id \
        else f"{message.arbitration_id:03X}"
    data = bytes(message.data[:message.dlc])
    return f"< send {can_id} {len(data)}{''.join(f' {b:02X}' for b in data)} >"


class SocketcandBus(can.BusABC):
    """A python-can bus to a socketcand server (drive_hil --can socketcand:PORT).

    host, port: the server; channel: the bus to open (drive_hil has one, any name does);
    timeout_s: for the connection, the handshake and each send. SocketcandError when it
    cannot be opened, can.CanOperationError when the connection ends later."""

    def __init__(self, host="127.0.0.1", port=DEFAULT_PORT, channel="can0", timeout_s=2.0,
                 can_filters=None, **kwargs):
        self.address = f"{host}:{port}"
        self.server_errors = collections.deque(maxlen=100)
        self.errors_received = 0
        self.echoes = 0
        self._reader = MessageReader()
        self._send_lock = threading.Lock()
        self._closed = False
        try:
            self._socket = socket.create_connection((host, int(port)), timeout=timeout_s)
        except ConnectionRefusedError:
            raise SocketcandError(f"no drive_hil at {self.address}: connection refused; start "
                                  f"drive_hil --can socketcand:{port}") from None
        except socket.timeout:
            raise SocketcandError(f"no drive_hil at {self.address}: no answer to connect "
                                  f"within {timeout_s:g} s") from None
        except OSError as error:
            raise SocketcandError(f"cannot connect to {self.address}: "
                                  f"{error.strerror or error}") from None
        self._socket.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        try:
            deadline = time.monotonic() + timeout_s
            self._expect("hi", deadline, "the greeting")
            self.send_text(f"< open {channel} >")
            self._expect("ok", deadline, f"open {channel}")
            self.send_text("< rawmode >")
            self._expect("ok", deadline, "rawmode")
        except (can.CanError, OSError) as error:
            self._socket.close()
            if isinstance(error, SocketcandError):
                raise
            raise SocketcandError(f"{self.address}: handshake failed: {error}") from None
        self.channel_info = f"socketcand {self.address} {channel}"
        super().__init__(channel=channel, can_filters=can_filters, **kwargs)
        self.channel = channel

    # --- the stream

    def _read_some(self, timeout_s):
        """Reads what has arrived into the reader; False if nothing came within timeout_s
        (None: wait). CanOperationError when the server has closed the connection."""
        if self._closed:
            raise can.CanOperationError(f"{self.address}: the bus is shut down")
        try:
            ready, _, _ = select.select([self._socket], [], [], timeout_s)
            if not ready:
                return False
            data = self._socket.recv(65536)
        except (OSError, ValueError) as error:
            raise can.CanOperationError(f"{self.address}: receive failed: {error}") from None
        if not data:
            raise can.CanOperationError(f"{self.address}: the server closed the connection "
                                        f"(drive_hil stopped?)")
        self._reader.feed(data)
        return True

    def _next_message(self, deadline):
        """The words of the next message, reading as needed until `deadline` (monotonic,
        None: no limit); None at the deadline."""
        while True:
            words = self._reader.next()
            if words is not None:
                return words
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                return None
            self._read_some(left)

    def _expect(self, word, deadline, what):
        words = self._next_message(deadline)
        if words == word:
            return
        if words is None:
            raise SocketcandError(f"{self.address}: no '< {word} >' for {what} in time: is it "
                                  f"a socketcand server?")
        if words == "error busy":
            raise SocketcandError(f"{self.address}: busy: another client is connected (drive_hil "
                                  f"serves one at a time)")
        raise SocketcandError(f"{self.address}: {what}: expected '< {word} >', got '< {words} >'")

    def _take(self, words):
        """A frame as a can.Message; other messages are accounted for, None."""
        verb = words.split(" ", 1)[0]
        if verb == "frame":
            try:
                return parse_frame(words, self.channel)
            except ValueError as error:
                log.warning("%s: %s", self.address, error)
                self._reader.garbage += 1
                return None
        if verb == "error":
            self.errors_received += 1
            self.server_errors.append(words[len("error"):].strip())
            log.warning("%s: < %s >", self.address, words)
        elif verb == "echo":
            self.echoes += 1
        elif verb != "ok":
            self._reader.garbage += 1
        return None

    @property
    def garbage(self):
        """Received stretches that were no message, or no valid one."""
        return self._reader.garbage

    # --- python-can

    def _recv_internal(self, timeout):
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            words = self._next_message(deadline)
            if words is None:
                return None, False
            message = self._take(words)
            if message is not None:
                return message, False

    def send(self, msg, timeout=None):
        self.send_text(format_send(msg))

    def send_text(self, text):
        """Writes `text` as it is: for diagnostics, e.g. '< echo >' (answered '< echo >')."""
        try:
            with self._send_lock:
                self._socket.sendall(text.encode("ascii"))
        except (OSError, ValueError) as error:
            raise can.CanOperationError(f"{self.address}: cannot send: {error}") from None

    def shutdown(self):
        if self._closed:
            return
        self._closed = True
        super().shutdown()
        try:
            self._socket.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass  # the server may have gone first
        self._socket.close()
