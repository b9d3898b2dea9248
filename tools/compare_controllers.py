#!/usr/bin/python3
"""The three control laws side by side: DSMC (paper 000), IOL with its speed loop on the
voltage inverter (paper 001) and IFOC (the classic drive), on the same cases.

    compare_controllers.py --drive-sim FILE --work DIR [--pil-elf FILE] [--results FILE]

Each case is a scenario written to DIR from hal_sim/scenarios/seed000_realistic.toml (the
paper-000 motor on the realistic board) with the changes of CASES, once per law; the IOL gets
the stator flux of the same rotor flux at no load, (Ls/Lm)^2 flux2, and the same speed-loop
bandwidth as the IFOC. drive_sim runs them (two at a time) with a CSV; from the CSV come the
q-current ripple and the load-step figures. With --pil-elf the Cortex-M4F image runs each law
(tests/qemu/pil_test.py's image) for the instructions per tick. The table goes into FILE
(default docs/results.md) between the markers of its section, the plot next to it.
Needs python3-numpy and python3-matplotlib.
"""
import argparse
import concurrent.futures
import copy
import json
import math
import pathlib
import subprocess
import sys
import tomllib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import imd_version  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
BASE = ROOT / "hal_sim/scenarios/seed000_realistic.toml"
LAWS = ["dsmc", "iol", "ifoc"]
BEGIN, END = "<!-- compare_controllers: begin -->", "<!-- compare_controllers: end -->"
TICK_S = 1e-4
RUNNING = 3  # the drive state's number (firmware/drive_state.hpp, the CAN protocol's)
LOAD_STEP_S = 1.5
RIPPLE_BAND_HZ = (1000.0, 5000.0)



def twice_base_speed():
    """Twice the base speed of the base scenario's motor and board: where the no-load stator
    voltage at the flux reference, i_d sqrt(Rs^2 + (w_e Ls)^2) with i_d = psi/Lm, reaches
    0.95 v_bus/sqrt(3) (tests/hal_sim/test_field_weakening.cpp, the same rule)."""
    doc = tomllib.loads(BASE.read_text())
    m = tomllib.loads((BASE.parent / doc["motor_file"]).read_text())["motor"]
    v_max = 0.95 * doc["inverter"]["v_bus_V"] / math.sqrt(3)
    i_d = math.sqrt(doc["reference"]["flux"]["flux2_Wb2"]) / m["Lm_H"]
    base = math.sqrt((v_max / i_d) ** 2 - m["Rs_Ohm"] ** 2) / m["Ls_H"] / m["pole_pairs"]
    return 2 * round(base)


TWICE_BASE_RAD_S = twice_base_speed()

# name: (what it shows, changes to the base scenario: {"table.key": value})
CASES = {
    "realistic": ("seed-000 realistic profile: sine to 100 rad/s, 1 N m square load", {}),
    "load_step": ("50 rad/s, load step 0 -> 2 N m at 1.5 s", {
        "reference.speed": {"kind": "steps", "times_s": [0.0], "values_rad_s": [50.0]},
        "drive.max_accel_rad_s2": 200.0,
        "load": {"kind": "steps", "times_s": [LOAD_STEP_S], "values_Nm": [2.0]},
        "simulation.duration_s": 3.0}),
    "slow_reversal": ("1 rad/s sine at 0.5 Hz: reversals through zero, 0.5 N m from 0.5 s", {
        "reference.speed": {"kind": "sine", "amplitude_rad_s": 1.0, "frequency_Hz": 0.5},
        "load": {"kind": "steps", "times_s": [0.5], "values_Nm": [0.5]},
        "simulation.duration_s": 4.0, "metrics.settle_s": 1.0}),
    "field_weakening": ("400 rad/s, 1.25 x base speed (100 rad/s^2 ramp), 0.3 N m load", {
        "reference.speed": {"kind": "steps", "times_s": [0.0], "values_rad_s": [400.0]},
        "drive.max_accel_rad_s2": 100.0,
        "load": {"kind": "steps", "times_s": [0.0], "values_Nm": [0.3]},
        "protection.overspeed_rad_s": 600.0,
        "simulation.duration_s": 6.0, "metrics.settle_s": 5.0}),
    "twice_base": (f"{TWICE_BASE_RAD_S} rad/s, 2 x base speed (ramp over 3 s), no load", {
        "reference.speed": {"kind": "steps", "times_s": [0.0], "values_rad_s": [TWICE_BASE_RAD_S]},
        "drive.max_accel_rad_s2": TWICE_BASE_RAD_S / 3.0,
        "load": {"kind": "steps", "times_s": [0.0], "values_Nm": [0.0]},
        "protection.overspeed_rad_s": 1.5 * TWICE_BASE_RAD_S,
        "simulation.duration_s": 6.0, "metrics.settle_s": 5.0}),
    "rotor_hot": ("realistic profile, plant Rr = 1.5 x the controller's", {
        "plant.Rr_Ohm": 1.5}),
    "rotor_cold": ("realistic profile, plant Rr = 0.6 x the controller's", {
        "plant.Rr_Ohm": 0.6}),
}


