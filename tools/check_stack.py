#!/usr/bin/env python3
"""Post-link check: a bound on the stack an image can use, against the stack it reserves.
Exit status: 0 the bound fits, 1 it does not (or a path is unbounded), 2 bad input.

The bound is the deepest path of the main thread (from the reset handler) plus, for each
interrupt level that may preempt it, the deepest path of that level's handlers and the frame
the core stacks on entry with the FPU context (26 words and an alignment word: 108 B). The
levels are given as groups of handlers (--level, repeatable): handlers of one group cannot
preempt each other, a group may preempt the ones before it. Then one fault handler (--faults)
and NMI on top of it. The levels must name every interrupt the image enables: the check does
not read the interrupt controller's set-up.

The objects are those the image's link map names (--map, its paths relative to --build-dir).
Frames are the compiler's own: GCC's -fcallgraph-info=su writes each object's functions'
frames, pushed registers included, beside it (NAME.ci). Functions without one (libgcc, newlib,
assembly) take the sum of every stack decrement in their code (`push`, `vpush`, `stmdb sp!`,
`sub sp`, `str`/`strd .., [sp, #-N]!`): at least their frame. A frame the compiler calls
dynamic, or a library function that moves the stack pointer by a register, fails the check.

Calls come from the linked image, as tools/check_tick_path.py finds them (direct calls, tail
calls, code falling into the next function). Indirect calls are resolved by the name of the
member they call, where the compiler shows that a function's indirect calls are all virtual:
its GIMPLE dump (-fdump-tree-optimized, beside the object) has no call through a pointer. The
.ci file gives each indirect call's source place; the statement there names the member, and a
virtual call reaches only the overriders of that name: the address-taken functions of that
name, when some virtual function (one in a vtable) has it. Otherwise (a call through a
pointer in the function, a statement naming no virtual function, a function with more
indirect calls in its code than the .ci file lists, one without a .ci file or a dump) an
indirect call may reach every address-taken function. A cycle (recursion) fails the check.
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
# GIMPLE: a function's header, and a call whose callee is an SSA name (`_5 (x_2);`,
# `y_3 = fp.0_1 (x_2);`): a call through a pointer (builtins, `__atomic_load_1`, are not).
# A virtual call reads OBJ_TYPE_REF (...).
DUMP_FUNCTION_RE = re.compile(r'^;; Function .* \((\S+), funcdef_no=')
POINTER_CALL_RE = re.compile(r'^\s+(?:[^=;]+ = )?(?!__)[A-Za-z_.][\w.]*_\d+(?:\(D\))? \(')
DECREMENT_RE = re.compile(r'^\s*[0-9a-f]+:\s+(push|stmdb|vpush|sub|subw|str|strd)(?:\.w)?\s+(.*)$')


class Unbounded(Exception):
    pass


def linked_objects(map_path, build_dir):
    """The objects the image's link map names (direct objects and the archive members it
    took), as paths without their .obj/.o suffix: where their .ci and GIMPLE dumps are."""
    try:
        text = open(map_path, errors='replace').read()
    except OSError as e:
        raise ctp.BadInput(f'cannot read the link map {map_path}: {e.strerror}')
    stems = set()
    for path in re.findall(r'^LOAD (\S+\.(?:obj|o))$', text, re.M):
        stems.add(os.path.join(build_dir, re.sub(r'\.(obj|o)$', '', path)))
    for archive, member in set(re.findall(r'(\S+\.a)\(([^)\s]+\.(?:obj|o))\)', text)):
        # CMake keeps a library's objects in <dir>/CMakeFiles/<name>.dir/..., by source path.
        lib = os.path.basename(archive)[3:-2] if os.path.basename(archive).startswith('lib') else ''
        objects = os.path.join(build_dir, os.path.dirname(archive), 'CMakeFiles', f'{lib}.dir')
        for obj in glob.glob(os.path.join(objects, '**', member), recursive=True):
            stems.add(re.sub(r'\.(obj|o)$', '', obj))
    return sorted(stems)


def read_objects(stems):
    """From each object's .ci file: {mangled name: frame bytes}, {mangled name: [(file, line,
    col)]} (a name compiled in several objects, as an inline function is: its largest frame,
    and the longest list of calls). From its GIMPLE dump (-fdump-tree-optimized): the functions
    that call through a pointer (an SSA name), not through a vtable (OBJ_TYPE_REF), and those
    the dumps show."""
    frames, indirect, pointer_callers, dumped = {}, {}, set(), set()
    found = [stem for stem in stems if os.path.exists(stem + '.ci')]
    if not found:
        raise ctp.BadInput('no .ci file beside the linked objects (built without '
                           '-fcallgraph-info=su?)')
    for stem in found:
        calls = {}  # this object's: one entry per call, an inlined body's calls once per copy
        with open(stem + '.ci', errors='replace') as f:
            for line in f:
                if m := NODE_RE.match(line):
                    if frame := FRAME_RE.search(m[2]):
                        if frame[2] != 'static':
                            raise Unbounded(f'{m[2].split(chr(92))[0]}: {frame[2]} frame '
                                            f'({stem}.ci)')
                        frames[m[1]] = max(frames.get(m[1], 0), int(frame[1]))
                elif m := EDGE_RE.match(line):
                    calls.setdefault(m[1], []).append((m[2], int(m[3]), int(m[4])))
        for name, sites in calls.items():  # an inline function's copies: the same calls
            if len(sites) > len(indirect.get(name, [])):
                indirect[name] = sites
        for dump in glob.glob(glob.escape(stem) + '.*t.optimized'):
            function = None
            with open(dump, errors='replace') as f:
                for line in f:
                    if m := DUMP_FUNCTION_RE.match(line):
                        function = m[1]
                        dumped.add(function)
                    elif function and POINTER_CALL_RE.match(line):
                        pointer_callers.add(function)
    return frames, indirect, pointer_callers, dumped


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
        elif mn in ('str', 'strd') and (s := re.search(r'\[sp,\s*#-(\d+)\]!', ops)):
            sums[current] += int(s[1])
    return sums, recursive


def graph(args):
    funcs, taken = ctp.build(args)
    frames, indirect, pointer_callers, dumped = read_objects(
        linked_objects(args.map, args.build_dir))
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
            # By name only where the compiler's own view shows every indirect call of the
            # function to be virtual: a dump of it, and no call through a pointer in it.
            only_virtual = any(n in dumped for n in f.names) and not any(
                n in pointer_callers for n in f.names)
            if f.start in startup_callers:
                targets |= startup
            elif only_virtual and len(sites) >= len(f.indirect_sites) and all(named):
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
    ap.add_argument('--map', required=True, help="the image's link map (-Wl,-Map)")
    ap.add_argument('--build-dir', required=True,
                    help="the directory the link ran in (the map's relative paths start there)")
    ap.add_argument('--main', default='Reset_Handler', help='the main thread\'s entry')
    ap.add_argument('--level', action='append', default=[], metavar='H1,H2',
                    help='handlers of one interrupt level, lowest level first (repeatable)')
    ap.add_argument('--startup-caller', default='Reset_Handler',
                    help='the function whose indirect calls run the start-up arrays')
    ap.add_argument('--faults', default='HardFault_Handler,MemManage_Handler,'
                    'BusFault_Handler,UsageFault_Handler,Default_Handler')
    ap.add_argument('--nmi', default='NMI_Handler', help='preempts the faults too')
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
        for label, handlers in (('faults', args.faults), ('NMI', args.nmi)):
            linked = [root(h, required=False) for h in handlers.split(',')]
            parts.append((label, [f for f in linked if f is not None], EXCEPTION_FRAME_BYTES))
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
