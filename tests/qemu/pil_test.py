#!/usr/bin/python3
"""The qemu tier's processor-in-the-loop test: runs the Cortex-M4F image (firmware/cortex_m/pil)
on QEMU's mps2-an386 and compares its summary with the host build's float run of the same
scenario (drive_sim, drive.precision=float).

usage: pil_test.py --elf FILE --drive-sim FILE --scenario FILE --work DIR [--seeds N]
                   [--controller NAME] [--cycles-per-instruction C] [--max-tick-share S]
                   [--stack-report FILE]

The image runs the compiled-in scenario of the same name as FILE's stem; --controller changes
its law (and the host's) to NAME.

The tolerance. The MCU and the host compute the same float control law with different rounding
(the MCU fuses multiply-adds, its atan2f and sqrtf are newlib's), and the plant's ADC and
encoder quantize: a last-bit difference flips one quantization decision, after which the two runs
are two realizations of the same closed loop under the same noise statistics, not one
trajectory. So the host is run again with N other ADC noise seeds, and each metric of the MCU
must lie within 5 standard deviations of that seed-to-seed spread from the host's run of the
scenario's own seed. For two independent draws the difference has sqrt(2) sd: 5 sd is 3.5 sd of
the difference, about 5e-4 two-sided per metric. The start-up (calibration, magnetizing) has no
spread; running_from_s must match within 2 ticks.

Also checked: the run completed (exit status 0: no fault, no overrun), every tick ran, and the
control path's instructions per tick (QEMU -icount shift=0: 1 ns of virtual time per
instruction), to the PWM write and for the whole control stage, are printed, the whole one as a
share of the scenario's period (the host's simulated time over
its ticks) on the STM32G431's 170 MHz core at C cycles per instruction (default 1). With
--max-tick-share S the whole tick's mean must be at most S of the period: S * period * 170 MHz / C
instructions. The image's measurement of a float recompute of the exact discretization (its
`pil recompute` line) must be present, take time, and fit inside the stack its probe paints;
its cost is printed. With --stack-report FILE (tools/check_stack.py's report on the image), the
stack's high-water mark of the run must lie within the bound the build computed: a measured
use above it would prove the bound wrong.
"""
import argparse
import json
import re
import statistics
import subprocess
import sys
from pathlib import Path

METRICS = ["speed_rms_err_rad_s", "speed_max_err_rad_s", "flux2_rms_err_Wb2",
           "flux2_max_err_Wb2", "load_est_rms_err_Nm", "i_peak_A", "i_peak_total_A",
           "saturated_fraction"]
SD_LIMIT = 5.0
CORE_CLOCK_HZ = 170e6  # the STM32G431's (firmware/cortex_m/stm32g431)
QEMU_TIMEOUT_S = 600  # about 30 s on this machine's 2 cores
# The stack the recompute probe paints (kProbeBytes, firmware/cortex_m/pil/recompute_probe.hpp):
# a run that overflows it reads as exactly this size.
RECOMPUTE_PROBE_BYTES = 2048


def run_pil(elf, scenario, controller):
    # The image's options are its semihosting command line (firmware/cortex_m/pil/pil_options).
    args = f"arg=pil,arg=scenario={scenario}" + (f",arg=controller={controller}" if controller else "")
    cmd = ["qemu-system-arm", "-M", "mps2-an386", "-cpu", "cortex-m4", "-display", "none",
           "-monitor", "none", "-serial", "stdio", "-semihosting-config",
           f"enable=on,target=native,{args}", "-icount", "shift=0,sleep=off", "-kernel", str(elf)]
    print("pil_test: " + " ".join(cmd), flush=True)
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=QEMU_TIMEOUT_S)
    sys.stdout.write(done.stdout)
    sys.stderr.write(done.stderr)
    fields = {}
    for line in done.stdout.splitlines():
        words = line.split()
        if len(words) >= 3 and words[0] == "pil":
            if words[1] == "metric":
                fields[words[2]] = float(words[3])
            else:  # "pil <kind> name value name value ..."
                for name, value in zip(words[2::2], words[3::2]):
                    fields[f"{words[1]}.{name}"] = value
    return done.returncode, fields


