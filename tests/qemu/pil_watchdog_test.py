#!/usr/bin/python3
"""The qemu tier's watchdog test: the Cortex-M4F image (firmware/cortex_m/pil) on QEMU's
mps2-an386 with its control stage made to hang at 0.5 s (stall_at_ms=500). The CMSDK watchdog,
fed by the control stage only, must expire (its NMI records the cause), reset the board, and
the image must start again, report reset_cause watchdog in its first heartbeat, and run the
scenario to the end without the stall (which it skips after a watchdog reset).

usage: pil_watchdog_test.py --elf FILE
"""
import argparse
import subprocess
import sys

QEMU_TIMEOUT_S = 300  # about 6 s on this machine


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--elf", required=True)
    args = parser.parse_args()
    cmd = ["qemu-system-arm", "-M", "mps2-an386", "-cpu", "cortex-m4", "-display", "none",
           "-monitor", "none", "-serial", "stdio", "-semihosting-config",
           "enable=on,target=native,arg=pil,arg=duration_ms=1000,arg=stall_at_ms=500",
           "-icount", "shift=0,sleep=off", "-kernel", args.elf]
    print("pil_watchdog_test: " + " ".join(cmd), flush=True)
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=QEMU_TIMEOUT_S)
    lines = [line for line in done.stdout.splitlines() if line.startswith("pil ")]
    for line in lines:
        if not line.startswith(("pil stage_", "pil metric")):
            print(line)
    sys.stderr.write(done.stderr)
    expected = ["pil reset_cause power_on", "pil first_heartbeat reset_cause power_on",
                "pil watchdog expired: the board resets", "pil reset_cause watchdog",
                "pil first_heartbeat reset_cause watchdog", "pil end status 0"]
    at = 0
    for line in lines:  # in this order, other lines between
        if at < len(expected) and line == expected[at]:
            at += 1
    ok = done.returncode == 0 and at == len(expected)
    if not ok:
        missing = expected[at] if at < len(expected) else "(exit status 0)"
        print(f"pil_watchdog_test: FAIL: exit {done.returncode}, missing: {missing}")
        return 1
    print("pil_watchdog_test: passed: the stalled control stage ended in a watchdog reset, "
          "the first heartbeat after it said so, and the run completed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
