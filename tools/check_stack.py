#!/usr/bin/env python3
"""Post-link check: a bound on the stack an image can use, against the stack it reserves.
Exit status: 0 the bound fits, 1 it does not (or a path is unbounded), 2 bad input.

The bound is the deepest path of the main thread (from the reset handler) plus, for each
interrupt level that may preempt it, the deepest path of that level's handlers and the frame
the core stacks on entry with the FPU context (26 words and an alignment word: 108 B). The
levels are given as groups of handlers (--level, repeatable): handlers of one group cannot
preempt each other, a group may preempt the ones before it. Faults and NMI (--faults) come
last, one of them at a time.

Frames are the compiler's own (GCC's -fcallgraph-info=su, the NAME.ci files beside the objects,
--ci-dir): the bytes each function's frame takes, pushed registers included. Functions without
one (libgcc, newlib, assembly) take the sum of every stack decrement in their code (`push`,
`vpush`, `stmdb sp!`, `sub sp`, `str .., [sp, #-N]!`): at least their frame. A frame the compiler
calls dynamic fails the check.

Calls come from the linked image, as tools/check_tick_path.py finds them (direct calls, tail
calls, code falling into the next function). An indirect call is resolved by the name of the
function it calls: the .ci file gives each indirect call's source location, whose text names the
member called (`x.name(`, `p->name(`). A virtual call can reach only overriders of that name, so
its targets are the address-taken functions of that name, when some virtual function (one in a
vtable) has it. Otherwise (a function pointer, a call the text does not name, a function with
more indirect calls in its code than the .ci file lists, or one without a .ci file) it may reach
every address-taken function. A cycle (recursion) has no bound and fails the check.
Limits: a function pointer whose name equals a virtual function's is taken for that function.
"""
import argparse
import functools
import glob
import os
import re
import subprocess
import sys

import check_tick_path as ctp
import imd_version

EXCEPTION_FRAME_BYTES = 108  # 8 basic + 18 FP words stacked on entry, and the alignment word
NODE_RE = re.compile(r'^node: \{ title: "(?:[^"]*:)?([^":]+)" label: "(.*)" \}$')
EDGE_RE = re.compile(r'^edge: \{ sourcename: "(?:[^"]*:)?([^":]+)" targetname: "__indirect_call"'
                     r' label: "(.*):(\d+):(\d+)" \}$')
FRAME_RE = re.compile(r'\\n(\d+) bytes \(([a-z,]+)\)$')
SELF_CALL_RE = re.compile(r'^\s*[0-9a-f]+:\s+blx?(?:\.w)?\s+([0-9a-f]+) <')
DECREMENT_RE = re.compile(r'^\s*[0-9a-f]+:\s+(push|stmdb|vpush|sub|subw|str)(?:\.w)?\s+(.*)$')


class Unbounded(Exception):
    pass


def read_ci(ci_dir):
    """{mangled name: frame bytes}, {mangled name: [(file, line, col)]} from every .ci file
    (a name compiled in several objects: its largest frame, and the calls of every copy)."""
    frames, indirect = {}, {}
    files = glob.glob(os.path.join(ci_dir, '**', '*.ci'), recursive=True)
    if not files:
        raise ctp.BadInput(f'no .ci files under {ci_dir} (built without -fcallgraph-info=su?)')
    for path in files:
        with open(path, errors='replace') as f:
            for line in f:
                if m := NODE_RE.match(line):
                    if frame := FRAME_RE.search(m[2]):
                        if frame[2] != 'static':
                            raise Unbounded(f'{m[2].split(chr(92))[0]}: {frame[2]} frame '
                                            f'({path})')
                        frames[m[1]] = max(frames.get(m[1], 0), int(frame[1]))
                elif m := EDGE_RE.match(line):  # a name in several objects: all their calls
                    indirect.setdefault(m[1], []).append((m[2], int(m[3]), int(m[4])))
    return frames, indirect


@functools.lru_cache(maxsize=None)
def source_lines(path):
    try:
        with open(path, errors='replace') as f:
            return f.read().splitlines()
    except OSError:
        return []


def called_names(site):
    """The functions a call at (file, line, col) may name: each identifier followed by `(` in
    the statement around that place (from the `;`, `{` or `}` before it to the `;` after it).
    GCC places a call at its `(`, at the variable it initializes or at its last argument."""
    path, line, col = site
    lines = source_lines(path)
    if not 0 < line <= len(lines):
        return set()
    at = sum(len(t) + 1 for t in lines[:line - 1]) + col - 1
    text = '\n'.join(lines)
    start = max(text.rfind(c, 0, at) for c in ';{}') + 1
    end = text.find(';', at)
    statement = text[start:end if end >= 0 else len(text)]
    return set(re.findall(r'([A-Za-z_~][A-Za-z0-9_]*)\s*(?:<[^;()]*?>)?\s*\(', statement))


