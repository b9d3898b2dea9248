#!/usr/bin/env python3
"""Instructions per tick, by function, of the processor-in-the-loop image on QEMU.

The PIL image (drive_pil_mps2_an386.elf) runs a scenario twice under `-icount shift=0`: once to
--from-ms and once to --to-ms. QEMU's `-d in_asm,exec,nochain` log names every translated
block's instructions once and every execution of a block with its function; the difference of
the two runs' counts, per function, is what the ticks between the two times executed (the
start-up and the model build cancel). The simulated plant and board of the PIL image are in
the list too: on the board those are the motor and the peripherals' registers.

  tools/profile_pil.py build-cortex-m4f/bin/drive_pil_mps2_an386.elf --from-ms 300 --to-ms 400

The logs are parsed as they stream (a 100 ms window logs gigabytes), the two runs in parallel.
"""
import argparse
import collections
import concurrent.futures
import os
import re
import subprocess
import sys
import tempfile
import threading

import check_tick_path  # its objdump runner, for --classes

_TRACE = re.compile(rb"^\[[0-9a-f]+/([0-9a-f]+)/[0-9a-f]+/([0-9a-f]+)\] ?(.*)$")
_CF_COUNT_MASK = 0x1FF  # QEMU's instruction limit of a block in its cflags (0: none)
_INSN = re.compile(rb"^0x([0-9a-f]+):  ")
_ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..")) + "/"  # the project


def run_counts(elf, scenario, controller, duration_ms, lines_of=None):
    """Instructions executed per function (and per address of the functions lines_of
    matches) over a run of duration_ms, and the run's tick rate."""
    args = ["arg=pil", f"arg=scenario={scenario}", f"arg=duration_ms={duration_ms}"]
    if controller:
        args.append(f"arg=controller={controller}")
    with tempfile.TemporaryDirectory() as tmp, tempfile.TemporaryFile() as console:
        fifo = os.path.join(tmp, "log")
        os.mkfifo(fifo)
        qemu = subprocess.Popen(
            ["qemu-system-arm", "-M", "mps2-an386", "-cpu", "cortex-m4", "-display", "none",
             "-monitor", "none", "-serial", "stdio",
             "-semihosting-config", "enable=on,target=native," + ",".join(args),
             "-icount", "shift=0,sleep=off", "-d", "in_asm,exec,nochain", "-D", fifo,
             "-kernel", elf], stdout=console, stderr=subprocess.STDOUT)
        # QEMU may exit before it opens the log: open it then, so that the reader sees its end.
        threading.Thread(target=_release_fifo, args=(qemu, fifo), daemon=True).start()
        blocks = {}  # a block's start address -> its instructions' addresses (longest listing)
        executed = collections.Counter()  # a Trace line's "[.../pc/.../cflags] function" -> runs
        cut = collections.Counter()  # (Trace line, the I/O instruction it stopped at) -> times
        with open(fifo, "rb", buffering=1 << 20) as log:
            listing, last = None, None
            for line in log:
                if line.startswith(b"Trace "):
                    last = line[line.find(b"["):]  # parsed once per block below
                    executed[last] += 1
                elif line.startswith(b"Stopped execution") and last is not None:
                    executed[last] -= 1  # logged before it ran, then not run
                    last = None
                elif line.startswith(b"cpu_io_recompile: rewound") and last is not None:
                    # -icount: a device access mid-block; the block ran up to that instruction,
                    # which runs again, alone, and then the rest of the block as a new one.
                    cut[(last, int(line.split()[-1], 16))] += 1
                    last = None
                elif line.startswith(b"0x"):
                    m = _INSN.match(line)
                    if m is not None:
                        listing = listing if listing is not None else []
                        listing.append(int(m.group(1), 16))
                    continue
                if listing:  # a listing ends at the first other line
                    if len(listing) > len(blocks.get(listing[0], ())):
                        blocks[listing[0]] = listing  # a shorter copy: a limited retranslation
                listing = None
        qemu.wait()
        console.seek(0)
        out = console.read().decode(errors="replace")
    if "pil end status" not in out or "pil fault code none" not in out:
        sys.exit(f"profile_pil: the run to {duration_ms} ms failed:\n{out[-2000:]}")
    # The tick rate: the PIL clock's counts per period and its frequency.
    period = re.search(r"counts_per_period (\d+)", out)
    clock = re.search(r"clock_Hz (\d+)", out)
    if not period or not clock:
        sys.exit(f"profile_pil: the run to {duration_ms} ms printed no tick rate:\n{out[-2000:]}")
    rate_Hz = int(clock[1]) / int(period[1])
    per_function = collections.Counter()
    per_address = collections.Counter()  # of the functions that match lines_of
    counted = [(tail, n, None) for tail, n in executed.items()]
    counted += [(tail, -n, io_pc) for (tail, io_pc), n in cut.items()]
    for tail, n, io_pc in counted:
        function, addresses = _block(tail, blocks)
        if io_pc is not None:  # a cut run: take back what it did not execute
            addresses = addresses[addresses.index(io_pc):] if io_pc in addresses else []
        per_function[function] += n * len(addresses)
        if lines_of and lines_of.search(function):
            for pc in addresses:
                per_address[pc] += n
    return per_function, per_address, rate_Hz


