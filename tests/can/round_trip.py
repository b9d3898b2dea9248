#!/usr/bin/env python3
"""CAN round trip: a simulated run's CAN log, decoded by drive_monitor into CSV, matches the
simulator's own CSV within the telemetry scaling; and a DBC decoder this project did not write
(candied, through tools/dbc_check/run.sh) decodes the same log to the same values.

usage: round_trip.py DRIVE_SIM DRIVE_MONITOR SOURCE_DIR WORK_DIR
Standard library only. Exits 1 with the first mismatches listed."""
import csv
import math
import subprocess
import sys
from pathlib import Path

# monitor column -> (sim column, telemetry scale): the signal's resolution in messages.hpp.
PAIRS = {
    "speed_rad_s": ("omega_est_rad_s", 0.01),
    "speed_ref_rad_s": ("omega_ref_cmd_rad_s", 0.01),
    "flux2_Wb2": ("flux2_ctrl_est_Wb2", 1e-4),
    "flux2_ref_Wb2": ("flux2_ctrl_ref_Wb2", 1e-4),
    "iA_A": ("iA_est_A", 0.01),
    "iB_A": ("iB_est_A", 0.01),
    "load_Nm": ("load_est_Nm", 0.01),
    "v_bus_V": ("v_bus_meas_V", 0.1),
    "u_alpha_V": ("u_alpha_cmd_V", 0.1),
    "u_beta_V": ("u_beta_cmd_V", 0.1),
}
# candied's (message, signal) -> monitor column.
CANDIED = {
    ("telemetry_speed_flux", "speed_rad_s"): "speed_rad_s",
    ("telemetry_speed_flux", "speed_ref_rad_s"): "speed_ref_rad_s",
    ("telemetry_speed_flux", "flux2_Wb2"): "flux2_Wb2",
    ("telemetry_speed_flux", "flux2_ref_Wb2"): "flux2_ref_Wb2",
    ("telemetry_current", "iA_A"): "iA_A",
    ("telemetry_current", "iB_A"): "iB_A",
    ("telemetry_current", "load_Nm"): "load_Nm",
    ("telemetry_current", "v_bus_V"): "v_bus_V",
    ("telemetry_voltage", "u_alpha_V"): "u_alpha_V",
    ("telemetry_voltage", "u_beta_V"): "u_beta_V",
}


def run(args):
    result = subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        sys.exit(f"round_trip: {' '.join(map(str, args))} failed ({result.returncode}):\n"
                 f"{result.stderr}")


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(row for row in f if not row.startswith("#")))


def tick_of(time_s):
    return round(float(time_s) / 1e-4)


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    drive_sim, drive_monitor, source, work = sys.argv[1:]
    source, work = Path(source), Path(work)
    work.mkdir(parents=True, exist_ok=True)
    log, sim_csv, mon_csv, candied_csv = (work / n for n in
                                          ("run.log", "sim.csv", "monitor.csv", "candied.csv"))
    run([drive_sim, source / "hal_sim/scenarios/seed000_can.toml", "--duration-s", "1.0",
         "--csv", sim_csv, "--can-log", log])
    run([drive_monitor, "watch", "--log", log, "--csv", mon_csv, "--no-table"])

    sim = {tick_of(r["t_s"]): r for r in read_csv(sim_csv)}
    monitor = read_csv(mon_csv)
    # 1 s at the scripted rates: 100 Hz until 0.5 s, then 1000 Hz. One sample either way: the
    # tick the rate changes on may or may not coincide with a sample of the old rate.
    expected_rows = 50 + 500
    if abs(len(monitor) - expected_rows) > 1:
        sys.exit(f"round_trip: {len(monitor)} telemetry samples decoded, expected {expected_rows}")
    errors, checked = [], 0
    for row in monitor:
        k = tick_of(row["time_s"])
        if k not in sim:
            errors.append(f"t = {row['time_s']} s: no such tick in the simulator's CSV")
            continue
        for column, (sim_column, scale) in PAIRS.items():
            sent, got = float(sim[k][sim_column]), float(row[column])
            # Half a step of the signal's scale, plus the single-precision packing (2^-23 of the
            # value) and the CSV's printed digits (1e-9 relative).
            bound = 0.5 * scale + abs(sent) * (2.0 ** -23 + 1e-9) + 1e-12
            checked += 1
            if not abs(sent - got) <= bound:
                errors.append(f"t = {row['time_s']} s {column}: sim {sent}, decoded {got}, "
                              f"bound {bound:.3g}")
    print(f"round_trip: {len(monitor)} samples, {checked} values within the telemetry scale")

    run([source / "tools/dbc_check/run.sh", source / "docs/can/drive.dbc", log, "--csv",
         candied_csv])
    by_tick = {tick_of(r["time_s"]): r for r in monitor}
    compared = 0
    for row in read_csv(candied_csv):
        column = CANDIED.get((row["message"], row["signal"]))
        if column is None:
            continue
        mon = by_tick.get(tick_of(row["time_s"]))
        if mon is None:
            errors.append(f"candied decoded {row['message']} at {row['time_s']} s, "
                          f"drive_monitor has no sample there")
            continue
        a, b = float(row["value"]), float(mon[column])
        compared += 1
        if not math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-9):
            errors.append(f"t = {row['time_s']} s {column}: candied {a}, drive_monitor {b}")
    if compared < len(monitor) * len(CANDIED):
        errors.append(f"candied decoded {compared} telemetry values, expected "
                      f"{len(monitor) * len(CANDIED)}")
    print(f"round_trip: candied agrees with drive_monitor on {compared} values")
    if errors:
        print("\n".join(errors[:20]), file=sys.stderr)
        sys.exit(f"round_trip: {len(errors)} mismatches")


main()
