#!/usr/bin/env python3
"""tools/profile_pil.py on the processor-in-the-loop image: two 10 ms windows of the realistic
scenario, 10..20 ms and 15..25 ms, both while the drive calibrates its ADC offsets (the first
256 ticks), by function and by source line.

What it checks, and why the bounds hold:
- Both windows count 100 ticks, and the tick's own function (its stages inlined) costs the
  same in both, within 5 %: every calibrating tick runs the same code. A subtraction that went
  wrong (a run's counts lost or taken twice) would put the 5 ms difference of the cumulative
  counts, about a quarter, between them.
- It lies between 50 instructions (a tick that only reads the ADC) and 5 000 (twice the 2 500
  the PIL timer measures for a running tick at most).
- The total is at least ten times the tick's function: the plant integrates in soft double,
  tens of thousands of instructions a tick, and it must be in the list.
- The source lines name the firmware's files: the image has its debug information.
- The instructions by kind (--classes) add up to those by source line, each of the six kinds and
  the total printed to a tenth (0.35 at most apart), and some are FP arithmetic (the bus voltage is scaled
  at every tick): every counted address was found in the disassembly and classified.

Usage: profile_pil_test.py --elf drive_pil_mps2_an386.elf
"""
import argparse
import os
import re
import subprocess
import sys

TOOL = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'tools',
                    'profile_pil.py')
HEAD_RE = re.compile(r'^instructions per tick, .* \((\d+) ticks\); total (\d+)$', re.M)
TICK_RE = re.compile(r'^\s*([\d.]+)\s+imd::firmware::Drive<float>::on_tick\(\)$', re.M)
LINE_RE = re.compile(r'^\s*[\d.]+\s+firmware/\S+\.(cpp|hpp):\d+$', re.M)
LINES_TOTAL_RE = re.compile(r'^instructions per tick by source line, .* \(([\d.]+) in all\)$', re.M)
KIND_RE = re.compile(r'^\s*([\d.]+)\s+[\d.]+ %  (.+)$', re.M)


def profile(elf, from_ms, to_ms, failures):
    """(ticks, total, on_tick) of one window, or None."""
    done = subprocess.run([sys.executable, TOOL, elf, '--from-ms', str(from_ms), '--to-ms',
                           str(to_ms), '--lines', 'imd8firmware', '--classes'],
                          capture_output=True, text=True, timeout=600)
    sys.stdout.write(done.stdout)
    sys.stderr.write(done.stderr)
    head, tick = HEAD_RE.search(done.stdout), TICK_RE.search(done.stdout)
    if done.returncode != 0 or not head or not tick:
        failures.append(f'{from_ms}..{to_ms} ms: exit {done.returncode}, no header or no '
                        'Drive<float>::on_tick() line')
        return None
    if not LINE_RE.search(done.stdout):
        failures.append(f'{from_ms}..{to_ms} ms: no firmware source line (debug information?)')
    lines_total, kinds = LINES_TOTAL_RE.search(done.stdout), dict(
        (kind, float(n)) for n, kind in KIND_RE.findall(done.stdout))
    if not lines_total or len(kinds) != 6 or \
            abs(sum(kinds.values()) - float(lines_total[1])) > 0.35 or \
            not kinds.get('FP arithmetic', 0) > 0:
        failures.append(f'{from_ms}..{to_ms} ms: the kinds {kinds} do not add up to the source '
                        f'lines\' {lines_total[1] if lines_total else "(none)"}')
    return int(head[1]), int(head[2]), float(tick[1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--elf', required=True)
    a = ap.parse_args()
    failures = []
    windows = [profile(a.elf, 10, 20, failures), profile(a.elf, 15, 25, failures)]
    if all(windows):
        (ticks1, total1, tick1), (ticks2, total2, tick2) = windows
        if ticks1 != 100 or ticks2 != 100:
            failures.append(f'windows of {ticks1} and {ticks2} ticks, not 100')
        if abs(tick1 - tick2) > 0.05 * max(tick1, tick2):
            failures.append(f'on_tick {tick1} and {tick2} a tick: the windows disagree')
        for tick, total in ((tick1, total1), (tick2, total2)):
            if not 50 <= tick <= 5000:
                failures.append(f'on_tick at {tick} instructions a tick, outside [50, 5000]')
            if total < 10 * tick:
                failures.append(f'total {total} below ten times on_tick: no plant?')
    for f in failures:
        print(f'profile_pil_test: FAIL: {f}')
    print('profile_pil_test: ' + ('FAIL' if failures else 'PASS'))
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