def set_key(doc, dotted, value):
    *tables, key = dotted.split(".")
    for t in tables:
        doc = doc.setdefault(t, {})
    doc[key] = value


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    return repr(float(v)) if isinstance(v, float) else str(v)


def toml_text(doc, prefix=""):
    lines, tables = [], []
    for key, value in doc.items():
        (tables if isinstance(value, dict) else lines).append((key, value))
    text = "".join(f"{k} = {toml_value(v)}\n" for k, v in lines)
    for key, value in tables:
        name = f"{prefix}{key}"
        if any(not isinstance(v, dict) for v in value.values()):
            text += f"\n[{name}]\n"
        text += toml_text(value, name + ".")
    return text


def scenario(case, law, motor):
    doc = tomllib.loads(BASE.read_text())
    doc["motor_file"] = str((BASE.parent / doc["motor_file"]).resolve())
    for dotted, value in CASES[case][1].items():
        if dotted == "plant.Rr_Ohm":
            value *= motor["Rr_Ohm"]  # a factor of the controller's
        set_key(doc, dotted, copy.deepcopy(value))
    drive = doc["drive"]
    drive["controller"] = law
    drive["torque_limit_Nm"] = torque_limit(doc, motor)
    if law == "iol":
        flux2 = doc["reference"]["flux"].pop("flux2_Wb2")
        doc["reference"]["flux"]["stator_flux2_Wb2"] = (motor["Ls_H"] / motor["Lm_H"]) ** 2 * flux2
        drive.update({"outer_speed_loop": True, "outer_flux_loop": True,
                      "flux_loop_time_constant_s": 0.02,
                      "speed_loop_bandwidth_rad_s": speed_bandwidth(doc)})
        drive.pop("speed_reaching_pole", None)
        drive.pop("flux_reaching_pole", None)
    return toml_text(doc)


def torque_limit(doc, motor):
    """The torque of the current limit at the flux reference, 3/2 p Lm/Lr psi i_q with
    |i| = 0.95 i_max: what the current allows, given to the speed loops that limit a torque."""
    flux = math.sqrt(doc["reference"]["flux"]["flux2_Wb2"])
    i_max = 0.95 * doc["inverter"]["i_max_A"]
    i_q = math.sqrt(max(i_max ** 2 - (flux / motor["Lm_H"]) ** 2, 0.0))
    return 1.5 * motor["pole_pairs"] * motor["Lm_H"] / motor["Lr_H"] * flux * i_q


def speed_bandwidth(doc):
    """The IFOC's speed-loop bandwidth rule (control/ifoc_design.hpp), given to the IOL too."""
    period = doc["drive"].get("sample_period_s", TICK_S)
    observer = doc.get("observers", {}).get("encoder_bandwidth_rad_s", 400.0)
    return min(2 * math.pi / (20 * period) / 10, observer / 4)


