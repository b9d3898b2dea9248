#!/usr/bin/env python3
"""Self-test of tools/check_tick_path.py, without CMake: builds tiny Cortex-M4F fixture ELFs
with arm-none-eabi-g++ (the firmware's flags, and startup.cpp with its own vector table) and
runs the checker on them. Each fixture is linked twice: fixture_sections.ld puts the vector
table in its own .isr_vector section, fixture_text.ld puts it (and .rodata) inside .text, as
hal/cortex_m/linker/cortex_m_sections.ld does. Prints PASS/FAIL per case; exits 1 on any
failure, 2 if the fixtures do not build.

Usage: tests/tick_path/run.py [--cxx arm-none-eabi-g++] [--objdump arm-none-eabi-objdump]
                              [--keep DIR] [-v]
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
CHECKER = os.path.join(HERE, '..', '..', 'tools', 'check_tick_path.py')
FLAGS = ['-mcpu=cortex-m4', '-mthumb', '-mfloat-abi=hard', '-mfpu=fpv4-sp-d16', '-O2',
         '-std=c++20', '-ffunction-sections', '-fdata-sections', '-fno-exceptions', '-fno-rtti',
         '-nostartfiles', '--specs=nano.specs', '-Wl,--gc-sections']
LAYOUTS = ('sections', 'text')
TICK = ['--root', 'SysTick_Handler', '--root', 'PendSV_Handler']


def case(name, fixture, args, rc, expect=(), reject=(), layouts=LAYOUTS, needs=(), report=(),
         report_reject=(), defines=()):
    """fixture: the case_*.cpp/.S sources after startup.cpp (built with -D defines);
    expect/reject: regexes on the checker's output; needs: regexes the fixture's disassembly
    must match (so that the case tests what it claims); report, report_reject: regexes the
    --report file must match, must not match."""
    return dict(name=name, fixture=fixture, args=args, rc=rc, expect=expect, reject=reject,
                layouts=layouts, needs=needs, report=report, report_reject=report_reject,
                defines=defines)


CASES = [
    case('1 clean: float tick, virtual call of float-only classes', ['case_clean.cpp'],
         TICK + ['--root', 'fixture::Controller::on_tick*'], 0,
         expect=[r'^tick path clean: 3 roots, \d+ functions reachable \(1 indirect call sites, '
                 r'2 address-taken targets\); no double soft-float, heap or exceptions$'],
         needs=[r'<HardFault_Handler>:\n(.+\n)*?.*\tbl\s+\S+ <__aeabi_dmul>',
                r'<ADC_IRQHandler>:\n(.+\n)*?.*\tbl\s+\S+ <__adddf3>',
                r'<fixture_init>:\n(.+\n)*?.*\tbl\s+\S+ <sqrt>'],
         report=[r'fixture::LowPass::step\(float\)', r'fixture::Deadband::step\(float\)'],
         report_reject=[r'(ADC_IRQ|HardFault_|Reset_)Handler', r'fixture_init']),
    case('1b clean: roots by mangled and by parameterless demangled name', ['case_clean.cpp'],
         ['--root', '_ZN7fixture10Controller7on_tickEf', '--root', 'fixture::Controller::on_tick'],
         0, expect=[r'^tick path clean: 1 root, ']),
    case('1c control: the same handler also stored as a callback counts', ['case_clean.cpp'],
         TICK, 1, defines=['FIXTURE_HOOK'],
         expect=[r'__aeabi_dmul: SysTick_Handler -> fixture::Controller::on_tick\(float\) -> '
                 r'\(indirect\) HardFault_Handler -> __aeabi_dmul$']),
    case('1d --deny-regex on a demangled name', ['case_clean.cpp'],
         TICK + ['--deny-regex', r'^fixture::LowPass::step'], 1,
         expect=[r'-> \(indirect\) fixture::LowPass::step\(float\)$']),
    case('2 tick calls a double function', ['case_double.cpp'], TICK, 1,
         expect=[r'^  __aeabi_dmul: SysTick_Handler -> fixture::scale\(float\) -> __aeabi_dmul$',
                 r'^  __aeabi_f2d: ', r'^  __aeabi_d2f: ']),
    case('3 double reached only through a vtable', ['case_virtual_double.cpp'], TICK, 1,
         expect=[r'__aeabi_dmul: SysTick_Handler -> \(indirect\) fixture::PreciseModel::eval'
                 r'\(float\) -> __aeabi_dmul'],
         reject=[r'FastModel']),
    case('4 double and std::sqrt(double) in init only', ['case_init_double.cpp'], TICK, 0,
         expect=[r'^tick path clean: 2 roots, '],
         needs=[r'<fixture_init>:\n(.+\n)*?.*\tbl\s+\S+ <sqrt>',
                r'<fixture_init>:\n(.+\n)*?.*\tbl\s+\S+ <__aeabi_dmul>']),
    case('4b --no-double-in-image: the same fixture fails on its start-up double',
         ['case_init_double.cpp'], TICK + ['--no-double-in-image'], 1,
         expect=[r'^tick path clean: 2 roots, ', r'^image NOT free of double precision: ',
                 r'^  sqrt <- fixture_init$', r'^  __aeabi_dmul <- .*fixture_init']),
    case('4c --no-double-in-image on a float-only image', ['case_malloc.cpp'],
         ['--root', 'PendSV_Handler', '--no-double-in-image'], 0,
         expect=[r'^image free of double precision: none of \d+ functions$']),
    case('5 tick calls malloc', ['case_malloc.cpp'], TICK, 1,
         expect=[r'^  malloc: SysTick_Handler -> malloc$']),
    case('6 tail call (b.w) into a double function', ['case_tail_call.cpp'], TICK, 1,
         expect=[r'SysTick_Handler -> \(tail call\) fixture::publish\(float\) -> __aeabi_dmul'],
         needs=[r'<SysTick_Handler>:\n(.+\n)*?.*\tb\.w\s+\S+ <_ZN7fixture7publishEf>']),
    case('7 nonexistent root', ['case_clean.cpp'], ['--root', 'NoSuch_Handler'], 2,
         expect=[r'error: root not found in .*: NoSuch_Handler']),
    case('8 virtual destructor: operator delete through the vtable', ['case_virtual_dtor.cpp'],
         TICK, 1, expect=[r'SysTick_Handler -> \(indirect\) fixture::Dac::~Dac\(\) \[deleting '
                          r'destructor\] -> operator delete\(void\*, unsigned int\)$']),
    case('9 std::array::at: std::__throw_* with -fno-exceptions', ['case_throw.cpp'], TICK, 1,
         expect=[r'SysTick_Handler -> std::__throw_out_of_range_fmt\(char const\*, \.\.\.\)$']),
    case('10 asm: falls off its end into the next function', ['case_asm.cpp', 'case_asm.S'],
         ['--root', 'SysTick_Handler'], 1,
         expect=[r'asm_fall_a -> \(falls through\) asm_fall_b -> malloc$']),
    case('11 asm: veneer (ldr pc, [pc]) followed as a jump', ['case_asm.cpp', 'case_asm.S'],
         ['--root', 'PendSV_Handler'], 1, reject=[r'indirect\)'],
         expect=[r'asm_veneer -> \(tail call\) far_double -> __aeabi_dmul$']),
    case('12 asm: address built by movw/movt, called by blx', ['case_asm.cpp', 'case_asm.S'],
         ['--root', 'SVC_Handler'], 1, expect=[r'asm_movw_call -> \(indirect\) '],
         report=[r'^0x\w+\s+\d+ movw_target$']),
    case('12b asm: a vector known only by its section takes no address', ['case_asm.cpp',
         'case_asm.S'], ['--root', 'SVC_Handler'], 1, layouts=['sections'],
         needs=[r'<asm_irq_handler>:\n(.+\n)*?.*\tbl\s+\S+ <__adddf3>'],
         report_reject=[r'asm_irq_handler']),
    case('12c control: the same vector counts without --exclude-section .isr_vector',
         ['case_asm.cpp', 'case_asm.S'], ['--root', 'SVC_Handler', '--exclude-section', '.none'],
         1, layouts=['sections'], report=[r'asm_irq_handler']),
    case('12d asm: a switch\'s table jump (-Os) stays in the function, its cases followed',
         ['case_asm.cpp', 'case_asm.S'], ['--root', 'asm_switch'], 1, reject=[r'\(indirect\)'],
         expect=[r'\(0 indirect call sites', r'asm_switch -> far_double -> __aeabi_dmul$'],
         needs=[r'<asm_switch>:\n(.+\n)*?.*\tldr\.w\s+pc, \[r1, r0, lsl #2\]']),
    case('12e asm: a table jump to another function is a call through a pointer',
         ['case_asm.cpp', 'case_asm.S'], ['--root', 'asm_table_out'], 1,
         expect=[r'\(1 indirect call sites', r'asm_table_out -> \(indirect\) ']),
    case('13 missing ELF', None, ['--root', 'SysTick_Handler'], 2, layouts=['sections'],
         expect=[r'error: no such file']),
    case('14 objdump missing', ['case_clean.cpp'], TICK + ['--objdump', '/nonexistent/objdump'],
         2, layouts=['sections'], expect=[r'error: cannot run objdump']),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--cxx', default='arm-none-eabi-g++')
    ap.add_argument('--objdump', default='arm-none-eabi-objdump')
    ap.add_argument('--keep', metavar='DIR', help='build the fixtures here and keep them')
    ap.add_argument('-v', '--verbose', action='store_true', help="show the checker's output")
    args = ap.parse_args()
    try:
        version = subprocess.run([args.cxx, '--version'], capture_output=True, text=True)
    except OSError as e:
        print(f'cannot run {args.cxx}: {e}', file=sys.stderr)
        return 2
    print(f'toolchain: {version.stdout.splitlines()[0]}')
    temp = None if args.keep else tempfile.TemporaryDirectory(prefix='tick_path.')
    out_dir = args.keep or temp.name
    os.makedirs(out_dir, exist_ok=True)
    built = {}

    def build(fixture, layout, defines):
        key = (tuple(fixture), layout, tuple(defines))
        if key not in built:
            stem = '_'.join([os.path.splitext(fixture[0])[0].replace('case_', ''), *defines])
            elf = os.path.join(out_dir, f'{stem.lower()}_{layout}.elf')
            extra = [f'-D{d}' for d in defines]
            if 'case_throw.cpp' in fixture:
                extra.append('--specs=nosys.specs')  # the C library's abort() needs _exit etc.
            cmd = [args.cxx, *FLAGS, *extra, '-T', os.path.join(HERE, f'fixture_{layout}.ld'),
                   *(os.path.join(HERE, s) for s in ['startup.cpp', *fixture]), '-o', elf]
            done = subprocess.run(cmd, capture_output=True, text=True)
            if done.returncode != 0:
                print(f'fixture build failed:\n{" ".join(cmd)}\n{done.stderr}', file=sys.stderr)
                sys.exit(2)
            disasm = subprocess.run([args.objdump, '-d', '--no-show-raw-insn', elf],
                                    capture_output=True, text=True).stdout
            built[key] = (elf, disasm)
        return built[key]

    failures = 0
    for c in CASES:
        for layout in c['layouts']:
            problems, report = [], os.path.join(out_dir, 'report.txt')
            if c['fixture'] is None:
                elf, disasm = os.path.join(out_dir, 'missing.elf'), ''
            else:
                elf, disasm = build(c['fixture'], layout, c['defines'])
            problems += [f'fixture lacks {n!r}' for n in c['needs'] if not re.search(n, disasm)]
            extra = ['--objdump', args.objdump] if '--objdump' not in c['args'] else []
            if os.path.exists(report):
                os.remove(report)
            run = subprocess.run([sys.executable, CHECKER, elf, *c['args'], *extra,
                                  '--report', report], capture_output=True, text=True)
            output = run.stdout + run.stderr
            if 'Traceback' in output:
                problems.append('the checker crashed')
            if run.returncode != c['rc']:
                problems.append(f'exit {run.returncode}, expected {c["rc"]}')
            problems += [f'no match for {e!r}' for e in c['expect']
                         if not re.search(e, output, re.M)]
            problems += [f'unexpected {r!r}' for r in c['reject'] if re.search(r, output, re.M)]
            text = open(report).read() if os.path.exists(report) else ''
            problems += [f'report lacks {r!r}' for r in c['report'] if not re.search(r, text, re.M)]
            problems += [f'report has {r!r}' for r in c['report_reject']
                         if re.search(r, text, re.M)]
            print(f'{"FAIL" if problems else "PASS"} {c["name"]} [{layout}]')
            if problems or args.verbose:
                print('    ' + output.strip().replace('\n', '\n    '))
                for p in problems:
                    print(f'    -> {p}')
            failures += bool(problems)
    total = sum(len(c['layouts']) for c in CASES)
    kept = f'; fixtures kept in {out_dir}' if args.keep else ''
    print(f'{total - failures}/{total} passed{kept}')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
