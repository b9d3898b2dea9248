#!/usr/bin/env python3
"""drive_monitor over socketcand: the real drive_hil serves its bus over TCP (--can
socketcand:0, any free port, read back from the line it prints); `drive_monitor send
--socketcand` enables it at 30 rad/s and feeds its watchdog for 2 s, then `drive_monitor watch
--socketcand --csv` records 1 s of telemetry, in which the drive must hold that speed. No
kernel CAN socket anywhere.

The server takes one client at a time, so send and watch run one after the other. The machine
is shared and not real time (ctest runs tests in parallel on two cores), so drive_hil runs
under the normal scheduler (--priority 0) with margins that concern the host, not the link:
a 50 ms tick budget (a preempted tick would otherwise trip `overrun`) and a 5 s command
watchdog, which covers the gap from send's last frame through watch's second, however slowly
the two programs start. The control results do not depend on the pace: the simulated plant
advances one period per tick (docs/hil.md).

usage: monitor_over_socketcand.py DRIVE_HIL DRIVE_MONITOR SOURCE_DIR WORK_DIR
Standard library only. Exits 1 with what went wrong."""
import csv
import re
import subprocess
import sys
import threading
import time
from pathlib import Path

SPEED_rad_s = 30.0
# The bounds of tests/python/test_socketcand_hil.py, on the same scenario: there, over the
# same link, mean |error| 0.06-0.07 rad/s and the largest dip 0.55 rad/s (the scenario's 0/1 N m
# square-wave load, each step a dip the sliding-mode loop rejects). The watch starts about 2 s
# after the ramp (400 rad/s^2, 75 ms to 30 rad/s) has ended, so every row counts. The bounds
# leave about four times the measured error: a link that lost commands or telemetry misses
# them by far (a stopped drive is 30 rad/s off), a busy host does not. Speed resolution 0.01.
MEAN_ERROR_rad_s = 0.3
MAX_ERROR_rad_s = 2.0
# The link is judged by the drive's own sample counter (8 bits, wraps), not by rows per wall
# second: drive_hil keeps real time only when the host lets it (under ASan on a busy 2-core
# machine it ran at half speed and sent 47 samples in the watch's second, every one of them
# received). Fast telemetry is 100 Hz of the drive's time, so a watch of 1 s spans at most 100
# samples, well inside the counter's 256. The link may lose at most half of the samples the
# drive sent (TCP loses none; a link that drops telemetry misses this by far), and the drive
# must have sent at least MIN_SAMPLES: a tenth of real time, or the drive is not running.
MAX_LOST_SHARE = 0.5
MIN_SAMPLES = 10
START_TIMEOUT_S = 20.0  # drive_hil's start on a loaded machine (scenario, model, memory lock)


def fail(message):
    print(f"monitor_over_socketcand: {message}", file=sys.stderr)
    sys.exit(1)


def main(drive_hil, drive_monitor, source_dir, work_dir):
    work = Path(work_dir)
    work.mkdir(parents=True, exist_ok=True)
    hil = subprocess.Popen(
        [drive_hil, "hal_sim/scenarios/seed000_hil.toml", "--can", "socketcand:0", "--node", "1",
         "--priority", "0", "--set", "protection.tick_budget_us=50000",
         "--set", "protection.command_timeout_s=5"],
        cwd=source_dir, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    lines = []
    reader = threading.Thread(target=lambda: lines.extend(l.rstrip("\n") for l in hil.stderr),
                              daemon=True)
    reader.start()
    try:
        port = None
        deadline = time.monotonic() + START_TIMEOUT_S
        while port is None and time.monotonic() < deadline and hil.poll() is None:
            for line in list(lines):
                match = re.search(r"socketcand: listening on 127\.0\.0\.1:(\d+)", line)
                if match:
                    port = match.group(1)
            time.sleep(0.05)
        if port is None:
            fail("drive_hil printed no listening line:\n" + "\n".join(lines))
        address = f"127.0.0.1:{port}"

        send = subprocess.run(
            [drive_monitor, "send", "--socketcand", address, "--node", "1", "set-speed",
             str(SPEED_rad_s), "--enable", "--repeat-hz", "20", "--for-s", "2"],
            capture_output=True, text=True, timeout=30)
        if send.returncode != 0:
            fail(f"send exited {send.returncode}:\n{send.stdout}{send.stderr}")
        csv_path = work / "watch.csv"
        watch = subprocess.run(
            [drive_monitor, "watch", "--socketcand", address, "--node", "1", "--csv",
             str(csv_path), "--duration-s", "1", "--no-table"],
            capture_output=True, text=True, timeout=30)
        if watch.returncode != 0:
            fail(f"watch exited {watch.returncode}:\n{watch.stdout}{watch.stderr}")
        with csv_path.open() as f:
            rows = list(csv.DictReader(f))
        if not rows:
            fail("no telemetry row in 1 s")
        counters = [int(r["sample"]) for r in rows]
        sent = 1 + sum((b - a) % 256 for a, b in zip(counters, counters[1:]))
        if sent < MIN_SAMPLES or len(rows) < (1 - MAX_LOST_SHARE) * sent:
            fail(f"{len(rows)} telemetry rows in 1 s of {sent} samples the drive sent (samples "
                 f"{counters[0]} to {counters[-1]}): expected at least {MIN_SAMPLES} sent and "
                 f"at most {MAX_LOST_SHARE:.0%} lost")
        errors = [abs(float(r["speed_rad_s"]) - SPEED_rad_s) for r in rows]
        mean, worst = sum(errors) / len(errors), max(errors)
        states = {r["state"] for r in rows if r["state"]}
        faults = {r["first_fault"] for r in rows if r["first_fault"]} - {"none"}
        if states != {"running"} or faults:
            fail(f"drive not running throughout: states {states}, faults {faults}")
        if mean > MEAN_ERROR_rad_s or worst > MAX_ERROR_rad_s:
            fail(f"speed off {SPEED_rad_s} rad/s: mean |error| {mean:.3f} (at most "
                 f"{MEAN_ERROR_rad_s}), worst {worst:.3f} (at most {MAX_ERROR_rad_s})")
        print(f"{len(rows)} rows of {sent} samples sent, at {SPEED_rad_s} rad/s over {address}: "
              f"mean |error| {mean:.3f} rad/s, worst {worst:.3f} rad/s")
    finally:
        if hil.poll() is None:
            hil.terminate()
        try:
            hil.wait(timeout=15)
        except subprocess.TimeoutExpired:
            hil.kill()
            hil.wait()


if __name__ == "__main__":
    if len(sys.argv) != 5:
        fail("usage: monitor_over_socketcand.py DRIVE_HIL DRIVE_MONITOR SOURCE_DIR WORK_DIR")
    main(*sys.argv[1:])