def unqualified(dname):
    """The function's own name: `a::B<c::d>::step(int) const [clone .x]` -> `step`,
    `f(int)::{lambda(int)#1}::operator()(int) const` -> `operator()`."""
    name = re.sub(r'( \[clone [^]]*\])+$', '', dname).replace('(anonymous namespace)', 'anon')
    name = re.sub(r'(\s*(const|volatile|&|&&|noexcept))+$', '', name)
    if name.endswith(')'):  # the parameter list: from its balanced '('
        depth = 0
        for i in range(len(name) - 1, -1, -1):
            depth += {')': 1, '(': -1}.get(name[i], 0)
            if depth == 0:
                name = name[:i]
                break
    depth, start = 0, 0
    for i, c in enumerate(name):
        depth += {'<': 1, '(': 1, '{': 1, '>': -1, ')': -1, '}': -1}.get(c, 0)
        if depth == 0 and name.startswith('::', i):
            start = i + 2
    return name[start:]


def scan(tool, elf):
    """{function start: sum of the stack decrements in its code} for every function (None when
    it moves the stack pointer by a register: a dynamic frame), and the functions that call
    their own start (check_tick_path's graph leaves such calls out)."""
    sums, current, recursive = {}, None, set()
    for line in ctp.objdump(tool, '-d', '--no-show-raw-insn', elf).splitlines():
        if m := re.match(r'^([0-9a-f]+) <', line):
            current = int(m[1], 16)
            sums.setdefault(current, 0)
            continue
        if sums.get(current, 0) is None:
            continue
        if (m := SELF_CALL_RE.match(line)) and current is not None and int(m[1], 16) == current:
            recursive.add(current)
        m = DECREMENT_RE.match(line)
        if not m or current is None:
            continue
        mn, ops = m[1], m[2].split(';')[0].strip()
        if mn in ('push', 'stmdb', 'vpush') and (mn != 'stmdb' or ops.startswith('sp!')):
            regs = 0
            for part in re.findall(r'\{([^}]*)\}', ops)[0].split(','):
                lo_hi = re.findall(r'\d+', part)
                regs += int(lo_hi[1]) - int(lo_hi[0]) + 1 if '-' in part else 1
            sums[current] += 4 * regs * (2 if re.search(r'\bd\d', ops) else 1)
        elif mn in ('sub', 'subw') and (s := re.match(r'sp,\s*(?:sp,\s*)?#(\d+)', ops)):
            sums[current] += int(s[1])
        elif mn == 'sub' and re.match(r'sp,\s*(?:sp,\s*)?(r\d+|ip|lr)', ops):
            sums[current] = None
        elif mn == 'str' and (s := re.search(r'\[sp,\s*#-(\d+)\]!', ops)):
            sums[current] += int(s[1])
    return sums, recursive


def graph(args):
    funcs, taken = ctp.build(args)
    frames, indirect = read_ci(args.ci_dir)
    fallback, recursive = scan(args.objdump, args.elf)
    sections, symbols, _ = ctp.load(args.objdump, args.elf)

    def functions_in(lo, hi):
        words = (ctp.word_at(sections, a) for a in range(lo, hi, 4))
        return {w & ~1 for w in words if w is not None and w & 1 and (w & ~1) in funcs}

    vtables = set()
    for addr, flags, sec, size, name, dname in symbols:
        if name.startswith('_ZTV'):
            vtables |= functions_in(addr, addr + size)
    # The C runtime's start-up arrays: what --startup-caller's indirect calls run.
    at = {s[4]: s[0] for s in symbols}
    startup = set()
    for array in ('__preinit_array', '__init_array'):
        if f'{array}_start' in at and f'{array}_end' in at:
            startup |= functions_in(at[f'{array}_start'], at[f'{array}_end'])
    startup_callers = {f.start for f, _ in ctp.root_matches(funcs, args.startup_caller)}
    by_name = {}
    for start in taken:
        for dname in funcs[start].dnames:
            by_name.setdefault(unqualified(dname), set()).add(start)
    virtual_names = {n for n, starts in by_name.items() if starts & vtables}
    frame, callees, notes = {}, {}, []
    for f in funcs.values():
        known = [frames[n] for n in f.names if n in frames]
        frame[f.start] = max(known) if known else fallback.get(f.start, 0)
        if frame[f.start] is None:
            raise Unbounded(f'{f.label()}: moves the stack pointer by a register (no .ci frame)')
        targets = {t for t, _ in f.edges} | ({f.start} & recursive)
        if f.indirect_sites:
            sites = max((indirect.get(n, []) for n in f.names), key=len)
            named = [called_names(s) & virtual_names for s in sites]
            if f.start in startup_callers:
                targets |= startup
            elif len(sites) >= len(f.indirect_sites) and all(named):
                for names in named:
                    for n in names:
                        targets |= by_name[n]
            else:
                targets |= set(taken)
                notes.append(f.label())
        callees[f.start] = targets
    return funcs, frame, callees, notes


