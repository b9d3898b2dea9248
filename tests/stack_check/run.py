#!/usr/bin/env python3
"""Self-test of tools/check_stack.py, without CMake: builds a small Cortex-M4F fixture image
with arm-none-eabi-g++ (the firmware's flags, -fcallgraph-info=su -fdump-tree-optimized, the
start-up of tests/tick_path) in a few variants and runs the check on them. Prints PASS/FAIL per case; exits
1 on any failure, 2 if the fixtures do not build.

Usage: tests/stack_check/run.py [--cxx arm-none-eabi-g++] [--objdump arm-none-eabi-objdump]
                                [--keep DIR] [-v]
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
CHECKER = os.path.join(HERE, '..', '..', 'tools', 'check_stack.py')
STARTUP = os.path.join(HERE, '..', 'tick_path', 'startup.cpp')
FLAGS = ['-mcpu=cortex-m4', '-mthumb', '-mfloat-abi=hard', '-mfpu=fpv4-sp-d16', '-O2',
         '-std=c++20', '-ffunction-sections', '-fdata-sections', '-fno-exceptions', '-fno-rtti',
         '-fcallgraph-info=su', '-fdump-tree-optimized', '-Wno-vla']
LINK = ['-nostartfiles', '--specs=nano.specs', '-Wl,--gc-sections']
LEVELS = ['--level', 'PendSV_Handler', '--level', 'SysTick_Handler']
SUMMARY_RE = re.compile(r'^stack bounded: (\d+) B of (\d+) B reserved \(main thread (\d+), '
                        r'level 1 (\d+), level 2 (\d+), faults (\d+), NMI (\d+)\)$', re.M)
ENTRY = 108  # the check's exception frame


def bounds(output):
    """{total, reserved, main, pendsv, systick, faults} from the check's summary, or {}."""
    m = SUMMARY_RE.search(output)
    keys = ('total', 'reserved', 'main', 'pendsv', 'systick', 'faults', 'nmi')
    return dict(zip(keys, map(int, m.groups()))) if m else {}


