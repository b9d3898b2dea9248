#!/usr/bin/python3
"""The qemu tier's Python client test: boots Debian's x86_64 kernel (qemu_guest.py) with the
host build's drive_hil and its shared libraries (guest_programs.py), the host's Python
interpreter and python3-can (python_bundle.py) and the imdrive package, and checks that the
client, over vcan0, finds the drive idle, reads a parameter, enables it, sets a speed and sees
it held in telemetry, sees the command watchdog trip by name when it stops commanding, and an
emergency stop latched by name.

usage: python_test.py --bin-dir DIR --source-dir DIR --cache DIR --work DIR
"""
import argparse
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import guest_programs  # noqa: E402
import python_bundle  # noqa: E402

CHECKS = ["idle", "parameter_read", "speed", "watchdog_fault", "emergency_stop",
          "enable_refused_in_fault"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    for name in ("--bin-dir", "--source-dir", "--cache", "--work"):
        parser.add_argument(name, required=True, type=Path)
    args = parser.parse_args()
    hil = args.bin_dir / "drive_hil"
    if not hil.is_file():
        print(f"python_test: missing {hil}: the host build makes it (build/bin)")
        return 2
    started = time.monotonic()
    args.work.mkdir(parents=True, exist_ok=True)
    root = args.work / "python-root"
    tops = python_bundle.stage(root, args.source_dir / "tools/python")
    in_bundle = {f"/{p.relative_to(root)}" for p in root.rglob("*") if p.is_file()}
    try:
        binaries, libraries = guest_programs.stage([hil], args.work / "programs", in_bundle)
    except guest_programs.ShipError as error:
        print(f"python_test: {error}")
        return 2
    src = args.source_dir
    command = [sys.executable, str(HERE / "qemu_guest.py"), "--arch", "x86_64",
               "--cache", str(args.cache), "--work", str(args.work),
               "--guest-script", str(HERE / "guest_python.sh"), "--binary", str(binaries[0]),
               "--file", f"{HERE / 'python_guest.py'}:/hil/python_guest.py",
               "--file", f"{src / 'tests/qemu/hil.toml'}:/hil/tests/qemu/hil.toml",
               "--file", f"{src / 'hal_sim/motors/seed000.toml'}:/hil/hal_sim/motors/seed000.toml",
               # The guest's own limit, below ctest's (tests/qemu.cmake).
               "--timeout-s", "240", "--cpus", "2", "--memory-mb", "1024"]
    for top in tops:
        command += ["--file", f"{top}:/{top.name}"]
    for spec in libraries:
        command += ["--file", spec]
    guest = subprocess.run(command)
    out = args.work / "out"
    log = (out / "python.log").read_text() if (out / "python.log").is_file() else ""
    print("python_test: the client's output:\n" + log)
    if guest.returncode != 0:
        print(f"python_test: the guest run failed (qemu_guest.py exit {guest.returncode})")
        return 1
    passed = {line.split()[1] for line in log.splitlines()
              if line.startswith("check ") and line.split()[2] == "ok"}
    missing = [name for name in CHECKS if name not in passed]
    print(f"python_test: {len(CHECKS) - len(missing)} of {len(CHECKS)} checks passed "
          f"in {time.monotonic() - started:.0f} s" + (f"; failed: {missing}" if missing else ""))
    return 0 if not missing else 1


if __name__ == "__main__":
    sys.exit(main())
