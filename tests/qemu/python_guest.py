"""Runs in the qemu guest: the Python client commands drive_hil over vcan0 and prints one
"check NAME ok|FAIL DETAIL" line per check for python_test.py. Waits are wall-clock and
generous: the emulated guest runs the 10 kHz loop several times slower than real time."""
import can

import imdrive


def check(name, ok, detail=""):
    print(f"check {name} {'ok' if ok else 'FAIL'} {detail}", flush=True)


def main():
    with can.Bus(interface="socketcan", channel="vcan0") as bus, \
            imdrive.Drive(bus, 1, answer_timeout_s=3.0) as drive:
        drive.wait_state("idle", 60.0)
        check("idle", True, f"heartbeat state {drive.state}")
        drive.set_telemetry_rate(50)
        rs = drive.read_parameter("Rs_Ohm", wait_s=10.0)
        check("parameter_read", abs(rs - 14.0) < 1e-6, f"Rs_Ohm = {rs}")  # seed000.toml
        drive.enable()
        drive.wait_state("running", 60.0)
        drive.set_speed(30.0)
        # 1 rad/s: the bound hil_test.py uses for the settled step (its reasoning holds here).
        sample = drive.wait_for_sample(lambda s: abs(s.speed_rad_s - 30.0) < 1.0, 60.0)
        check("speed", True, f"{sample.speed_rad_s:.2f} rad/s, state {sample.state}")
        drive.stop_keep_alive()
        hb = drive.wait_state("fault", 60.0)
        check("watchdog_fault", hb.first_fault == "command_timeout",
              f"first_fault {hb.first_fault}, latched {imdrive.active_faults(hb)}")
        drive.clear_faults()
        drive.wait_state("idle", 60.0)
        drive.emergency_stop()
        hb = drive.wait_state("fault", 60.0)
        check("emergency_stop", hb.first_fault == "emergency_stop", f"first_fault {hb.first_fault}")
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
