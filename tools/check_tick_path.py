#!/usr/bin/env python3
"""Post-link check: code reachable from the tick's interrupt entries (--root) must not reach
double-precision soft-float, the heap or the exception machinery (DEFAULT_DENY, --deny-regex).
Exit status: 0 clean, 1 a denied function is reachable (one call chain each), 2 bad input.
With --no-double-in-image, also 1 if double-precision soft-float is linked anywhere in the
image, reachable from the tick or not (each such function is listed with its direct callers).

Method: a static call graph of the linked ELF. Functions are the FUNC symbols of `objdump -t`
(Thumb bit cleared; a function ends at its size or at the next function, so literal pools and
local labels belong to it). Edges come from `objdump -d`: `bl`/`blx` to an address, and any
branch (`b`, `b<cond>`, `.n`/`.w`, `cbz`, `cbnz`) that leaves the function (a tail call);
branches inside the function are not edges. Code that runs off its end into the next function
(libgcc's assembly: __aeabi_dsub falls into __adddf3) is an edge too. A breadth-first search
from the roots gives one shortest chain per denied function reached; it does not go past one.

Conservative assumptions (it may report a chain that never runs; it should not miss one,
within the limits below):
- An indirect call or jump (`blx rN`, `bx rN` but `bx lr`, `mov pc, rN`, `add pc, rN`,
  `ldr pc, ...`, `ldm rN, {.., pc}`) may call any address-taken function: a function whose
  start (with the Thumb bit) is an aligned 32-bit word of an allocated section (vtables,
  function pointer tables, .data initial values), of a literal pool in code, or the value of a
  `movw`/`movt` pair. Literal pools over-approximate (an address may only be stored or
  compared), and a virtual call may reach every virtual function (and deleting destructor) of
  the image. Not counted: .init_array/.fini_array/.preinit_array and the vector tables: their
  sections (--exclude-section) and, for tables placed inside .text, data objects known by name
  (--exclude-object), whose second word is the entry point (the core's vectors), or that
  directly follow such a table (the chip's interrupt vectors).
- Returns: `bx lr`, `pop {.., pc}`, `ldr pc, [sp], #N`, `ldm sp!, {.., pc}`. `tbb`/`tbh` stay
  in the function, and so does a switch's table jump at -Os (`adr rB, table` right before
  `ldr pc, [rB, rI, lsl #2]`) when the table's words, up to the first that is not, are places
  in the function (at least one). A linker veneer (`ldr pc, [pc, #imm]` loading a function's address) is a
  direct jump.
- Limits: a function address made at run time any other way is not seen, nor is code that no
  FUNC symbol covers (a branch into it is reported on stderr).
"""
import argparse
import bisect
import collections
import fnmatch
import os
import re
import struct
import subprocess
import sys

import imd_version

DOUBLE_DENY = [
    r'^__aeabi_(d|cd|f2d|i2d|ui2d|l2d|ul2d)',  # double soft-float, run-time ABI names
    r'^__(add|sub|mul|div|neg)df3$',
    r'^__(extendsfdf2|truncdfsf2|fix(uns)?dfsi|fix(uns)?dfdi|float(un)?sidf|float(un)?didf)$',
    r'^__(eq|ne|lt|le|gt|ge|unord)df2$',
    r'^(sin|cos|tan|asin|acos|atan|atan2|sinh|cosh|tanh|exp|exp2|expm1|log|log2|log10|log1p|pow'
    r'|sqrt|cbrt|hypot|fmod|remainder|floor|ceil|round|trunc|lround|llround|lrint|llrint|rint'
    r'|nearbyint|modf|frexp|ldexp|scalbn|copysign|fabs|fmin|fmax|fdim|fma)$',  # double libm
    r'^__ieee754_(?!.*f$)', r'^__kernel_(sin|cos|tan|rem_pio2)$',  # newlib's double internals
]
DEFAULT_DENY = DOUBLE_DENY + [
    r'^_?(malloc|free|calloc|realloc|memalign|aligned_alloc)(_r)?$',  # heap
    r'^_(malloc|free|calloc|realloc)_r$',
    r'^_Zn[wa]', r'^_Zd[la]',  # operator new, new[], delete, delete[]
    r'^__cxa_(throw|allocate_exception|begin_catch|rethrow)', r'^_Unwind_',  # exceptions
    r'^_ZSt\d+__throw_', r'^__gxx_personality',
]
DEFAULT_EXCLUDE_SECTIONS = ['.isr_vector', '.vectors*']
START_UP_SECTIONS = ['.init_array*', '.fini_array*', '.preinit_array*']
VECTOR_OBJECTS = ['g_core_vectors', 'g_pfnVectors', '__isr_vector', '__Vectors', '__vector_table',
                  'vector_table', 'g_irq_vectors']

