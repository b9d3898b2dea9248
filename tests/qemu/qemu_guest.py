#!/usr/bin/python3
"""Boots one of Debian 12's own kernels under QEMU (TCG) with a busybox initramfs and runs a test
script in it: the `qemu` test tier, for SocketCAN (vcan) and GPIO (the PL061 of the aarch64 `virt`
machine) on real kernels rather than on the host's.

usage: qemu_guest.py --arch x86_64|aarch64 --cache DIR --work DIR --guest-script PATH
                     [--binary PATH ...] [--file SRC:GUEST_PATH ...] [--timeout-s S]
                     [--trace-pl061 FILE] [--memory-mb M] [--cpus N]

The kernel package (what linux-image-<debian arch> depends on) and, when the host's /bin/busybox
cannot run in the guest, busybox-static for the guest's architecture are fetched with
`apt-get download` once and cached under --cache, keyed by the package file's name: a new Debian
kernel is a new file name, so it is fetched on the first run after `apt-get update` sees it.

The guest's /init mounts proc, sys, dev, debugfs (/sys/kernel/debug) and a tmpfs on /tmp, loads
can, can-dev, can-raw and vcan, brings vcan0 up, then runs the guest script as /test.sh (cwd /,
stdin /dev/null, PATH with the busybox applets and the --binary programs in /bin) and powers off.
The script ships files to the host with `emit NAME FILE`; they land in --work/out/NAME.

Outputs in --work: console.log (kernel messages and the test's output; emitted files' base64 is
elided), qemu-stderr.log, initrd.gz, out/. --trace-pl061 FILE (aarch64 only) makes QEMU log every
PL061 output-pin level change to FILE with host wall-clock timestamps:
    <thread id>@<unix s>.<us>:pl061_set_output <device> setting output <pin> to <0|1>

Exit code: the guest script's (0 = pass); 1 if the guest never reached the end of the script
(timeout, kernel panic, QEMU exit) or an emitted file arrived damaged; 2 for setup errors (missing
tools or packages, bad arguments, the guest failing to load a module). Standard library only.
"""
import argparse
import os
import re
import selectors
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

# The parts of this script, beside it: running it puts its directory on sys.path. They must not
# import this file back: run as a script it is __main__, and a second copy would have its own
# classes and state.
from guest_arches import ARCHES
from guest_console import Console
from guest_initramfs import HARNESS_PATHS, build_initramfs, busybox_for, check_guest_program
from guest_packages import (SetupError, check_dpkg_architecture, check_module_dependencies,
                            fetch_package, find_kernel, kernel_file_wanted, module_bytes,
                            resolve_kernel_package)

# How long QEMU may take to exit after the end marker (poweroff -f is immediate; this is slack).
POWEROFF_GRACE_S = 15.0


# ----------------------------------------------------------------------------------------------
# Running QEMU and following its console


def qemu_command(arch, kernel, initrd, memory_mb, cpus, trace_file):
    spec = ARCHES[arch]
    command = [f"qemu-system-{arch}", *spec["qemu_args"],
               # TCG always: KVM is not on every CI machine and hangs on some that have it.
               "-accel", "tcg",
               "-m", str(memory_mb),
               # Multi-threaded TCG gives each guest CPU a host thread: a real-time loop pinned
               # to one guest CPU leaves the other to the rest of the guest.
               "-smp", str(cpus),
               # No default NIC, VGA, floppy...: less to probe at boot; the serial port is added
               # explicitly and is the guest's stdout, and the only output.
               "-nodefaults", "-no-user-config", "-display", "none", "-serial", "stdio",
               # The guest powering off, rebooting or panicking (panic=-1: reboot at once) ends
               # QEMU.
               "-no-reboot",
               "-kernel", str(kernel), "-initrd", str(initrd),
               # Not `quiet`: the whole boot log costs ~0.15 s on the emulated UART and is what
               # tells a broken boot apart; kernel messages during the test land in console.log too.
               "-append", f"console={spec['console']} panic=-1"]
    if trace_file:
        # The `log` trace backend writes one line per PL061 output pin that changes level;
        # -msg timestamp=on adds <thread id>@<host wall-clock seconds.microseconds>: to each.
        command += ["-trace", "pl061_set_output", "-D", str(trace_file), "-msg", "timestamp=on"]
    return command