def run(drive_sim, work, case, law, motor):
    path = work / f"{case}.{law}.toml"
    path.write_text(scenario(case, law, motor))
    csv, summary = work / f"{case}.{law}.csv", work / f"{case}.{law}.json"
    done = subprocess.run([str(drive_sim), str(path), "--csv", str(csv), "--summary-json",
                           str(summary)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                          text=True)
    if done.returncode != 0 or not summary.exists():
        sys.exit(f"compare_controllers: {path} failed:\n{done.stderr}")
    return json.loads(summary.read_text()), csv


def q_current(d, pole_pairs):
    """The stator current across the true rotor flux, in the flux frame (A)."""
    angle = pole_pairs * d["theta_mech_rad"]
    c, s = np.cos(angle), np.sin(angle)
    i_a = c * d["i_alpha_A"] + s * d["i_beta_A"]  # rotor frame
    i_b = -s * d["i_alpha_A"] + c * d["i_beta_A"]
    flux = np.hypot(d["flux_A_Wb"], d["flux_B_Wb"])
    return (d["flux_A_Wb"] * i_b - d["flux_B_Wb"] * i_a) / np.maximum(flux, 1e-9)


def band_rms(x, band_hz):
    """RMS of the part of x in the band (one-sided spectrum, Parseval)."""
    spectrum = np.fft.rfft(x - np.mean(x))
    f = np.fft.rfftfreq(x.size, TICK_S)
    power = np.abs(spectrum) ** 2 * 2 / x.size ** 2
    power[-1] /= 2 if x.size % 2 == 0 else 1  # the Nyquist bin is not doubled
    return math.sqrt(power[(f >= band_hz[0]) & (f <= band_hz[1])].sum())


def limited_text(summary):
    """The run's last limitation: its reason and span, or "none"."""
    span = summary["limited"]
    if span is None:
        return "none"
    to = "end" if span["to_s"] is None else f"{span['to_s']:.2f} s"
    return f"{span['reason']}, {span['from_s']:.2f} s to {to}"


def analyse(summary, csv, pole_pairs, case):
    d = np.genfromtxt(csv, delimiter=",", names=True)
    after = d["t_s"] >= summary["settle_s"]
    error = d["omega_mech_rad_s"] - d["omega_ref_rad_s"]
    r = {"speed_rms": summary["speed_rms_err_rad_s"], "speed_max": summary["speed_max_err_rad_s"],
         "ripple": band_rms(q_current(d, pole_pairs)[after], RIPPLE_BAND_HZ),
         "saturated": summary["saturated_fraction"], "i_peak": summary["i_peak_A"],
         "i_ripple": summary["current_ripple_control_rms_A"], "v_ripple": summary["voltage_ripple_rms_V"],
         "faults": ", ".join(f["code"] for f in summary["faults"]) or "none",
         "limited": limited_text(summary),
         "speed": d["omega_mech_rad_s"], "ramp": d["omega_ref_cmd_rad_s"],
         "flux2": d["flux2_Wb2"], "limited_column": d["limited"],
         "law_ns": summary["stage_ns"]["law"], "tick_ns": summary["tick_exec_ns_mean"],
         # Plotted against the drive's own reference (after its ramp) while it runs.
         "t": d["t_s"], "error": np.where(d["state"] == RUNNING,
                                          d["omega_mech_rad_s"] - d["omega_ref_cmd_rad_s"], 0.0)}
    if case == "load_step":
        step = d["t_s"] >= LOAD_STEP_S
        r["dip"] = float(np.max(np.abs(error[step])))
        band = 0.02 * abs(d["omega_ref_rad_s"][step][0])
        outside = np.nonzero(np.abs(error[step]) > band)[0]
        r["recovery_s"] = 0.0 if outside.size == 0 else (outside[-1] + 1) * TICK_S
        r["band"] = band
    return r


def pil_instructions(elf, law):
    """Mean instructions per tick (sense to actuate) and in the law stage, on the MCU."""
    scenario_name = "seed001_realistic" if law == "iol" else "seed000_realistic"
    cmd = ["qemu-system-arm", "-M", "mps2-an386", "-cpu", "cortex-m4", "-display", "none",
           "-monitor", "none", "-serial", "stdio", "-semihosting-config",
           f"enable=on,target=native,arg=pil,arg=scenario={scenario_name},arg=controller={law}",
           "-icount", "shift=0,sleep=off", "-kernel", str(elf)]
    out = subprocess.run(cmd, capture_output=True, text=True, timeout=900).stdout
    fields = {}
    for line in out.splitlines():
        words = line.split()
        if len(words) >= 4 and words[0] == "pil" and words[1] != "metric":
            for name, value in zip(words[2::2], words[3::2]):
                fields[f"{words[1]}.{name}"] = value
    if fields.get("end.status") != "0":
        return scenario_name, math.nan, math.nan
    law_counts = float(fields["stage_law.mean_counts"]) * 1e9 / float(fields["stage_law.clock_Hz"])
    return scenario_name, float(fields["tick.exec_ns_mean"]), law_counts


def plot_twice_base(results, path):
    """Speed and rotor flux of each law on the step to twice the base speed; the time the
    drive reported itself limited is shaded."""
    fig, (speed, flux) = plt.subplots(2, 1, figsize=(10, 7), sharex=True, constrained_layout=True)
    for i, law in enumerate(LAWS):
        r = results["twice_base"][law]
        line, = speed.plot(r["t"], r["speed"], lw=1.0, label=f"{law} (limited: {r['limited']})")
        flux.plot(r["t"], r["flux2"], lw=0.8, color=line.get_color(), label=law)
        limited = r["limited_column"] > 0
        speed.fill_between(r["t"], i * 0.02, i * 0.02 + 0.02, where=limited, color=line.get_color(),
                           alpha=0.6, transform=speed.get_xaxis_transform(), step="mid")
    r = results["twice_base"][LAWS[-1]]
    speed.plot(r["t"], r["ramp"], "k--", lw=0.8, label="reference after the ramp")
    speed.set(ylabel="speed [rad/s]", title=CASES["twice_base"][0] + " (bars: limited)")
    flux.set(xlabel="t [s]", ylabel="rotor flux^2 [Wb^2]")
    speed.legend(loc="lower right", fontsize=8)
    flux.legend(loc="upper right", fontsize=8)
    fig.savefig(path, dpi=80)


def plot(results, path):
    fig, axes = plt.subplots(4, 2, figsize=(12, 13), constrained_layout=True)
    for ax in axes.flat[len(CASES):]:
        ax.axis("off")
    for ax, case in zip(axes.flat, CASES):
        for law in LAWS:
            r = results[case][law]
            ax.plot(r["t"], r["error"], lw=0.7, label=law)
        ax.set(title=CASES[case][0], xlabel="t [s]",
               ylabel="speed - ramped reference [rad/s]")
        limit = max(3 * max(results[case][law]["speed_rms"] for law in LAWS), 0.5)
        ax.set_ylim(-limit, limit)
        ax.legend(loc="upper right", fontsize=8)
    fig.savefig(path, dpi=80)


def table(results, pil):
    rows = ["| case | law | speed RMS [rad/s] | peak error [rad/s] | q ripple 1-5 kHz [A] "
            "| current ripple [A] | voltage ripple [V] | saturated | peak current [A] | faults "
            "| limited (last) |",
            "|---|---|---|---|---|---|---|---|---|---|---|"]
    for case in CASES:
        for law in LAWS:
            r = results[case][law]
            rows.append(f"| {case} | {law} | {r['speed_rms']:.3g} | {r['speed_max']:.3g} | "
                        f"{r['ripple']:.3g} | {r['i_ripple']:.3g} | {r['v_ripple']:.3g} | "
                        f"{r['saturated']:.3f} | {r['i_peak']:.2f} | "
                        f"{r['faults']} | {r['limited']} |")
    rows += ["", "Current and voltage ripple: the summary's control-rate ripple per phase, "
             "f_s/4..f_s/2 (docs/control.md); the q ripple is the 1-5 kHz band of the "
             "rotor-frame q current.", "", "Load step (50 rad/s, 0 -> 2 N m): the largest speed error after the step, and "
             "the time until the error stays within 2 % of the speed (0: it never left).", "",
             "| law | dip [rad/s] | recovery to 2 % [ms] |", "|---|---|---|"]
    for law in LAWS:
        r = results["load_step"][law]
        rows.append(f"| {law} | {r['dip']:.3g} | {1e3 * r['recovery_s']:.1f} |")
    rows += ["", "Tick cost. Host: mean time of the law stage and of the tick (sense to actuate) "
             "in double, the median over the cases (a shared machine: for comparison only). "
             "Cortex-M4F: mean instructions on the PIL run (QEMU mps2-an386, float)"
             + ("." if pil else ": not run (--no-pil)."), "",
             "| law | host law [ns] | host tick [ns] | M4F scenario | M4F tick | M4F law stage |",
             "|---|---|---|---|---|---|"]
    for law in LAWS:
        law_ns = np.median([results[c][law]["law_ns"] for c in CASES])
        tick_ns = np.median([results[c][law]["tick_ns"] for c in CASES])
        name, tick, law_counts = pil.get(law, ("-", math.nan, math.nan))
        rows.append(f"| {law} | {law_ns:.0f} | {tick_ns:.0f} | {name} | {tick:.0f} | "
                    f"{law_counts:.0f} |")
    return "\n".join(rows) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--drive-sim", required=True, type=pathlib.Path)
    parser.add_argument("--work", required=True, type=pathlib.Path)
    parser.add_argument("--pil-elf", type=pathlib.Path)
    parser.add_argument("--results", type=pathlib.Path, default=ROOT / "docs/results.md")
    imd_version.add_argument(parser)
    args = parser.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    motor_doc = tomllib.loads((BASE.parent / tomllib.loads(BASE.read_text())["motor_file"])
                              .read_text())["motor"]
    jobs = {(c, law): None for c in CASES for law in LAWS}
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
        for key in jobs:
            jobs[key] = pool.submit(run, args.drive_sim, args.work, *key, motor_doc)
        results = {c: {} for c in CASES}
        for (case, law), job in jobs.items():
            summary, csv = job.result()
            results[case][law] = analyse(summary, csv, motor_doc["pole_pairs"], case)
            print(f"compare_controllers: {case} {law}: speed RMS "
                  f"{results[case][law]['speed_rms']:.4g} rad/s", flush=True)
    pil = {law: pil_instructions(args.pil_elf, law) for law in LAWS} if args.pil_elf else {}
    image = args.results.parent / "img" / "compare_controllers.png"
    image.parent.mkdir(exist_ok=True)
    plot(results, image)
    twice_base = image.parent / "twice_base_speed.png"
    plot_twice_base(results, twice_base)
    section = (f"{BEGIN}\n`tools/compare_controllers.sh` writes this section and "
               f"[the plot](img/{image.name}).\n\n{table(results, pil)}\n"
               f"![speed error of each law in each case](img/{image.name})\n\n"
               f"The step to twice the base speed, [speed and flux](img/{twice_base.name}):\n\n"
               f"![speed and flux at twice the base speed](img/{twice_base.name})\n{END}")
    text = args.results.read_text()
    if BEGIN in text and END in text:
        text = text[:text.index(BEGIN)] + section + text[text.index(END) + len(END):]
    else:
        text += "\n## The three laws side by side\n\n" + section + "\n"
    args.results.write_text(text)
    print(f"compare_controllers: wrote {args.results} and {image}")


if __name__ == "__main__":
    main()