def _block(tail, blocks):
    """The function of a Trace line and the instructions its block ran: the block's listing,
    cut to the count its cflags carry when QEMU limited it (-icount's budget)."""
    m = _TRACE.match(tail)
    if m is None:
        return "?", []
    function = m.group(3).strip().decode(errors="replace") or "?"
    addresses = blocks.get(int(m.group(1), 16), [])
    limit = int(m.group(2), 16) & _CF_COUNT_MASK
    return function, addresses[:limit] if limit else addresses


def _release_fifo(qemu, fifo):
    qemu.wait()
    try:  # a reader still waiting in open() gets a writer and then the end of the file
        os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
    except OSError:
        pass  # no reader waiting: it opened the log and reads to QEMU's end


def source_lines(elf, per_address):
    """Executions per source line: of each address, the innermost line in the project's own
    files (addr2line -i lists the inlining chain; a library header's line, an Eigen operator or
    std::min, is charged to the project line that inlined it)."""
    pcs = sorted(per_address)
    out = subprocess.run(["arm-none-eabi-addr2line", "-a", "-i", "-e", elf] +
                         [hex(pc) for pc in pcs], capture_output=True, text=True,
                         check=True).stdout.splitlines()
    chains, chain = [], None
    for line in out:
        if line.startswith("0x"):
            chain = []
            chains.append(chain)
        elif chain is not None:
            chain.append(line.split(" ")[0].replace(_ROOT, ""))
    per_line = collections.Counter()
    for pc, chain in zip(pcs, chains):
        own = [where for where in chain if not where.startswith(("/", "??"))]  # not libraries
        per_line[own[0] if own else (chain[0] if chain else "?")] += per_address[pc]
    return per_line


# What an instruction does, by its mnemonic (Thumb-2 and the FPv4 single-precision FPU), in
# the order tried: the arithmetic the tick needs, and what moves its values and chooses its path.
_CLASSES = [
    ("FP arithmetic",
     re.compile(r"^v(add|sub|n?mul|n?ml[as]|fn?m[as]|div|sqrt|neg|abs|cvt|cmpe?)(\.|$)")),
    ("FP load, store, move", re.compile(r"^v(ldr|str|ldm\w*|stm\w*|push|pop|mov|mrs|msr)")),
    ("load, store", re.compile(r"^(ldr|str|ldm|stm)[a-z]*(\.[nw])?$|^(push|pop)(\.w)?$")),
    ("branch", re.compile(r"^(b|bl|blx|bx)(eq|ne|cs|cc|hs|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|al)?"
                          r"(\.[nw])?$|^(cbn?z|tb[bh]|it[te]*)$")),
    ("compare", re.compile(r"^(cmp|cmn|tst|teq)(\.[nw])?$")),
    ("integer", re.compile(r".")),
]


