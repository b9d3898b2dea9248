"""Runs in the qemu guest: the Python client commands drive_hil over vcan0 and prints one
"check NAME ok|FAIL DETAIL" line per check for python_test.py. Waits are wall-clock and
generous: the emulated guest runs the 10 kHz loop several times slower than real time."""
import can

import imdrive

SPEED_RAD_S = 30.0
# As hil_test.py argues for the same board and step: the speed is held to 0.08 rad/s RMS
# (docs/results.md), so the mean |error| of the settled samples must be within 1 rad/s, over
# ten times that and far from the 30 rad/s error of a drive that did not follow the step.
SPEED_TOLERANCE_RAD_S = 1.0
# 0.5 s of the drive's time at the 50 Hz telemetry set below: long enough to be settled, not
# a single lucky sample.
SETTLED_SAMPLES = 25


def check(name, ok, detail=""):
    print(f"check {name} {'ok' if ok else 'FAIL'} {detail}", flush=True)


def or_none(wait):
    """wait()'s result, or None when it ran out of time (the check that needed it fails)."""
    try:
        return wait()
    except imdrive.NoAnswer as error:
        print(f"# {error}", flush=True)
        return None


def settled_speed(drive):
    """The samples after the speed first came within the bound, SETTLED_SAMPLES of them."""
    first = or_none(lambda: drive.wait_for_sample(
        lambda s: abs(s.speed_rad_s - SPEED_RAD_S) < SPEED_TOLERANCE_RAD_S, 60.0))
    samples = []
    if first is not None:
        for sample in drive.samples(timeout_s=10.0):
            samples.append(sample)
            if len(samples) == SETTLED_SAMPLES:
                break
    return samples


def main():
    with can.Bus(interface="socketcan", channel="vcan0") as bus, \
            imdrive.Drive(bus, 1, answer_timeout_s=3.0) as drive:
        hb = or_none(lambda: drive.wait_state("idle", 60.0))
        check("idle", hb is not None and hb.first_fault == "none"
              and not imdrive.active_faults(hb), f"state {drive.state}, first fault {getattr(hb, 'first_fault', None)}")
        if hb is None:
            return
        drive.set_telemetry_rate(50)
        rs = drive.read_parameter("Rs_Ohm", wait_s=10.0)
        check("parameter_read", abs(rs - 14.0) < 1e-6, f"Rs_Ohm = {rs}")  # seed000.toml
        drive.enable()
        drive.wait_state("running", 60.0)
        drive.set_speed(SPEED_RAD_S)
        samples = settled_speed(drive)
        error = sum(abs(s.speed_rad_s - SPEED_RAD_S) for s in samples) / max(len(samples), 1)
        check("speed", len(samples) == SETTLED_SAMPLES and error < SPEED_TOLERANCE_RAD_S
              and all(s.state == "running" for s in samples),
              f"mean |speed - {SPEED_RAD_S:g}| = {error:.3f} rad/s over {len(samples)} samples, "
              f"states {sorted({s.state for s in samples})}")
        drive.stop_keep_alive()
        hb = drive.wait_state("fault", 60.0)
        check("watchdog_fault", hb.first_fault == "command_timeout",
              f"first_fault {hb.first_fault}, latched {imdrive.active_faults(hb)}")
        drive.clear_faults()
        drive.wait_state("idle", 60.0)
        drive.emergency_stop()
        hb = drive.wait_state("fault", 60.0)
        check("emergency_stop", hb.first_fault == "emergency_stop",
              f"first_fault {hb.first_fault}")
        try:
            drive.enable()
            check("enable_refused_in_fault", False, "accepted")
        except imdrive.CommandRejected as error:
            check("enable_refused_in_fault", error.result == "not_allowed", str(error))


if __name__ == "__main__":
    try:
        main()
    except imdrive.DriveError as error:
        check("client", False, f"{type(error).__name__}: {error}")
