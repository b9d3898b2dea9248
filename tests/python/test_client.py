"""imdrive.Drive against the fake drive on python-can's virtual bus: acknowledgements, the
rejection and timeout paths, the alive counter's resynchronization, telemetry, parameters,
identification and faults by name."""
import math

import pytest

import imdrive
from imdrive import CommandEncoder, CommandRejected, NoAnswer

# The fake's speed follows its reference with a 50 ms lag: after 1 s (20 time constants) it is
# within 30 * e^-20 of 30 rad/s; the telemetry's resolution is 0.01 rad/s. 0.05 rad/s holds both
# with margin, and is far from any speed a drive that ignored the command would show.
SPEED_TOLERANCE_RAD_S = 0.05


def test_accepted_command_returns_its_ack(fake_and_bus):
    fake, bus = fake_and_bus
    with imdrive.Drive(bus, 1) as drive:
        ack = drive.enable()
        assert ack.result == "accepted" and ack.message == "enable"
        assert fake.received[-1] == ("enable", "accepted")


def test_rejection_raises_with_the_result_name(fake_and_bus):
    fake, bus = fake_and_bus
    fake.refuse = "not_allowed"
    with imdrive.Drive(bus, 1) as drive:
        with pytest.raises(CommandRejected) as caught:
            drive.select_controller("iol")
    assert caught.value.result == "not_allowed"
    assert "select_controller controller=iol rejected: not_allowed" in str(caught.value)


def test_silent_drive_times_out(fake_and_bus):
    fake, bus = fake_and_bus
    with imdrive.Drive(bus, 1, answer_timeout_s=0.3) as drive:
        drive.disable()  # learns the counter from a heartbeat
        fake.silent = True
        with pytest.raises(NoAnswer, match="no command_ack for enable"):
            drive.enable()


def test_no_heartbeat_means_no_counter(fake_and_bus):
    fake, bus = fake_and_bus
    fake.silent = True
    with imdrive.Drive(bus, 1, answer_timeout_s=0.3) as drive:
        with pytest.raises(NoAnswer, match="no heartbeat"):
            drive.disable()


def test_value_out_of_range_is_refused_before_the_bus(fake_and_bus):
    fake, bus = fake_and_bus
    with imdrive.Drive(bus, 1) as drive:
        with pytest.raises(ValueError, match="set_speed.speed_ref_rad_s: 5000.0 rad/s is outside"):
            drive.set_speed(5000.0)
    assert not any(name == "set_speed" for name, _ in fake.received)


def test_counter_resynchronizes_after_another_host(fake_and_bus):
    """Another host moves the drive's counter reference 8 ahead: the client's next frame is
    stale, so it learns the counter from the next heartbeat and sends it again."""
    fake, bus = fake_and_bus
    with imdrive.Drive(bus, 1) as drive:
        drive.disable()
        other = CommandEncoder(1, first_counter=drive._encoder.next_counter)
        for step in (3, 3, 2):
            other.next_counter = (other.next_counter + step - 1) % 16
            bus.send(other.encode("clear_faults"))
            drive.wait_for_frame("command_ack", lambda a: a.result == "accepted")
        assert drive.clear_faults().result == "accepted"
    results = [r for _, r in fake.received]
    assert "stale_counter" in results and results[-1] == "accepted"


def test_speed_is_followed_and_read_back(fake_and_bus):
    fake, bus = fake_and_bus
    with imdrive.Drive(bus, 1) as drive:
        drive.enable()
        drive.set_speed(30.0)
        sample = drive.wait_for_sample(
            lambda s: abs(s.speed_rad_s - 30.0) < SPEED_TOLERANCE_RAD_S, timeout_s=3.0)
        assert sample.state == "running" and sample.speed_ref_rad_s == 30.0
        assert isinstance(sample, imdrive.TelemetrySample)
        drive.disable()
        assert drive.keep_alive.results["accepted"] > 0


def test_watchdog_fault_is_reported_by_name(fake_and_bus):
    fake, bus = fake_and_bus
    with imdrive.Drive(bus, 1) as drive:
        drive.enable()
        drive.wait_state("running", 2.0)
        drive.stop_keep_alive()
        hb = drive.wait_state("fault", 2.0)
        assert hb.first_fault == "command_timeout"
        assert imdrive.active_faults(hb) == ["command_timeout"]
        drive.clear_faults()
        assert drive.wait_state("idle", 1.0).first_fault == "none"