def deepest(funcs, frame, callees, root):
    """(bytes, chain of starts) of the deepest path from root."""
    memo, active = {}, []

    def visit(start):
        if start in memo:
            return memo[start]
        if start in active:
            cycle = active[active.index(start):] + [start]
            raise Unbounded('recursion: ' + ' -> '.join(funcs[s].label() for s in cycle))
        active.append(start)
        best = (0, [])
        for t in callees[start]:
            best = max(best, visit(t), key=lambda b: b[0])
        active.pop()
        memo[start] = (frame[start] + best[0], [start] + best[1])
        return memo[start]

    sys.setrecursionlimit(max(10000, 4 * len(funcs)))
    return visit(root)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('elf')
    ap.add_argument('--ci-dir', required=True, help='directory searched for the .ci files')
    ap.add_argument('--main', default='Reset_Handler', help='the main thread\'s entry')
    ap.add_argument('--level', action='append', default=[], metavar='H1,H2',
                    help='handlers of one interrupt level, lowest level first (repeatable)')
    ap.add_argument('--startup-caller', default='Reset_Handler',
                    help='the function whose indirect calls run the start-up arrays')
    ap.add_argument('--faults', default='NMI_Handler,HardFault_Handler,MemManage_Handler,'
                    'BusFault_Handler,UsageFault_Handler,Default_Handler')
    ap.add_argument('--report', metavar='FILE', help='write each deepest path with its frames')
    ap.add_argument('--objdump', default='arm-none-eabi-objdump')
    imd_version.add_argument(ap)
    args = ap.parse_args(argv)
    args.exclude_section, args.exclude_object = None, []
    try:
        if not os.path.isfile(args.elf):
            raise ctp.BadInput(f'no such file: {args.elf}')
        funcs, frame, callees, notes = graph(args)
        symbols = {s[4]: s[0] for s in ctp.load(args.objdump, args.elf)[1]}  # name -> address
        if '__stack_top__' not in symbols or '__stack_bottom__' not in symbols:
            raise ctp.BadInput('no __stack_bottom__/__stack_top__ symbols in the image')
        reserved = symbols['__stack_top__'] - symbols['__stack_bottom__']

        def root(spec, required=True):
            hits = ctp.root_matches(funcs, spec)
            if not hits and required:
                raise ctp.BadInput(f'no function {spec} in {args.elf}')
            return hits[0][0].start if hits else None

        parts = [('main thread', [root(args.main)], 0)]
        parts += [(f'level {i + 1}', [root(h) for h in lvl.split(',')], EXCEPTION_FRAME_BYTES)
                  for i, lvl in enumerate(args.level)]
        faults = [root(h, required=False) for h in args.faults.split(',')]  # those linked
        parts.append(('faults', [f for f in faults if f is not None], EXCEPTION_FRAME_BYTES))
        rows, total = [], 0
        for label, starts, entry in parts:
            depth, chain = max((deepest(funcs, frame, callees, s) for s in starts),
                               key=lambda d: d[0], default=(0, []))
            rows.append((label, depth + entry, entry, chain))
            total += depth + entry
    except ctp.BadInput as e:
        print(f'check_stack: error: {e}', file=sys.stderr)
        return 2
    except Unbounded as e:
        print(f'check_stack: stack NOT bounded: {e}')
        return 1
    if args.report:
        with open(args.report, 'w') as out:
            out.write(f'# Stack bound of {os.path.basename(args.elf)} (tools/check_stack.py): '
                      f'{total} B of {reserved} B reserved\n')
            for label, depth, entry, chain in rows:
                out.write(f'{label}: {depth} B ({entry} B stacked on entry)\n')
                for s in chain:
                    out.write(f'  {frame[s]:5d} {funcs[s].label()}\n')
            out.write('# indirect calls taken to reach any address-taken function, in:\n')
            out.writelines(f'#   {n}\n' for n in sorted(set(notes)))
    summary = ', '.join(f'{label} {depth}' for label, depth, _, _ in rows)
    if total > reserved:
        print(f'stack NOT within its reservation: bound {total} B > {reserved} B ({summary})')
        return 1
    print(f'stack bounded: {total} B of {reserved} B reserved ({summary})')
    return 0


if __name__ == '__main__':
    sys.exit(main())