COND = r'(?:eq|ne|cs|hs|cc|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|al)'
BRANCH_RE = re.compile(rf'^b(l|lx)?({COND})?(?:\.[nw])?$')  # b, bl, blx; condition, width
CBZ_RE = re.compile(r'^cbn?z$')
TARGET_RE = re.compile(r'(?:^|[\s,])([0-9a-f]+) <')
INSN_RE = re.compile(r'^\s*([0-9a-f]+):\s+(\S+)\s*(.*)$')
SYM_RE = re.compile(r'^([0-9a-f]+) (.{7}) (\S+)\s+([0-9a-f]+)\s+'
                    r'(?:\.hidden |\.protected |\.internal )?(.*)$')
ADR_RE = re.compile(r'\(adr (r\d+), ([0-9a-f]+)')  # objdump's comment on `add rN, pc, #imm`
TABLE_JUMP_RE = re.compile(r'pc,\s*\[(r\d+),\s*r\d+,\s*lsl\s*#2\]$')
REG_RE = re.compile(r'\b(r\d+|sp|lr|pc|ip|fp|sl|sb)\b')
SEC_RE = re.compile(r'^\s*\d+\s+(\S+)\s+([0-9a-f]+)\s+([0-9a-f]+)\s+[0-9a-f]+\s+([0-9a-f]+)')


class BadInput(Exception):
    pass


class Func:
    def __init__(self, start):
        self.start, self.end, self.size = start, start, 0
        self.names, self.dnames = [], []  # raw and demangled names of the aliases
        self.edges = []  # (target start, kind: call/tail/fall)
        self.indirect_sites = []
        self.unresolved = []  # branches to no function

    def label(self, i=0):
        deleting = self.names[i].endswith('D0Ev')  # demangled D0, D1 and D2 look alike
        return self.dnames[i] + (' [deleting destructor]' if deleting else '')


def objdump(tool, *args):
    try:
        done = subprocess.run([tool, *args], capture_output=True, text=True, errors='replace')
    except OSError as e:
        raise BadInput(f'cannot run objdump {tool!r} ({e.strerror}); use --objdump PATH')
    if done.returncode != 0:
        raise BadInput(f'{tool} {" ".join(args)} failed: {done.stderr.strip()}')
    return done.stdout


def load(tool, elf):
    """Sections {name: (vma, size, bytes or None, flags)}, symbols, entry point."""
    lines, raw, sections = objdump(tool, '-h', elf).splitlines(), open(elf, 'rb').read(), {}
    for line, flag_line in zip(lines, lines[1:]):
        if m := SEC_RE.match(line):
            flags = {f.strip() for f in flag_line.split(',')}
            size, vma, off = int(m[2], 16), int(m[3], 16), int(m[4], 16)
            data = raw[off:off + size] if 'CONTENTS' in flags else None
            sections[m[1]] = (vma, size, data, flags)
    # Both runs list the symbols in the same order: pair each raw name with its demangled one.
    plain = objdump(tool, '-t', '--special-syms', elf).splitlines()
    demangled = objdump(tool, '-t', '--special-syms', '-C', elf).splitlines()
    symbols = []
    for a, b in zip(plain, demangled if len(demangled) == len(plain) else plain):
        if m := SYM_RE.match(a):
            d = SYM_RE.match(b)
            symbols.append((int(m[1], 16), m[2], m[3], int(m[4], 16), m[5], d[5] if d else m[5]))
    entry = re.search(r'start address 0x([0-9a-f]+)', objdump(tool, '-f', elf))
    return sections, symbols, int(entry[1], 16) if entry else None


def word_at(sections, addr):
    for vma, size, data, _ in sections.values():
        if data is not None and vma <= addr <= vma + size - 4:
            return struct.unpack_from('<I', data, addr - vma)[0]
    return None