def run_guest(command, console, stderr_path, timeout_s):
    """Runs QEMU until it exits or `timeout_s` passes; returns (QEMU's exit code or None if it was
    killed, whether the timeout struck)."""
    with open(stderr_path, "wb") as stderr:
        # stdin from /dev/null: QEMU must not take the terminal of whoever runs the tests.
        process = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                   stderr=stderr)
    try:
        return follow_guest(process, console, timeout_s)
    finally:
        # Also when this script is interrupted (Ctrl-C, or ctest's own timeout sending SIGTERM):
        # an orphaned QEMU would spin on a CPU core until its guest's script ended, if ever.
        if process.poll() is None:
            process.kill()
            process.wait()


def follow_guest(process, console, timeout_s):
    deadline = console.started + timeout_s
    timed_out = False
    with selectors.DefaultSelector() as selector:
        selector.register(process.stdout, selectors.EVENT_READ)
        while True:
            now = time.monotonic()
            if now >= deadline:
                # A timeout only counts as one while the guest still had work to do; after the
                # end marker it merely means QEMU did not exit (reported as a warning).
                timed_out = console.end_time is None and console.setup_failure is None
                break
            if not selector.select(timeout=deadline - now):
                continue
            data = os.read(process.stdout.fileno(), 65536)
            if not data:  # QEMU closed its stdout: it exited
                break
            console.feed(data)
            if console.end_time is not None or console.setup_failure is not None:
                # The guest is done and powering off: some slack, not the rest of the timeout.
                deadline = min(deadline, time.monotonic() + POWEROFF_GRACE_S)
    console.flush()
    try:
        # Closing stdout comes a moment before the exit itself; a hung QEMU gets the grace time.
        return process.wait(timeout=0 if timed_out else POWEROFF_GRACE_S), timed_out
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
        return None, timed_out


# ----------------------------------------------------------------------------------------------
# The PL061 trace, for the tests that read it (import qemu_guest; qemu_guest.read_pl061_trace(...))

PL061_TRACE_RE = re.compile(
    r"^(?:\d+@(\d+\.\d+):)?pl061_set_output (\S+) setting output (\d) to ([01])$")


def read_pl061_trace(path):
    """The pin level changes in a --trace-pl061 file, as (host time s, pin, level) in file order.

    QEMU logs a pin only when its level changes: first all 8 pins at 0 when the machine resets
    (virt pulls every line down; an input reads as 0 here), then every change the guest causes.
    A pin's level is its GPIODATA bit while GPIODIR makes it an output, else 0. The time is the
    host's wall clock (gettimeofday, microseconds) when QEMU's vCPU thread performed the write,
    not the guest's clock; under TCG intervals agree with the guest's to a fraction of a
    millisecond on an idle host, but a loaded host stretches them."""
    changes = []
    for line in Path(path).read_text().splitlines():
        match = PL061_TRACE_RE.match(line)
        if match:
            time_s = float(match.group(1)) if match.group(1) else None
            changes.append((time_s, int(match.group(3)), int(match.group(4))))
    return changes


# ----------------------------------------------------------------------------------------------


