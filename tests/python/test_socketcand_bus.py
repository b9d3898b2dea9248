"""SocketcandBus against a scripted socketcand server on loopback: the stream is cut at every
byte (the handshake too), frames that share a read with `< ok >` are kept, sends are in the
protocol's format, and the errors say what to do. Also the command line's bus opening."""
import errno
import socket
import threading

import can
import pytest

from imdrive import SocketcandBus
from imdrive.bus_open import BusOpenError, open_bus, parse_host_port, socketcan_error_text
from imdrive.cli import main
from imdrive.socketcand_bus import MessageReader, SocketcandError, format_send, parse_frame

FRAMES = b"< frame 030 1700000000.000100 0102 >< frame 021 1700000000.000200  >"


class ScriptedServer:
    """Accepts one client and plays `script`: each item is bytes to send (one byte per send
    when `trickle`), or a message to wait for (str)."""

    def __init__(self, script, trickle=False):
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.received = b""
        self.script, self.trickle = script, trickle
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        conn, _ = self.listener.accept()
        with conn:
            for item in self.script:
                if isinstance(item, str):
                    while item.encode() not in self.received:
                        data = conn.recv(4096)
                        if not data:
                            return
                        self.received += data
                elif self.trickle:
                    for i in range(len(item)):
                        conn.sendall(item[i:i + 1])
                else:
                    conn.sendall(item)
            while data := conn.recv(4096):  # until the client closes
                self.received += data

    def close(self):
        self.listener.close()


HANDSHAKE = [b"< hi >", "< open can0 >", b"< ok >", "< rawmode >"]


@pytest.mark.parametrize("trickle", [False, True], ids=["whole", "byte_by_byte"])
def test_handshake_and_frames_whatever_the_reads(trickle):
    server = ScriptedServer(HANDSHAKE + [b"< ok >" + FRAMES], trickle=trickle)
    with SocketcandBus("127.0.0.1", server.port) as bus:
        first, second = bus.recv(timeout=2.0), bus.recv(timeout=2.0)
        assert (first.arbitration_id, bytes(first.data)) == (0x30, b"\x01\x02")
        assert first.timestamp == pytest.approx(1700000000.0001)
        assert not first.is_extended_id
        assert (second.arbitration_id, second.dlc) == (0x21, 0)
        assert bus.recv(timeout=0.05) is None
    server.close()


def test_sends_frames_in_the_protocols_format():
    server = ScriptedServer(HANDSHAKE + [b"< ok >", "< send 7FF 0 >"])
    with SocketcandBus("127.0.0.1", server.port) as bus:
        bus.send(can.Message(arbitration_id=0x21, data=[1, 0xF1], is_extended_id=False))
        bus.send(can.Message(arbitration_id=0x7FF, data=[], is_extended_id=False))
    server.thread.join(timeout=2.0)  # the server reads until the client has closed
    assert b"< send 021 2 01 F1 >< send 7FF 0 >" in server.received
    server.close()
    assert format_send(can.Message(arbitration_id=0x1AAAAAAA, data=[1])) == \
        "< send 1AAAAAAA 1 01 >"
    with pytest.raises(can.CanOperationError):
        format_send(can.Message(arbitration_id=0x21, is_remote_frame=True, is_extended_id=False))


def test_server_errors_are_counted_and_kept():
    server = ScriptedServer(HANDSHAKE + [b"< ok >< error send: identifier '2G' is not hex >"
                                         + FRAMES])
    with SocketcandBus("127.0.0.1", server.port) as bus:
        assert bus.recv(timeout=2.0).arbitration_id == 0x30
        assert bus.errors_received == 1
        assert bus.server_errors[-1] == "send: identifier '2G' is not hex"
    server.close()


def test_a_busy_server_is_named():
    server = ScriptedServer([b"< error busy >"])
    with pytest.raises(SocketcandError, match="busy: another client is connected"):
        SocketcandBus("127.0.0.1", server.port)
    server.close()


def test_nothing_listening_says_what_to_start(capsys):
    with socket.create_server(("127.0.0.1", 0)) as probe:
        port = probe.getsockname()[1]  # free once closed
    with pytest.raises(SocketcandError) as caught:
        SocketcandBus("127.0.0.1", port)
    assert str(caught.value) == (f"no drive_hil at 127.0.0.1:{port}: connection refused; start "
                                 f"drive_hil --can socketcand:{port}")
    with pytest.raises(BusOpenError, match="no drive_hil at 127.0.0.1"):
        open_bus(socketcand=f"127.0.0.1:{port}")
    assert main(["send", "--socketcand", f"127.0.0.1:{port}", "enable"]) == 2
    assert f"imdrive: no drive_hil at 127.0.0.1:{port}: connection refused" in \
        capsys.readouterr().err


def test_reader_skips_garbage_and_bounds_an_endless_message():
    reader = MessageReader()
    reader.feed(b"junk< fra")
    assert reader.next() is None
    reader.feed(b"me 1 2 >< ok < echo >" + b"< " + b"x" * 300)
    assert reader.next() == "frame 1 2"
    assert reader.next() == "echo"  # '< ok' was cut short by the next '<'
    assert reader.next() is None
    assert reader.garbage == 3
    with pytest.raises(ValueError):
        parse_frame("frame 21 1.0 0")  # an odd number of hex digits


def test_reads_the_documented_frame_with_a_word_per_byte():
    # socketcand's doc/protocol.md shows this form; its server writes the contiguous one.
    message = parse_frame("frame 123 23.424242 11 22 33 44")
    assert message.arbitration_id == 0x123 and not message.is_extended_id
    assert bytes(message.data) == bytes([0x11, 0x22, 0x33, 0x44])
    assert message.timestamp == pytest.approx(23.424242)  # parsed from text: one rounding
    assert bytes(parse_frame("frame 21 1.0 1122").data) == b"\x11\x22"
    for bad in ("frame 21 1.0 1 2", "frame 21 1.0 11 2G", "frame 21 1.0 " + "11 " * 9):
        with pytest.raises(ValueError):
            parse_frame(bad)


def test_host_port_and_socketcan_errors():
    assert parse_host_port("29536") == ("127.0.0.1", 29536)
    assert parse_host_port("10.0.0.2:29536") == ("10.0.0.2", 29536)
    assert parse_host_port("[::1]:29536") == ("::1", 29536)
    # The forms drive_monitor refuses too (tests/hal/test_socketcand_client.cpp), same message.
    for bad in ("host:", ":5", "h:0", "h:70000", "h:12x", "h:+5", "h: 5", "0", "", "h:\u00b2"):
        with pytest.raises(BusOpenError) as caught:
            parse_host_port(bad)
        assert str(caught.value) == (f"--socketcand {bad}: expected PORT, HOST:PORT or "
                                     f"[V6]:PORT with a port in 1..65535, e.g. 127.0.0.1:29536")
    text = socketcan_error_text("vcan0", OSError(errno.EAFNOSUPPORT, "Address family not "
                                                 "supported by protocol"))
    assert "this kernel has no CAN support" in text
    assert "--socketcand 127.0.0.1:29536" in text and "modprobe vcan" in text