def build(args):
    """Functions {start: Func} with their edges, and the address-taken function starts."""
    sections, symbols, entry = load(args.objdump, args.elf)
    code = {n for n, s in sections.items() if {'ALLOC', 'CODE'} <= s[3]}
    funcs = {}
    for addr, flags, sec, size, name, dname in symbols:
        if flags[6] == 'F' and sec in code:
            f = funcs.setdefault(addr & ~1, Func(addr & ~1))
            f.names.append(name)
            f.dnames.append(dname)
            f.size = max(f.size, size)
    if not funcs:
        raise BadInput(f'{args.elf}: no function symbols in code sections (stripped?)')
    starts = sorted(funcs)
    sec_ends = sorted(s[0] + s[1] for n, s in sections.items() if n in code)
    for i, start in enumerate(starts):
        limit = min(starts[i + 1] if i + 1 < len(starts) else sec_ends[-1],
                    sec_ends[bisect.bisect_right(sec_ends, start)])
        funcs[start].end = min(start + funcs[start].size, limit) if funcs[start].size else limit

    def containing(addr):
        i = bisect.bisect_right(starts, addr) - 1
        return funcs[starts[i]] if i >= 0 and addr < funcs[starts[i]].end else None

    taken, pool_words, last, movw, adr = set(), set(), {}, {}, {}

    def switch_table(f, start):
        """Whether the words from start (an `adr` address) are a jump table into f: at least
        one, each a Thumb address inside f, up to the first word that is not."""
        count = 0
        while start is not None and (w := word_at(sections, start + 4 * count)) is not None \
                and w & 1 and f.start <= (w & ~1) < f.end:
            count += 1
        return count > 0
    for line in objdump(args.objdump, '-d', '--no-show-raw-insn', args.elf).splitlines():
        m = INSN_RE.match(line)
        f = m and containing(int(m[1], 16))
        if not f:
            continue
        addr, mn, ops = int(m[1], 16), m[2], m[3].split('@')[0].strip()
        if mn.startswith('.'):  # .word, .short, .byte: data in code
            if mn == '.word' and addr % 4 == 0:
                pool_words.add(addr)
            continue
        if not mn.startswith('nop'):  # nop, nop.w: alignment padding
            last[f.start] = (mn, ops)
        b, t = BRANCH_RE.match(mn), TARGET_RE.search(ops)
        if (b or CBZ_RE.match(mn)) and t:
            target = containing(int(t[1], 16))
            if target is None:
                f.unresolved.append(f'{addr:#x}: {mn} {ops}')
            elif target is not f:
                f.edges.append((target.start, 'call' if b and b[1] else 'tail'))
            continue
        base = mn if mn.startswith('tb') else re.sub(rf'{COND}?(\.[nw])?$', '', mn)
        regs = REG_RE.findall(ops)
        after_adr = adr.pop(f.start, None)  # (register, address) of an adr just before
        if table := ADR_RE.search(m[3]):
            adr[f.start] = (table[1], int(table[2], 16))
        if b or base == 'bx':  # blx rN, bx rN
            if ops != 'lr':
                f.indirect_sites.append(addr)
        elif base in ('ldr', 'mov', 'add') and regs[:1] == ['pc']:
            if re.match(r'pc,\s*(\[sp\],\s*#\d+|lr)$', ops):
                continue  # returns: ldr pc, [sp], #N (pop) and mov pc, lr
            jump = TABLE_JUMP_RE.match(ops) if base == 'ldr' else None
            if jump and after_adr and after_adr[0] == jump[1] and switch_table(f, after_adr[1]):
                continue  # a switch: its cases are in the function
            lit = re.match(r'pc,\s*\[pc(?:,\s*#(-?\d+))?\]$', ops) if base == 'ldr' else None
            value = word_at(sections, ((addr + 4) & ~3) + int(lit[1] or 0)) if lit else None
            if value is not None and value & 1 and (value & ~1) in funcs:
                f.edges.append((value & ~1, 'tail'))  # a veneer
            else:
                f.indirect_sites.append(addr)
        elif base.startswith('ldm') and 'pc' in regs and regs[0] != 'sp':
            f.indirect_sites.append(addr)
        elif base in ('movw', 'movt') and regs and (imm := re.search(r'#(\d+)', ops)):
            if base == 'movw':
                movw[(f.start, regs[0])] = int(imm[1])
            elif (f.start, regs[0]) in movw:
                taken.add((int(imm[1]) << 16) | movw[(f.start, regs[0])])
    for f in funcs.values():  # does the last instruction let execution run into the next one?
        mn, ops = last.get(f.start, ('b', ''))
        b, base = BRANCH_RE.match(mn), re.sub(r'\.[nw]$', '', mn)
        regs = REG_RE.findall(ops)
        ends = (b and not b[2]) or base in ('bx', 'udf', 'bkpt') or (
            base in ('ldr', 'mov', 'add') and regs[:1] == ['pc']) or (
            base in ('pop', 'ldm', 'ldmia', 'ldmfd') and 'pc' in regs)
        if not ends and f.end in funcs:
            f.edges.append((f.end, 'fall'))

    # Address-taken: words of allocated sections (in code: literal pools only), movw/movt values.
    excluded = START_UP_SECTIONS + (args.exclude_section or DEFAULT_EXCLUDE_SECTIONS)
    holes = []  # data objects that are vector tables
    entry = entry if entry is not None and entry & 1 and (entry & ~1) in funcs else None
    for addr, flags, sec, size, name, dname in sorted(s for s in symbols if s[1][6] == 'O'):
        named = any(fnmatch.fnmatchcase(n, p) for n in (name, dname)
                    for p in VECTOR_OBJECTS + args.exclude_object)
        second = word_at(sections, addr + 4) if size >= 8 else None
        resets = entry is not None and second in (entry, entry & ~1)
        follows = any(addr == hi for lo, hi in holes)  # the chip's vectors after the core's
        if size > 0 and (named or resets or follows):
            holes.append((addr, addr + size))
    mapped = any(s[4].startswith('$d') for s in symbols)  # else every word in code counts
    for name, (vma, size, data, flags) in sections.items():
        if data is None or 'ALLOC' not in flags or any(
                fnmatch.fnmatchcase(name, p) for p in excluded):
            continue
        for off in range(-vma % 4, size - 3, 4):
            addr = vma + off
            if any(lo <= addr < hi for lo, hi in holes) or (
                    name in code and mapped and containing(addr) and addr not in pool_words):
                continue  # a vector table, or an instruction
            taken.add(struct.unpack_from('<I', data, off)[0])
    return funcs, sorted(w & ~1 for w in taken if w & 1 and (w & ~1) in funcs)