def run_host(drive_sim, scenario, work, seed, controller):
    out = work / f"host_float_seed{seed}.json"
    law = ["--set", f"drive.controller={controller}"] if controller else []
    subprocess.run([str(drive_sim), str(scenario), "--set", "drive.precision=float",
                    "--set", f"simulation.seed={seed}", "--summary-json", str(out)] + law,
                   check=True, stdout=subprocess.DEVNULL)
    return json.loads(out.read_text())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--elf", required=True, type=Path)
    parser.add_argument("--drive-sim", required=True, type=Path)
    parser.add_argument("--scenario", required=True, type=Path)
    parser.add_argument("--work", required=True, type=Path)
    parser.add_argument("--seeds", type=int, default=16)
    parser.add_argument("--controller", default="")
    parser.add_argument("--cycles-per-instruction", type=float, default=1.0)
    parser.add_argument("--max-tick-share", type=float, default=None)
    parser.add_argument("--stack-report", type=Path, default=None)
    args = parser.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)

    failed = 0

    def check(ok, what, detail=""):
        nonlocal failed
        failed += 0 if ok else 1
        print(f"pil_test: {'ok  ' if ok else 'FAIL'} {what}{': ' + detail if detail else ''}")

    status, pil = run_pil(args.elf, args.scenario.stem, args.controller)
    check(status == 0 and pil.get("end.status") == "0", "the MCU run completed",
          f"exit {status}, fault {pil.get('fault.code')}, timer overruns "
          f"{pil.get('tick.timer_overruns')}")
    check(pil.get("start.controller") == (args.controller or pil.get("start.controller")),
          "the MCU ran the law asked for", f"{pil.get('start.controller')}")
    host = run_host(args.drive_sim, args.scenario, args.work, 1, args.controller)
    check(pil.get("tick.count") == str(host["ticks"]), "every tick ran",
          f"{pil.get('tick.count')} of {host['ticks']}")
    spread = [run_host(args.drive_sim, args.scenario, args.work, seed, args.controller)
              for seed in range(2, args.seeds + 2)]
    print(f"pil_test: {'metric':22s} {'MCU':>12s} {'host float':>12s} {'seed sd':>10s} {'|d|/sd':>7s}")
    for name in METRICS:
        sd = statistics.stdev([run[name] for run in spread])
        difference = abs(pil.get(name, float("nan")) - host[name])
        # No spread (a metric no seed changes, such as a law that never saturates): equal or not.
        ratio = difference / sd if sd > 0 else (0.0 if difference == 0 else float("inf"))
        print(f"pil_test: {name:22s} {pil.get(name, float('nan')):12.6g} {host[name]:12.6g} "
              f"{sd:10.3g} {ratio:7.2f}")
        check(ratio <= SD_LIMIT, f"{name} within {SD_LIMIT:g} sd of the host's float run")
    tick_s = host["simulated_s"] / host["ticks"]  # the scenario's period
    start_ticks = abs(pil.get("running_from_s", -1.0) - host["running_from_s"]) / tick_s
    check(start_ticks <= 2.0, "running from the same tick (within 2)",
          f"MCU {pil.get('running_from_s')} s, host {host['running_from_s']} s")

    mean, worst = int(pil.get("tick.exec_ns_mean", 0)), int(pil.get("tick.exec_ns_max", 0))
    whole, whole_worst = int(pil.get("tick.whole_ns_mean", 0)), int(pil.get("tick.whole_ns_max", 0))
    cpi = args.cycles_per_instruction
    us_per_instruction = cpi / CORE_CLOCK_HZ * 1e6
    period_us = tick_s * 1e6
    print(f"pil_test: tick up to the PWM write (sense to actuate): mean {mean} instructions, "
          f"max {worst}")
    # The processor's share is the whole control stage's: the work after the write runs in the
    # same interrupt, every tick.
    check(whole > mean, "the whole tick timed, longer than its part up to the PWM write",
          f"whole {whole}, to the write {mean}")
    print(f"pil_test: whole tick (the control stage): mean {whole} instructions, max "
          f"{whole_worst}; at {CORE_CLOCK_HZ / 1e6:g} MHz and {cpi:g} cycles per instruction "
          f"{whole * us_per_instruction:.1f} us mean, {whole_worst * us_per_instruction:.1f} us "
          f"max: {100 * whole * us_per_instruction / period_us:.1f} % and "
          f"{100 * whole_worst * us_per_instruction / period_us:.1f} % of the {period_us:g} us "
          "period")
    if args.max_tick_share is not None:
        budget = args.max_tick_share * tick_s * CORE_CLOCK_HZ / cpi
        check(0 < whole <= budget,
              f"mean whole tick within {100 * args.max_tick_share:g} % of the period",
              f"{whole} of {budget:.0f} instructions")
    # Each stage, from the ticks whose stages the drive timed (one in eight): counts of the
    # execution clock, in instructions (-icount shift=0: 1 ns per instruction).
    stages = ["sense", "estimate", "supervise", "law", "modulate", "protect", "actuate", "publish"]
    per_stage = []
    for stage in stages:
        counts = float(pil.get(f"stage_{stage}.mean_counts", "nan"))
        clock_Hz = float(pil.get(f"stage_{stage}.clock_Hz", "nan"))
        per_stage.append(f"{stage} {counts * 1e9 / clock_Hz:.0f}")
    print("pil_test: instructions per stage (timed ticks, each with one clock read): " +
          ", ".join(per_stage))

    # The float recompute of the discretization, measured by the image before its first tick.
    recompute_ns = int(pil.get("recompute.ns_mean", "-1"))
    recompute_stack = int(pil.get("recompute.stack_bytes", "-1"))
    check("recompute.ns_mean" in pil and recompute_ns > 0, "the recompute was timed",
          f"ns_mean {pil.get('recompute.ns_mean')}")
    check(0 < recompute_stack < RECOMPUTE_PROBE_BYTES,
          f"the recompute's stack within the probe's {RECOMPUTE_PROBE_BYTES} B",
          f"stack_bytes {pil.get('recompute.stack_bytes')}")
    print(f"pil_test: float recompute of the discretization: {recompute_ns} instructions, "
          f"{recompute_stack} B of stack, over {pil.get('recompute.runs')} runs")
    if args.stack_report is not None:
        first = args.stack_report.read_text().splitlines()[0]
        bound = re.search(r": (\d+) B of \d+ B reserved$", first)
        bound_bytes = int(bound[1]) if bound else -1
        used_bytes = int(pil.get("memory.stack_used_bytes", "-1"))
        check(0 < used_bytes <= bound_bytes, "the stack's high-water mark within the build's bound",
              f"{used_bytes} B used, bound {bound_bytes} B ({args.stack_report.name})")
    print(f"pil_test: {'passed' if failed == 0 else f'{failed} check(s) failed'}")
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