def instruction_classes(elf, per_address):
    """Executions per instruction class (_CLASSES) of the addresses counted."""
    listing = check_tick_path.objdump("arm-none-eabi-objdump", "-d", "--no-show-raw-insn", elf)
    mnemonic = {}
    for m in re.finditer(r"^\s*([0-9a-f]+):\s+([a-z][a-z0-9.]*)", listing, re.M):
        mnemonic[int(m.group(1), 16)] = m.group(2)
    per_class = collections.Counter()
    for pc, n in per_address.items():
        name = mnemonic.get(pc, "?")
        per_class[next(c for c, rule in _CLASSES if rule.match(name))] += n
    return per_class


def demangle(names):
    try:
        out = subprocess.run(["c++filt"], input="\n".join(names), capture_output=True,
                             text=True, check=True).stdout.splitlines()
        return out if len(out) == len(names) else names
    except (OSError, subprocess.CalledProcessError):
        return names


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("elf")
    p.add_argument("--scenario", default="seed000_realistic")
    p.add_argument("--controller", default="", help="dsmc, ifoc or iol (the scenario's if empty)")
    p.add_argument("--from-ms", type=int, default=300)
    p.add_argument("--to-ms", type=int, default=400)
    p.add_argument("--top", type=int, default=40)
    p.add_argument("--lines", default="", help="a regex of (mangled) function names whose "
                   "instructions are also listed by source line")
    p.add_argument("--all", action="store_true", help="print every function and line")
    p.add_argument("--classes", action="store_true", help="also count the --lines functions' "
                   "instructions by kind: FP arithmetic, FP and integer loads, stores and "
                   "moves, branches, compares, other integer")
    a = p.parse_args()
    if a.to_ms <= a.from_ms:
        sys.exit("profile_pil: --to-ms must be after --from-ms")
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        lines_of = re.compile(a.lines) if a.lines else None
        (early, early_pc, _), (late, late_pc, rate_Hz) = pool.map(
            lambda ms: run_counts(a.elf, a.scenario, a.controller, ms, lines_of),
            (a.from_ms, a.to_ms))
    ticks = (a.to_ms - a.from_ms) * 1e-3 * rate_Hz
    diff = {f: (late[f] - early.get(f, 0)) / ticks for f in late}
    rows = sorted(((v, f) for f, v in diff.items() if v > 0), reverse=True)
    top = len(rows) if a.all else a.top
    names = demangle([f for _, f in rows[:top]])
    print(f"instructions per tick, {a.scenario} {a.controller or ''} "
          f"{a.from_ms}..{a.to_ms} ms ({ticks:.0f} ticks); total {sum(diff.values()):.0f}")
    for (v, _), name in zip(rows[:top], names):
        print(f"{v:9.1f}  {name[:150]}")
    if lines_of:
        per_pc = {pc: late_pc[pc] - early_pc.get(pc, 0) for pc in late_pc}
        per_line = source_lines(a.elf, {pc: n for pc, n in per_pc.items() if n > 0})
        print(f"\ninstructions per tick by source line, functions matching {a.lines!r} "
              f"({sum(per_line.values()) / ticks:.1f} in all)")
        for where, n in per_line.most_common(None if a.all else a.top):
            print(f"{n / ticks:9.1f}  {where}")
        if a.classes:
            per_class = instruction_classes(a.elf, {pc: n for pc, n in per_pc.items() if n > 0})
            total = sum(per_class.values())
            print(f"\ninstructions per tick by kind, functions matching {a.lines!r}")
            for kind, _ in _CLASSES:
                print(f"{per_class[kind] / ticks:9.1f}  {100 * per_class[kind] / total:5.1f} %"
                      f"  {kind}")


if __name__ == "__main__":
    main()
