"""The emergency stop goes out at once: with no heartbeat to learn the counter from, with the
keep-alive stuck waiting for one, and it is sent once more when no ack comes."""
import time

import pytest

import imdrive
from imdrive import CommandEncoder, NoAnswer

# How soon the fake must receive the stop after emergency_stop() is called. The virtual bus
# hands a frame to the fake's receive thread in well under a millisecond; 50 ms leaves room for
# the scheduler of a loaded two-core machine (ctest runs tests in parallel) and is still ten
# times less than the 0.5 s a wait for a heartbeat would take before the frame went out.
STOP_LATENCY_S = 0.05


def _stop_arrival(fake):
    return next(t for t, name, _ in fake.arrivals if name == "emergency_stop")


def test_stop_goes_out_at_once_with_no_heartbeat(fake_and_bus):
    """The client never learnt the counter and no heartbeat comes: the stop still goes out."""
    fake, bus = fake_and_bus
    fake.heartbeats = False
    with imdrive.Drive(bus, 1) as drive:
        called = time.monotonic()
        ack = drive.emergency_stop()
        assert _stop_arrival(fake) - called < STOP_LATENCY_S
        assert ack.result == "accepted"
    assert fake.state == "fault" and fake.first_fault == "emergency_stop"


def test_stop_does_not_wait_for_a_stuck_keep_alive(fake_and_bus):
    """Another host moves the drive's counter on, so the keep-alive's next frame is stale and it
    waits for a heartbeat to learn the counter again; the heartbeats are lost. The stop must
    neither wait for that thread nor for a heartbeat, and no keep-alive frame follows it."""
    fake, bus = fake_and_bus
    with imdrive.Drive(bus, 1) as drive:
        drive.enable()
        drive.wait_state("running", 1.0)
        fake.heartbeats = False
        with fake._lock:
            ahead = (fake.last_counter + 3) % 16  # the most the drive accepts in one step
        bus.send(CommandEncoder(1, first_counter=ahead).encode("clear_faults"))
        drive.wait(lambda: drive.keep_alive.results["stale_counter"] > 0, 1.0, "no stale frame")
        time.sleep(2 * drive.keep_alive.period_s)  # the keep-alive now waits for a heartbeat
        called = time.monotonic()
        ack = drive.emergency_stop()
        assert _stop_arrival(fake) - called < STOP_LATENCY_S
        assert ack.result == "accepted" and not drive.keep_alive.running
        assert fake.arrivals[-1][1] == "emergency_stop"
    assert fake.first_fault == "emergency_stop"


def test_stop_without_ack_is_sent_twice(fake_and_bus):
    fake, bus = fake_and_bus
    with imdrive.Drive(bus, 1, answer_timeout_s=0.2) as drive:
        fake.silent = True  # it still receives, but answers nothing
        with pytest.raises(NoAnswer, match="no command_ack for emergency_stop"):
            drive.emergency_stop()
    assert [name for _, name, _ in fake.arrivals] == ["emergency_stop"] * 2
    assert fake.first_fault == "emergency_stop"
