"""The log replay bus on the checked-in captures (tests/data/can) and on lines written here:
the end of a log, DROPCOUNT lines as Debian 12's candump writes them, nanosecond timestamps."""
import math
import threading

import pytest

import imdrive
from imdrive.logbus import parse_dropcount, parse_line

# Generous for reading a few lines: a replay that has not ended by then never will.
END_TIMEOUT_S = 5.0


def _in_thread(work):
    """Runs work() in a thread; its result, or a failure when it does not end (a daemon thread:
    the test run is not held up by one that hangs)."""
    result = []
    thread = threading.Thread(target=lambda: result.append(work()), daemon=True)
    thread.start()
    thread.join(END_TIMEOUT_S)
    assert not thread.is_alive(), f"still running after {END_TIMEOUT_S:g} s: the log never ends"
    return result[0]


def test_iteration_ends_at_the_end_of_the_log(source_dir):
    bus = imdrive.LogReplayBus(source_dir / "tests/data/can/shared_bus.log")
    messages = _in_thread(lambda: list(bus))
    assert len(messages) == 47 and bus.ended  # every frame line of the capture


def test_recv_without_timeout_returns_none_after_the_end(source_dir):
    bus = imdrive.LogReplayBus(source_dir / "tests/data/can/node2_only.log", node_id=1)
    # Every frame is another node's: recv(None) reads to the end and returns None.
    assert _in_thread(lambda: bus.recv(None)) is None
    assert bus.ended and bus.skipped == {"other_node": 7, "error_frame": 1}
    assert _in_thread(lambda: bus.recv(None)) is None  # and again, at once


def test_dropcount_names_candumps_argument_with_its_filters(tmp_path):
    """can-utils 2020.11.0 (Debian 12) writes the argument as given, filters included."""
    line = "DROPCOUNT: dropped 2 CAN frames on 'can0,020:7E0,7FF:7FF' socket (total drops 2)"
    assert parse_dropcount(line) == 2
    assert parse_dropcount("DROPCOUNT: dropped 1 CAN frame on 'any' socket (total drops 9)") == 1
    log = tmp_path / "filtered.log"
    log.write_text("(1700000000.000100) can0 022#0100000001000001 R\n" + line + "\n")
    bus = imdrive.LogReplayBus(log)
    assert len(list(bus)) == 1 and bus.dropped == 2
    with pytest.raises(ValueError, match="bad DROPCOUNT line"):
        parse_dropcount("DROPCOUNT: dropped 2 CAN frames on can0 socket (total drops 2)")


def test_nanosecond_timestamps_of_candump_n():
    micro = parse_line("(1700000000.000100) can0 022#0100000001000001")
    nano = parse_line("(1700000000.000100500) can0 022#0100000001000001")
    # 500 ns apart. A double near 1.7e9 s resolves one ulp, 2**-22 s (0.24 us); each time is
    # rounded by at most half of it, so their difference is within one ulp.
    assert nano.timestamp - micro.timestamp == pytest.approx(500e-9, abs=math.ulp(1.7e9))
    # Near 0 the nanoseconds themselves are kept.
    assert parse_line("(0.000000001) can0 022#00").timestamp == 1e-9
    for fraction in ("1234567", "12345", "1234567890"):
        with pytest.raises(ValueError, match="6 or 9 digits"):
            parse_line(f"(1700000000.{fraction}) can0 022#00")
