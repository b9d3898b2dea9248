#!/usr/bin/env python3
"""tools/profile_pil.py on the processor-in-the-loop image: a 10 ms window of the realistic
scenario (the drive calibrating its ADC offsets, then magnetizing; 100 ticks), by function and
by source line.

The bounds are wide on purpose: they check that the profile measures the drive's tick, not its
exact cost. The tick's own function runs every tick with its stages inlined: between 50
instructions (a tick that only reads the ADC) and 5 000 (twice the 2 500 the PIL timer
measures for a running tick at most). The plant, in soft double, costs far more per tick than
the drive: the total must exceed the tick's function. The source lines need the image's debug
information.

Usage: profile_pil_test.py --elf drive_pil_mps2_an386.elf
"""
import argparse
import os
import re
import subprocess
import sys

TOOL = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'tools',
                    'profile_pil.py')


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--elf', required=True)
    a = ap.parse_args()
    done = subprocess.run([sys.executable, TOOL, a.elf, '--from-ms', '10', '--to-ms', '20',
                           '--lines', 'imd8firmware'], capture_output=True, text=True,
                          timeout=600)
    sys.stdout.write(done.stdout)
    sys.stderr.write(done.stderr)
    failures = []
    if done.returncode != 0:
        failures.append(f'exit status {done.returncode}')
    head = re.search(r'^instructions per tick, .* \((\d+) ticks\); total (\d+)$', done.stdout, re.M)
    tick = re.search(r'^\s*([\d.]+)\s+imd::firmware::Drive<float>::on_tick\(\)$', done.stdout,
                     re.M)
    if not head or int(head[1]) != 100:
        failures.append('no header with the window of 100 ticks')
    if not tick:
        failures.append('Drive<float>::on_tick() is not in the profile')
    elif not 50 <= float(tick[1]) <= 5000:
        failures.append(f'on_tick at {tick[1]} instructions a tick, outside [50, 5000]')
    elif head and int(head[2]) <= float(tick[1]):
        failures.append('the total is not above the tick function (the plant is missing)')
    if not re.search(r'^\s*[\d.]+\s+firmware/\S+\.(cpp|hpp):\d+$', done.stdout, re.M):
        failures.append('no firmware source line in the by-line profile (debug information?)')
    for f in failures:
        print(f'profile_pil_test: FAIL: {f}')
    print('profile_pil_test: ' + ('FAIL' if failures else 'PASS'))
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