def root_matches(funcs, spec):
    """[(function, alias index)]: exact raw or demangled name, or demangled without the
    parameters; failing that, a glob on either."""
    for exact in (True, False):
        hits = []
        for f in funcs.values():
            for i, (n, d) in enumerate(zip(f.names, f.dnames)):
                if (spec in (n, d, d.split('(')[0]) if exact
                        else fnmatch.fnmatchcase(n, spec) or fnmatch.fnmatchcase(d, spec)):
                    hits.append((f, i))
                    break
        if hits or not any(c in spec for c in '*?['):
            return hits
    return []


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('elf')
    ap.add_argument('--root', action='append', required=True, metavar='SYMBOL',
                    help='an entry of the tick: raw or demangled name, or a glob (repeatable)')
    ap.add_argument('--deny-regex', action='append', default=[], metavar='REGEX',
                    help='also deny functions whose raw or demangled name matches (repeatable)')
    ap.add_argument('--exclude-section', action='append', metavar='GLOB',
                    help='sections whose words take no address (default: .isr_vector, '
                         '.vectors*; .init_array, .fini_array, .preinit_array always)')
    ap.add_argument('--exclude-object', action='append', default=[], metavar='GLOB',
                    help='data objects whose words take no address, besides known vector table '
                         'names, the object holding the entry point and those following it')
    ap.add_argument('--report', metavar='FILE', help='write the reachable functions and sizes')
    ap.add_argument('--no-double-in-image', action='store_true',
                    help='also fail if double-precision soft-float is linked anywhere')
    ap.add_argument('--objdump', default='arm-none-eabi-objdump')
    imd_version.add_argument(ap)
    args = ap.parse_args(argv)
    try:
        if not os.path.isfile(args.elf):
            raise BadInput(f'no such file: {args.elf}')
        try:
            deny = [re.compile(r) for r in DEFAULT_DENY + args.deny_regex]
        except re.error as e:
            raise BadInput(f'bad --deny-regex: {e}')
        funcs, taken = build(args)
        roots = {}  # start -> the name that matched
        for spec in args.root:
            if not (hits := root_matches(funcs, spec)):
                key = spec.split('::')[-1].strip('*?[]').lower()
                near = sorted({f.label() for f in funcs.values() if key in f.label().lower()})
                raise BadInput(f'root not found in {args.elf}: {spec}' +
                               (f' (similar: {", ".join(near[:5])})' if near else ''))
            for f, i in hits:
                roots.setdefault(f.start, f.label(i))
    except (BadInput, OSError) as e:
        print(f'check_tick_path: error: {e}', file=sys.stderr)
        return 2

    forbidden = {}  # start -> the name to show; run-time ABI names (__aeabi_*) first
    for f in funcs.values():
        for i in sorted(range(len(f.names)), key=lambda i: (f.names[i][:8] != '__aeabi_',
                                                            f.names[i])):
            if any(r.search(f.names[i]) or r.search(f.dnames[i]) for r in deny):
                forbidden[f.start] = f.label(i)
                break

    parent = dict.fromkeys(roots)  # start -> (caller start, edge kind); breadth first
    queue, sites = collections.deque(funcs[a] for a in roots), 0
    while queue:
        f = queue.popleft()
        if f.start in forbidden:
            continue
        sites += len(f.indirect_sites)
        for target, kind in f.edges + [(t, 'indirect') for t in taken if f.indirect_sites]:
            if target not in parent:
                parent[target] = (f.start, kind)
                queue.append(funcs[target])
    reached = sorted((funcs[a] for a in parent), key=lambda f: f.start)
    for f in reached:
        for site in f.unresolved:
            print(f'check_tick_path: warning: {f.label()}: branch to no function, not followed '
                  f'({site})', file=sys.stderr)
    name = {f.start: forbidden.get(f.start) or roots.get(f.start) or f.label() for f in reached}
    if args.report:
        try:
            with open(args.report, 'w') as out:
                out.write(f'# Functions reachable from {", ".join(roots.values())} in '
                          f'{os.path.basename(args.elf)} (tools/check_tick_path.py)\n'
                          '# address, size in bytes, name; DENIED: a forbidden function\n')
                for f in reached:
                    out.write(f'{f.start:#010x} {f.end - f.start:6d} {name[f.start]}'
                              f'{"  DENIED" * (f.start in forbidden)}\n')
                out.write(f'# {len(reached)} functions, '
                          f'{sum(f.end - f.start for f in reached)} bytes\n')
        except OSError as e:
            print(f'check_tick_path: error: {e}', file=sys.stderr)
            return 2

    counts = (f'{len(roots)} root{"s" * (len(roots) > 1)}, {len(reached)} functions reachable '
              f'({sites} indirect call sites, {len(taken)} address-taken targets)')
    bad = sorted((f.start for f in reached if f.start in forbidden), key=forbidden.get)
    if not bad:
        print(f'tick path clean: {counts}; no double soft-float, heap or exceptions')
        return check_image_double(funcs) if args.no_double_in_image else 0
    print(f'tick path NOT clean: {len(bad)} forbidden function{"s" * (len(bad) > 1)} reachable '
          f'({counts}); one shortest call chain each:')
    hop = dict(call='', tail='(tail call) ', fall='(falls through) ', indirect='(indirect) ')
    for start in bad:
        chain, node = [], start
        while parent[node] is not None:
            chain.append(hop[parent[node][1]] + name[node])
            node = parent[node][0]
        print(f'  {forbidden[start]}: ' + ' -> '.join([name[node]] + chain[::-1]))
    if args.no_double_in_image:
        check_image_double(funcs)
    return 1


def check_image_double(funcs):
    """1 (and a list: each function with its direct callers) if any function of the image is
    double-precision soft-float, else 0."""
    double = [re.compile(r) for r in DOUBLE_DENY]
    linked = {}  # start -> name shown; run-time ABI names (__aeabi_*) first, as above
    for f in funcs.values():
        for i in sorted(range(len(f.names)), key=lambda i: (f.names[i][:8] != '__aeabi_',
                                                            f.names[i])):
            if any(r.search(f.names[i]) for r in double):
                linked[f.start] = f.label(i)
                break
    if not linked:
        print(f'image free of double precision: none of {len(funcs)} functions')
        return 0
    callers = collections.defaultdict(set)
    for f in funcs.values():
        for target, _ in f.edges:
            if target in linked and f.start not in linked:
                callers[target].add(f.label())
    print(f'image NOT free of double precision: {len(linked)} functions linked; with their '
          'callers outside double code:')
    for start in sorted(linked, key=linked.get):
        print(f'  {linked[start]} <- {", ".join(sorted(callers[start])) or "(double code only)"}')
    return 1


if __name__ == '__main__':
    sys.exit(main())