def test_emergency_stop_latches_its_fault(fake_and_bus):
    fake, bus = fake_and_bus
    with imdrive.Drive(bus, 1) as drive:
        drive.enable()
        drive.emergency_stop()
        assert drive.wait_state("fault", 1.0).first_fault == "emergency_stop"
        assert not drive.keep_alive.running


def test_parameters_read_write_save(fake_and_bus):
    fake, bus = fake_and_bus
    with imdrive.Drive(bus, 1) as drive:
        assert math.isnan(drive.read_parameters()["Rs_Ohm"])
        assert drive.write_parameter("Rs_Ohm", 14.0) == 14.0
        assert drive.read_parameter("Rs_Ohm") == 14.0
        drive.save_parameters()
        assert fake.saved
        with pytest.raises(imdrive.ParameterRefused, match="write Ls_H: not_positive"):
            drive.write_parameter("Ls_H", -1.0)
        with pytest.raises(ValueError, match="unknown value 'Rx_Ohm'"):
            drive.read_parameter("Rx_Ohm")


def test_identify_reports_progress_until_done(fake_and_bus):
    fake, bus = fake_and_bus
    steps = []
    with imdrive.Drive(bus, 1) as drive:
        last = drive.identify(progress=lambda f: steps.append(f.step), timeout_s=5.0)
    assert last.step == "done"
    assert steps.index("low_level") < steps.index("ramp_down") < steps.index("done")


def test_readme_example(fake_and_bus, source_dir):
    """The example of tools/python/README.md, run as it is written, on the fake drive."""
    fake, bus = fake_and_bus
    text = (source_dir / "tools/python/README.md").read_text()
    example = text.split("<!-- example -->")[1].split("```python")[1].split("```")[0]
    assert "drive.set_speed(30.0)" in example
    # The example opens SocketCAN can0; here the same code runs on the fake's virtual bus.
    example = example.replace('can.Bus(interface="socketcan", channel="can0")', "bus")
    namespace = {"bus": bus, "print": lambda *a: None}
    exec(compile(example, "README.md", "exec"), namespace)
    # 1 rad/s is the example's own bound (its predicate): the sample it printed is the first
    # that met it, with the drive running. The rest checks the commands it sent.
    sample = namespace["sample"]
    assert abs(sample.speed_rad_s - 30.0) < 1.0 and sample.state == "running"
    names = [name for name, _ in fake.received]
    assert names[:2] == ["enable", "set_speed"] and names[-1] == "disable"
    assert set(names) == {"enable", "set_speed", "disable"}  # the keep-alive repeats set_speed
    assert all(result == "accepted" for _, result in fake.received)


def test_enable_waits_for_the_end_of_the_offset_calibration():
    """A script started with the drive: its first heartbeat says calibrating, and enable then
    would be refused (not_allowed). enable() waits for the drive to leave calibrating."""
    import can
    from fake_drive import FakeDrive
    fake = FakeDrive("imdrive-test-calibrating")
    bus = can.Bus(interface="virtual", channel="imdrive-test-calibrating")
    try:
        with imdrive.Drive(bus, 1) as drive:
            assert drive.enable(keep_alive=False).result == "accepted"
            assert ("enable", "accepted") in fake.received
            assert ("enable", "not_allowed") not in fake.received
    finally:
        bus.shutdown()
        fake.close()


def test_enable_on_a_drive_stuck_calibrating_says_so():
    import can
    from fake_drive import FakeDrive
    fake = FakeDrive("imdrive-test-stuck")
    with fake._lock:
        fake.calibrated_at = float("inf")  # an ADC that never settles
    bus = can.Bus(interface="virtual", channel="imdrive-test-stuck")
    try:
        with imdrive.Drive(bus, 1) as drive:
            with pytest.raises(imdrive.NoAnswer, match="still calibrating"):
                drive.enable(keep_alive=False, calibration_timeout_s=0.3)
            assert not any(name == "enable" for name, _ in fake.received)
    finally:
        bus.shutdown()
        fake.close()