def parse_arguments():
    paragraphs = __doc__.split("\n\n")  # the usage paragraph is argparse's to write
    parser = argparse.ArgumentParser(description=paragraphs[0],
                                     epilog="\n\n".join(paragraphs[2:]),
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--arch", required=True, choices=sorted(ARCHES))
    parser.add_argument("--cache", required=True, type=Path,
                        help="where the Debian packages are kept between runs")
    parser.add_argument("--work", required=True, type=Path,
                        help="this run's directory: initrd.gz, console.log, out/")
    parser.add_argument("--guest-script", required=True, type=Path,
                        help="shell script run in the guest as /test.sh; its exit code is ours")
    parser.add_argument("--binary", action="append", default=[], type=Path,
                        help="program copied to the guest's /bin (repeatable)")
    parser.add_argument("--file", action="append", default=[], metavar="SRC:GUEST_PATH",
                        help="file or directory copied to GUEST_PATH (absolute; repeatable)")
    parser.add_argument("--timeout-s", type=float, default=110.0,
                        help="wall-clock limit for the whole boot and test (default 110)")
    parser.add_argument("--trace-pl061", type=Path, metavar="FILE",
                        help="aarch64: QEMU logs the PL061's output pin changes to FILE")
    parser.add_argument("--memory-mb", type=int, default=512)
    parser.add_argument("--cpus", type=int, default=1, help="guest CPUs (default 1)")
    return parser.parse_args()


def prepare(args):
    """Everything before QEMU starts; raises SetupError. Returns the QEMU command."""
    arch = args.arch
    if args.trace_pl061 and arch != "aarch64":
        raise SetupError("--trace-pl061 needs --arch aarch64 (only the virt machine has a PL061)")
    if shutil.which(f"qemu-system-{arch}") is None:
        raise SetupError(f"qemu-system-{arch} is not on the PATH: run tools/install_deps.sh --qemu")
    if not args.guest_script.is_file():
        raise SetupError(f"--guest-script {args.guest_script}: no such file")
    files = []
    for spec in args.file:
        source, sep, guest_path = spec.partition(":")
        if not sep or not guest_path.startswith("/") or not Path(source).exists():
            raise SetupError(f"--file {spec}: expected SRC:GUEST_PATH with an existing SRC and an "
                             f"absolute GUEST_PATH")
        # The harness's own files would be replaced (the archive's last entry for a path wins).
        if guest_path.rstrip("/") in HARNESS_PATHS:
            raise SetupError(f"--file {spec}: {guest_path} belongs to qemu_guest.py")
        files.append((Path(source), guest_path))
    for binary in args.binary:
        if not binary.is_file():
            raise SetupError(f"--binary {binary}: no such file")
        if f"/bin/{binary.name}" in HARNESS_PATHS:
            raise SetupError(f"--binary {binary}: /bin/{binary.name} belongs to qemu_guest.py")
        check_guest_program(binary, arch, shipped_paths(files))

    args.cache.mkdir(parents=True, exist_ok=True)
    check_dpkg_architecture(ARCHES[arch]["debian"])
    package = resolve_kernel_package(args.cache.resolve(), ARCHES[arch]["debian"])
    tree = fetch_package(package, args.cache.resolve(), kernel_file_wanted)
    kernel, module_paths = find_kernel(tree, package)
    modules = {name: module_bytes(path) for name, path in module_paths.items()}
    check_module_dependencies(modules)
    busybox = busybox_for(arch, args.cache.resolve())

    work = args.work.resolve()
    work.mkdir(parents=True, exist_ok=True)
    shutil.rmtree(work / "out", ignore_errors=True)  # no stale files from an earlier run
    (work / "out").mkdir()
    initrd = work / "initrd.gz"
    build_initramfs(initrd, busybox, modules, args.guest_script, args.binary, files)
    trace = None
    if args.trace_pl061:
        trace = args.trace_pl061.resolve()
        trace.parent.mkdir(parents=True, exist_ok=True)
        trace.unlink(missing_ok=True)
    print(f"qemu_guest: {arch} guest, kernel {kernel.name} ({package}), busybox {busybox}",
          flush=True)
    return qemu_command(arch, kernel, initrd, args.memory_mb, args.cpus, trace)


def report(args, console, qemu_code, timed_out, total_s, stderr_path):
    """Prints the timings and the verdict; returns the exit code."""
    def seconds(value):
        return "-" if value is None else f"{value:.2f}"
    test_s = (console.end_time - console.start_time
              if console.end_time is not None and console.start_time is not None else None)
    uptime = console.guest_uptime_at_start
    print(f"qemu_guest: boot-to-start {seconds(console.start_time)} s"
          f" (guest uptime {seconds(uptime)} s), test {seconds(test_s)} s,"
          f" total {seconds(total_s)} s,"
          f" guest exit code {'-' if console.exit_code is None else console.exit_code}")
    for name in console.emitted:
        print(f"qemu_guest: emitted {args.work / 'out' / name}")

    def fail_with_tail(code, message):
        # The verdict comes last, where whoever reads a ctest log looks first.
        stderr_text = stderr_path.read_text(errors="replace").strip()
        if stderr_text:
            print(f"--- QEMU's stderr ({stderr_path}) ---\n{stderr_text}", file=sys.stderr)
        print(f"--- last {len(console.tail)} console lines ({args.work / 'console.log'}) ---\n"
              + "\n".join(console.tail) + "\n---", file=sys.stderr)
        print(f"qemu_guest: FAILED: {message}", file=sys.stderr)
        return code

    if console.setup_failure is not None:
        return fail_with_tail(2, f"guest setup failed before the test: {console.setup_failure}")
    if console.exit_code is None:
        if timed_out:
            phase = ("booting (no start marker)" if console.start_time is None
                     else "running the test")
            return fail_with_tail(1, f"timeout: no end marker after {args.timeout_s:g} s, while "
                                     f"{phase}; QEMU killed")
        if qemu_code not in (None, 0) and not console.tail:
            return fail_with_tail(2, f"QEMU exited with code {qemu_code} before the guest printed "
                                     f"anything (bad QEMU option or kernel?)")
        if console.panic is not None:
            return fail_with_tail(1, f"crash: {console.panic}")
        return fail_with_tail(1, f"crash: QEMU exited (code {qemu_code}) before the end marker "
                                 f"(the guest powered off or rebooted)")
    if console.damaged:
        return fail_with_tail(1, "emitted file(s) damaged: " + "; ".join(console.damaged))
    if console.exit_code != 0:
        return fail_with_tail(console.exit_code, f"guest script exited with {console.exit_code}")
    if qemu_code is None:
        print("qemu_guest: warning: QEMU did not exit after the guest powered off; killed it",
              file=sys.stderr)
    print("qemu_guest: PASSED")
    return 0


def shipped_paths(files):
    """The guest paths of the files shipped, those inside a shipped directory included."""
    paths = set()
    for source, guest_path in files:
        paths.add(guest_path)
        if source.is_dir():
            root = guest_path.rstrip("/")
            paths.update(f"{root}/{p.relative_to(source)}" for p in source.rglob("*"))
    return paths


def main():
    # Our lines and QEMU's console tail interleave with stderr in ctest's log: keep them in order.
    sys.stdout.reconfigure(line_buffering=True)
    # SIGTERM unwinds like Ctrl-C does, through run_guest's clean-up that stops QEMU.
    def terminated(signum, frame):
        print(f"qemu_guest: terminated by signal {signum}; stopping QEMU", file=sys.stderr)
        sys.exit(128 + signum)
    signal.signal(signal.SIGTERM, terminated)
    args = parse_arguments()
    try:
        command = prepare(args)
    except SetupError as error:
        print(f"qemu_guest: setup error: {error}", file=sys.stderr)
        return 2
    work = args.work.resolve()
    started = time.monotonic()
    console = Console(work / "console.log", work / "out", started)
    stderr_path = work / "qemu-stderr.log"
    (work / "qemu-command.txt").write_text(" ".join(command) + "\n")
    try:
        qemu_code, timed_out = run_guest(command, console, stderr_path, args.timeout_s)
    except FileNotFoundError as error:
        print(f"qemu_guest: setup error: {error}", file=sys.stderr)
        return 2
    total_s = time.monotonic() - started
    console.log.close()
    return report(args, console, qemu_code, timed_out, total_s, stderr_path)


if __name__ == "__main__":
    sys.exit(main())
