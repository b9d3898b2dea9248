"""The drive's start as the client sees it (imdrive/startup.py): restarts told from the heartbeat
counter and the start state, not from a version frame alone nor from a state_change the firmware
never sends; the alive counter learnt again after a restart; a drive on another protocol refused
by name."""
import pytest

import imdrive
from imdrive import frames, startup, table
from imdrive.errors import ProtocolMismatch

from fake_drive import FakeDrive


def _heartbeat(counter, state="running"):
    message = frames.encode_message("heartbeat", 1, counter=counter, state=state)
    return frames.FrameDecoder(1).decode(message)


def _version():
    message = frames.encode_message("version", 1, protocol_version=table.PROTOCOL_VERSION)
    return frames.FrameDecoder(1).decode(message)


def _restarts(frames_):
    detector = startup.RestartDetector()
    return [i for i, f in enumerate(frames_) if detector.feed(f)]


def test_a_running_drive_shows_no_restart():
    """600 heartbeats (two wraps of the 8-bit counter) with a version frame after every tenth,
    as firmware/telemetry.cpp sends them; also a version frame right before a wrap to 0."""
    sequence = []
    for n in range(600):
        sequence.append(_heartbeat(n % 256))
        if n % 10 == 9:
            sequence.append(_version())
    assert _restarts(sequence) == []
    assert _restarts([_heartbeat(255), _version(), _heartbeat(0, "idle")]) == []
    # Lost heartbeats make the counter jump ahead, which is no restart either.
    assert _restarts([_heartbeat(10), _heartbeat(60)]) == []


def test_a_start_is_a_restart_with_or_without_its_version_frame():
    assert _restarts([_heartbeat(200), _version(), _heartbeat(0, "calibrating")]) == [2]
    assert _restarts([_heartbeat(200), _heartbeat(0, "calibrating")]) == [1]
    # The start's first heartbeats lost: the counter went back (40 -> 3).
    assert _restarts([_heartbeat(40, "idle"), _heartbeat(3, "idle")]) == [1]
    # The first heartbeat the client ever sees is nothing to compare with.
    assert _restarts([_version(), _heartbeat(0, "calibrating")]) == []


def test_restart_is_seen_and_the_counter_learnt_again(fake_and_bus):
    """The fake restarts as the firmware does: a version frame, then heartbeats from counter 0
    in state calibrating, no state_change into it. After a start the drive has no counter
    reference and reports command_counter 0, so the client's next command must carry 1."""
    fake, bus = fake_and_bus
    with imdrive.Drive(bus, 1) as drive:
        drive.disable()
        drive.disable()
        assert [c for _, name, c in fake.arrivals] == [1, 2]  # learnt: command_counter 0 + 1
        fake.restart()
        drive.wait(lambda: drive.restarts == 1, 1.0, "no restart seen")
        fake.wait_idle()
        assert drive.disable().result == "accepted"
        assert fake.arrivals[-1][1:] == ("disable", 1)  # not 3: the counter was learnt again
        # The periodic version frame (every tenth heartbeat) is no restart.
        drive.wait_for_frame("version", timeout_s=1.5)
        drive.wait_heartbeat()
        assert drive.restarts == 1
        assert startup.firmware_text(drive.version) == "0.1.0+g1234abcd"


def test_a_drive_on_another_protocol_is_refused_by_name():
    import can
    channel = "imdrive-test-protocol"
    fake = FakeDrive(channel, protocol_version=table.PROTOCOL_VERSION + 1)
    fake.wait_idle()
    bus = can.Bus(interface="virtual", channel=channel)
    try:
        with imdrive.Drive(bus, 1) as drive:
            fake.restart()  # its first frame is the version frame
            drive.wait_for_frame("version", timeout_s=1.0)
            expected = (f"node 1 speaks protocol {table.PROTOCOL_VERSION + 1} \\(firmware "
                        f"0.1.0\\+g1234abcd\\), this client protocol {table.PROTOCOL_VERSION}: "
                        f"its frames would decode wrongly")
            with pytest.raises(ProtocolMismatch, match=expected):
                drive.disable()
            with pytest.raises(ProtocolMismatch):
                drive.wait_heartbeat()
        assert fake.arrivals == []  # nothing was sent to it
    finally:
        bus.shutdown()
        fake.close()