# Each case: name, defines, stack size, extra arguments, exit status, regexes the output must
# match, and a check on the bounds (a failed assertion's text, or None).
CASES = [
    ('1 virtual calls resolved by name: only the main thread reaches the 2 KiB frame', [], 8192,
     [], 0, [r'^stack bounded: '],
     lambda b, report: (
         'main thread below its 2 KiB frame' if b['main'] < 2048 else
         'an interrupt reaches the 2 KiB frame' if max(b['pendsv'], b['systick']) >= 2048 else
         'an interrupt level without its stacked context' if min(
             b['pendsv'], b['systick'], b['faults'], b['nmi']) < ENTRY else
         'the levels do not add up' if b['total'] != b['main'] + b['pendsv'] + b['systick'] +
         b['faults'] + b['nmi'] else
         'the report lacks the deepest path' if not re.search(
             r'^main thread: \d+ B.*\n(  .*\n)*?\s+\d+ fixture::BigWork::heavy\(int\)$',
             report, re.M) else None)),
    ('2 a call through a function pointer may reach every address-taken function',
     ['FIXTURE_HOOK'], 8192, [], 0, [r'^stack bounded: '],
     lambda b, report: (
         'the pointer call did not reach the 2 KiB frame' if b['pendsv'] < 2048 + ENTRY else
         'the report does not name the unresolved caller' if not re.search(
             r'^#   PendSV_Handler$', report, re.M) else
         'the other level changed' if b['systick'] >= 2048 else None)),
    ('2b a pointer call in the same statement as a virtual call is not taken for it',
     ['FIXTURE_MIXED'], 8192, [], 0, [r'^stack bounded: '],
     lambda b, report: (
         'the pointer call did not reach the 2 KiB frame' if b['pendsv'] < 2048 + ENTRY else
         None)),
    ('3 recursion has no bound', ['FIXTURE_RECURSION'], 8192, [], 1,
     [r'^check_stack: stack NOT bounded: recursion: fixture::depth\(int\) -> '
      r'fixture::depth\(int\)$'], None),
    ('4 a dynamic frame has no bound', ['FIXTURE_VLA'], 8192, [], 1,
     [r'^check_stack: stack NOT bounded: .*sized.*: dynamic(,bounded)? frame'], None),
    ('5 a bound over the reservation fails', [], 2048, [], 1,
     [r'^stack NOT within its reservation: bound \d+ B > 2048 B \(main thread \d+, '], None),
    ('6 no link map', [], 8192, ['--map', '/nonexistent.map'], 2,
     [r'^check_stack: error: cannot read the link map /nonexistent\.map'], None),
    ('7 an unknown handler', [], 8192, ['--level', 'NoSuch_Handler'], 2,
     [r'^check_stack: error: no function NoSuch_Handler'], None),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--cxx', default='arm-none-eabi-g++')
    ap.add_argument('--objdump', default='arm-none-eabi-objdump')
    ap.add_argument('--keep', metavar='DIR', help='build the fixtures here and keep them')
    ap.add_argument('-v', '--verbose', action='store_true', help="show the check's output")
    args = ap.parse_args()
    temp = None if args.keep else tempfile.TemporaryDirectory(prefix='stack_check.')
    out_dir = args.keep or temp.name
    failures = 0
    for name, defines, stack, extra, rc, expect, check in CASES:
        stem = '_'.join(['stack', *defines, str(stack)]).lower()
        build_dir = os.path.join(out_dir, stem)
        os.makedirs(build_dir, exist_ok=True)
        elf = os.path.join(build_dir, 'fixture.elf')
        objects = []
        for source in (STARTUP, os.path.join(HERE, 'case_stack.cpp')):
            obj = os.path.join(build_dir, os.path.basename(source) + '.obj')
            objects.append(obj)
            cmd = [args.cxx, *FLAGS, *(f'-D{d}' for d in defines), '-c', source, '-o', obj]
            done = subprocess.run(cmd, capture_output=True, text=True, cwd=build_dir)
            if done.returncode != 0:
                print(f'fixture build failed:\n{" ".join(cmd)}\n{done.stderr}', file=sys.stderr)
                return 2
        link_map = os.path.join(build_dir, 'fixture.map')
        cmd = [args.cxx, *FLAGS, *LINK, '-T', os.path.join(HERE, 'fixture.ld'),
               f'-Wl,--defsym=STACK_SIZE={stack}', f'-Wl,-Map={link_map}', *objects, '-o', elf]
        done = subprocess.run(cmd, capture_output=True, text=True, cwd=build_dir)
        if done.returncode != 0:
            print(f'fixture link failed:\n{" ".join(cmd)}\n{done.stderr}', file=sys.stderr)
            return 2
        report = os.path.join(build_dir, 'report.txt')
        if os.path.exists(report):
            os.remove(report)
        ci = ['--build-dir', build_dir] + ([] if '--map' in extra else ['--map', link_map])
        levels = [] if '--level' in extra else LEVELS
        run = subprocess.run([sys.executable, CHECKER, elf, *ci, *levels, *extra,
                              '--objdump', args.objdump, '--report', report],
                             capture_output=True, text=True)
        output = run.stdout + run.stderr
        problems = ['the check crashed'] if 'Traceback' in output else []
        if run.returncode != rc:
            problems.append(f'exit {run.returncode}, expected {rc}')
        problems += [f'no match for {e!r}' for e in expect if not re.search(e, output, re.M)]
        if check is not None:
            b = bounds(output)
            text = open(report).read() if os.path.exists(report) else ''
            if problem := ('no summary line' if not b else check(b, text)):
                problems.append(problem)
        print(f'{"FAIL" if problems else "PASS"} {name}')
        if problems or args.verbose:
            print('    ' + output.strip().replace('\n', '\n    '))
            for p in problems:
                print(f'    -> {p}')
        failures += bool(problems)
    kept = f'; fixtures kept in {out_dir}' if args.keep else ''
    print(f'{len(CASES) - failures}/{len(CASES)} passed{kept}')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
