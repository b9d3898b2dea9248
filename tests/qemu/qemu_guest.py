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
import base64
import fcntl
import gzip
import hashlib
import io
import json
import lzma
import os
import re
import selectors
import shutil
import signal
import stat
import struct
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

# Per guest architecture: Debian's name for it, QEMU's command line, the serial console's name,
# and the ELF machine number its programs carry (to reject an x86 binary shipped to an arm guest).
ARCHES = {
    "x86_64": {
        "debian": "amd64",
        # The default PC machine; its 16550 UART is ttyS0, ACPI makes `poweroff -f` end QEMU.
        "qemu_args": ["-M", "pc"],
        "console": "ttyS0",
        "elf_machine": 62,  # EM_X86_64
    },
    "aarch64": {
        "debian": "arm64",
        # `virt` has the PL011 UART (ttyAMA0), PSCI for power-off, and the PL061 GPIO controller
        # (gpiochip0, 8 lines; line 3 is QEMU's power button). Cortex-A53 because TCG emulates it
        # faster than `max` (no pointer authentication to emulate).
        "qemu_args": ["-M", "virt", "-cpu", "cortex-a53"],
        "console": "ttyAMA0",
        "elf_machine": 183,  # EM_AARCH64
    },
}

# The SocketCAN modules, in load order (busybox insmod does not resolve dependencies: vcan needs
# can-dev, can-raw needs can), as paths under lib/modules/<version>/kernel/.
MODULES = [
    ("can", "net/can/can.ko"),
    ("can-dev", "drivers/net/can/dev/can-dev.ko"),
    ("can-raw", "net/can/can-raw.ko"),
    ("vcan", "drivers/net/can/vcan.ko"),
]
# What is unpacked from the kernel package: its boot/ files and a few module directories, not the
# ~400 MB of all modules. The CAN and GPIO driver directories are kept whole so that a later test
# can add e.g. can-bcm, vxcan or gpio-sim by editing MODULES alone.
KERNEL_SUBTREES = ["net/can/", "drivers/net/can/", "drivers/gpio/"]

# Console markers between the guest's /init, /bin/emit and this script. Distinctive enough that a
# test's own output does not contain them by accident.
MARK = "@@qemu_guest:"
START_RE = re.compile(re.escape(MARK) + r"start uptime_s=(\S+)")
END_RE = re.compile(re.escape(MARK) + r"end rc=(\d+) uptime_s=(\S+)")
SETUP_FAILED_RE = re.compile(re.escape(MARK) + r"setup-failed (.*)")
EMIT_BEGIN_RE = re.compile(re.escape(MARK) + r"emit-begin (\S+)")
EMIT_END_RE = re.compile(re.escape(MARK) + r"emit-end (\S+) (\d+) ([0-9a-f]{64})")
BASE64_LINE_RE = re.compile(r"^[A-Za-z0-9+/=]+$")
EMIT_NAME_RE = re.compile(r"^[A-Za-z0-9._-]+$")

# Guest files that --binary and --file must not replace.
HARNESS_PATHS = {"/init", "/test.sh", "/bin/emit", "/bin/busybox", "/bin/sh", "/dev/console"}

# How long QEMU may take to exit after the end marker (poweroff -f is immediate; this is slack).
POWEROFF_GRACE_S = 15.0
# Lines of the console printed when the run fails.
TAIL_LINES = 40

INIT_SCRIPT = r"""#!/bin/busybox sh
# PID 1 of the qemu test guest, written by tests/qemu/qemu_guest.py.
/bin/busybox --install -s
export PATH=/bin:/sbin:/usr/bin:/usr/sbin

# Anything that goes wrong before the test is the harness's fault, not the test's: say so and stop.
setup_failed() {
  echo "@@qemu_guest:setup-failed $*"
  poweroff -f
}
mount -t proc proc /proc || setup_failed "mount /proc"
mount -t sysfs sysfs /sys || setup_failed "mount /sys"
mount -t devtmpfs devtmpfs /dev || setup_failed "mount /dev"
mount -t debugfs debugfs /sys/kernel/debug || setup_failed "mount /sys/kernel/debug"
mount -t tmpfs tmpfs /tmp || setup_failed "mount /tmp"

for module in @MODULES@; do
  insmod /lib/modules/guest/$module.ko || setup_failed "insmod $module.ko"
done
ip link add dev vcan0 type vcan || setup_failed "ip link add vcan0"
ip link set vcan0 up || setup_failed "ip link set vcan0 up"

echo "@@qemu_guest:start uptime_s=$(cut -d ' ' -f 1 /proc/uptime)"
cd /
/test.sh < /dev/null
rc=$?
echo "@@qemu_guest:end rc=$rc uptime_s=$(cut -d ' ' -f 1 /proc/uptime)"
sync
poweroff -f
"""

EMIT_SCRIPT = r"""#!/bin/sh
# emit NAME FILE: ships FILE to the host, where qemu_guest.py writes it to <work>/out/NAME.
# Prints it base64-encoded between markers on /dev/console (whatever the caller's stdout is),
# with its size and SHA-256 so that the host notices damage. Call it from the foreground: other
# processes printing to the console at the same time would corrupt the block.
if [ $# -ne 2 ]; then echo "usage: emit NAME FILE" >&2; exit 2; fi
case "$1" in
  "" | . | .. | *[!A-Za-z0-9._-]*)
    echo "emit: bad name '$1' (letters, digits, . _ -)" >&2; exit 2 ;;
esac
if [ ! -f "$2" ]; then echo "emit: no file $2" >&2; exit 2; fi
size=$(stat -c %s "$2")
sum=$(sha256sum "$2" | cut -d ' ' -f 1)
# Kernel messages would land in the middle of the block: only emergencies while it is printed.
saved=$(cut -f 1 /proc/sys/kernel/printk)
echo 1 > /proc/sys/kernel/printk
{
  echo "@@qemu_guest:emit-begin $1"
  base64 "$2"
  echo "@@qemu_guest:emit-end $1 $size $sum"
} > /dev/console
echo "$saved" > /proc/sys/kernel/printk
"""


class SetupError(Exception):
    """A problem with the host, the arguments or the packages: exit code 2 and this message."""


# ----------------------------------------------------------------------------------------------
# Fetching and caching the Debian packages


def run_tool(argv, what):
    """Runs a host tool, returning its stdout; a failure becomes a SetupError naming `what`."""
    try:
        result = subprocess.run(argv, capture_output=True, text=True)
    except FileNotFoundError:
        raise SetupError(f"{what}: {argv[0]} not found (is this Debian? "
                         f"tools/install_deps.sh --qemu)")
    if result.returncode != 0:
        output = (result.stdout + result.stderr).strip()
        raise SetupError(f"{what} failed: {' '.join(argv)}\n{output}")
    return result.stdout


def apt_output(cache, argv, what):
    """run_tool for apt queries, remembered in <cache>/apt-answers.json: apt takes 1-2 s to start
    and the qemu tests each ask it twice or thrice, but its answers only change with its package
    lists, which apt-get update replaces (changing the lists directory's modification time)."""
    try:
        stamp = Path("/var/lib/apt/lists").stat().st_mtime_ns
    except OSError:
        stamp = None
    memo_path = cache / "apt-answers.json"
    memo = {}
    try:
        memo = json.loads(memo_path.read_text())
    except (OSError, ValueError):
        pass
    if stamp is None or memo.get("stamp") != stamp:
        memo = {"stamp": stamp, "answers": {}}
    key = " ".join(argv)
    if key not in memo["answers"]:
        memo["answers"][key] = run_tool(argv, what)  # failures raise, so are never remembered
        # Written whole and renamed: a concurrent run reads the old memo or this one, never half.
        with tempfile.NamedTemporaryFile("w", dir=cache, prefix=".apt-answers-", delete=False) as f:
            json.dump(memo, f, indent=1)
        os.chmod(f.name, 0o644)
        os.replace(f.name, memo_path)
    return memo["answers"][key]


def check_dpkg_architecture(debian_arch):
    """apt can only fetch packages of architectures dpkg knows (native or added as foreign)."""
    native = run_tool(["dpkg", "--print-architecture"], "asking dpkg its architecture").strip()
    foreign = run_tool(["dpkg", "--print-foreign-architectures"],
                       "asking dpkg its foreign architectures").split()
    if debian_arch != native and debian_arch not in foreign:
        raise SetupError(
            f"dpkg does not know the {debian_arch} architecture, so apt cannot fetch the guest's "
            f"kernel and busybox: run dpkg --add-architecture {debian_arch} && apt-get update "
            f"(tools/install_deps.sh --qemu does this for arm64)")


def resolve_kernel_package(cache, debian_arch):
    """linux-image-<arch> is a metapackage; the real kernel is the linux-image-<abi>-<arch> it
    depends on, e.g. linux-image-6.1.0-56-arm64:arm64."""
    meta = f"linux-image-{debian_arch}:{debian_arch}"
    output = apt_output(cache, ["apt-cache", "depends", meta], f"resolving {meta}")
    for line in output.splitlines():
        match = re.match(r"\s*\|?Depends:\s*(linux-image-\S+)", line)
        if match:
            package = match.group(1)
            # apt-cache leaves the architecture off native packages; apt-get download wants it
            # for foreign ones, and accepts it for native ones.
            return package if ":" in package else f"{package}:{debian_arch}"
    raise SetupError(f"apt-cache depends {meta} names no linux-image package:\n{output}\n"
                     f"(apt lists missing? run apt-get update or tools/install_deps.sh --qemu)")


def package_file_name(cache, package):
    """The .deb file name apt-get download would write, asked without downloading anything (the
    cache key: it changes with every new package version)."""
    output = apt_output(cache, ["apt-get", "download", "--print-uris", package],
                        f"looking up {package}")
    for line in output.splitlines():
        fields = line.split()
        if len(fields) >= 2 and fields[1].endswith(".deb"):
            return fields[1]
    raise SetupError(f"apt-get download --print-uris {package} printed no .deb:\n{output}\n"
                     f"(run apt-get update or tools/install_deps.sh --qemu)")


def members_of_deb(deb, wanted):
    """Yields (path without the leading ./, member, tar) for the members of `deb`'s data archive
    that `wanted(path)` accepts. dpkg-deb decompresses whatever compression the package uses."""
    process = subprocess.Popen(["dpkg-deb", "--fsys-tarfile", str(deb)], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE)
    # A stream ("r|"): the archive is read once, front to back, without seeking.
    with tarfile.open(fileobj=process.stdout, mode="r|") as tar:
        for member in tar:
            path = member.name[2:] if member.name.startswith("./") else member.name
            if wanted(path):
                yield path, member, tar
    process.stdout.close()
    if process.wait() != 0:
        raise SetupError(f"dpkg-deb --fsys-tarfile {deb} failed: "
                         f"{process.stderr.read().decode().strip()}")


def unpack_deb(deb, destination, wanted):
    """Writes the regular files of `deb` that `wanted` accepts under `destination` (only files:
    no symlinks or device nodes, and nothing outside `destination`)."""
    for path, member, tar in members_of_deb(deb, wanted):
        if not member.isfile() or ".." in Path(path).parts or path.startswith("/"):
            continue
        target = destination / path
        target.parent.mkdir(parents=True, exist_ok=True)
        with tar.extractfile(member) as source, open(target, "wb") as sink:
            shutil.copyfileobj(source, sink)
        os.chmod(target, member.mode & 0o755)


def fetch_package(package, cache, wanted):
    """The directory under `cache` holding the parts of `package` that `wanted` accepts, fetched
    and unpacked on first use. Concurrent runs (ctest -j) take a lock per package file, and the
    directory only appears, by rename, once complete: an interrupted unpack leaves no half tree."""
    file_name = package_file_name(cache, package)
    unpacked = cache / "unpacked" / file_name.removesuffix(".deb")
    if unpacked.is_dir():
        return unpacked
    (cache / "unpacked").mkdir(parents=True, exist_ok=True)
    with open(cache / f".{file_name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if unpacked.is_dir():  # another run fetched it while this one waited for the lock
            return unpacked
        print(f"qemu_guest: fetching {package} ({file_name}) into {cache}", flush=True)
        with tempfile.TemporaryDirectory(dir=cache, prefix=".fetch-") as scratch:
            scratch = Path(scratch)
            # apt-get download writes to the current directory. As root, apt warns that its _apt
            # user cannot write there and downloads as root: harmless, and only shown on failure.
            result = subprocess.run(["apt-get", "download", package], cwd=scratch,
                                    capture_output=True, text=True)
            deb = scratch / file_name
            if result.returncode != 0 or not deb.is_file():
                raise SetupError(
                    f"apt-get download {package} failed (no network or apt mirror? stale apt "
                    f"lists? try apt-get update):\n{(result.stdout + result.stderr).strip()}")
            tree = scratch / "tree"
            unpack_deb(deb, tree, wanted)
            os.rename(tree, unpacked)
    return unpacked


def kernel_file_wanted(path):
    """The parts of a linux-image package the guest needs (see KERNEL_SUBTREES)."""
    if path.startswith("boot/"):
        return True
    match = re.match(r"lib/modules/[^/]+/(.*)", path)
    if not match:
        return False
    rest = match.group(1)
    return (rest.startswith("modules.") or
            any(rest.startswith("kernel/" + subtree) for subtree in KERNEL_SUBTREES))


def find_kernel(tree, package):
    """(vmlinuz, {module name: .ko or .ko.xz path}) of an unpacked kernel package."""
    kernels = sorted((tree / "boot").glob("vmlinuz-*"))
    module_roots = sorted((tree / "lib" / "modules").glob("*/kernel"))
    if len(kernels) != 1 or len(module_roots) != 1:
        raise SetupError(f"{package} unpacked in {tree}: expected one boot/vmlinuz-* and one "
                         f"lib/modules/<version>/, found {kernels} and {module_roots}")
    modules = {}
    for name, relative in MODULES:
        # Plain .ko (Debian 12), or .ko.xz as later Debian kernels ship them.
        candidates = [module_roots[0] / relative, module_roots[0] / (relative + ".xz")]
        found = [path for path in candidates if path.is_file()]
        if not found:
            directory = candidates[0].parent
            present = sorted(p.name for p in directory.glob("*")) if directory.is_dir() else []
            raise SetupError(f"{package}: module {name} is not in the kernel package (looked for "
                             f"{candidates[0]}[.xz]; {directory.name}/ holds "
                             f"{', '.join(present) or 'nothing'}): was it renamed or built in? "
                             f"update MODULES in qemu_guest.py")
        modules[name] = found[0]
    return kernels[0], modules


def module_bytes(path):
    """The module's ELF bytes, decompressed here so that busybox insmod never needs to."""
    data = path.read_bytes()
    return lzma.decompress(data) if path.suffix == ".xz" else data


def check_module_dependencies(modules):
    """Each module's `depends=` (in its .modinfo section) must be loaded before it, by MODULES'
    order: a new kernel that splits a module differently fails here, not as an insmod error."""
    loaded = set()
    for name, _ in MODULES:
        match = re.search(rb"(?:^|\0)depends=([^\0]*)", modules[name])
        # modinfo spells module names with underscores (can_dev); MODULES with dashes.
        names = match.group(1).decode().split(",") if match else []
        needs = {d.replace("_", "-") for d in names if d}
        missing = needs - loaded
        if missing:
            raise SetupError(f"module {name} depends on {', '.join(sorted(missing))}, which "
                             f"qemu_guest.py does not load before it: update MODULES")
        loaded.add(name)


# ----------------------------------------------------------------------------------------------
# ELF checks for the programs shipped to the guest


def elf_info(path):
    """(e_machine, program interpreter or None) of a 64-bit little-endian ELF, or None."""
    data = path.read_bytes()
    if data[:4] != b"\x7fELF" or data[4] != 2 or data[5] != 1:
        return None
    e_machine = struct.unpack_from("<H", data, 18)[0]
    e_phoff = struct.unpack_from("<Q", data, 32)[0]
    e_phentsize, e_phnum = struct.unpack_from("<HH", data, 54)
    for i in range(e_phnum):
        header = e_phoff + i * e_phentsize
        p_type, _, p_offset, _, _, p_filesz = struct.unpack_from("<IIQQQQ", data, header)
        if p_type == 3:  # PT_INTERP: dynamically linked
            return e_machine, data[p_offset:p_offset + p_filesz].rstrip(b"\0").decode()
    return e_machine, None


def check_guest_program(path, arch, shipped_paths):
    """A program for /bin must be an ELF for the guest's CPU, and either static or accompanied
    (through --file) by its dynamic loader; scripts (#!) pass as they are."""
    if path.read_bytes()[:2] == b"#!":
        return
    info = elf_info(path)
    if info is None:
        raise SetupError(f"--binary {path}: not a 64-bit little-endian ELF program or a #! script")
    machine, interpreter = info
    if machine != ARCHES[arch]["elf_machine"]:
        raise SetupError(f"--binary {path}: built for ELF machine {machine}, not {arch} "
                         f"(wrong build directory?)")
    if interpreter and interpreter not in shipped_paths:
        raise SetupError(f"--binary {path} is dynamically linked ({interpreter}); the guest has no "
                         f"libraries: link it with -static, or ship the loader and libraries with "
                         f"--file SRC:GUEST_PATH")


def busybox_for(arch, cache):
    """The host's /bin/busybox when it is a static binary for the guest's CPU (busybox-static on
    an x86_64 host with an x86_64 guest), else busybox-static for the guest's architecture."""
    host = Path("/bin/busybox")
    if host.is_file():
        info = elf_info(host)
        if info == (ARCHES[arch]["elf_machine"], None):
            return host
    debian_arch = ARCHES[arch]["debian"]
    tree = fetch_package(f"busybox-static:{debian_arch}", cache, lambda p: p == "bin/busybox")
    return tree / "bin" / "busybox"


# ----------------------------------------------------------------------------------------------
# The initramfs: a gzip-compressed cpio archive in the kernel's "newc" format, written here so that
# owners, modes and /dev/console need neither root nor a host cpio.


class Cpio:
    def __init__(self):
        self.out = io.BytesIO()
        self.inode = 1
        self.dirs = set()

    def _entry(self, name, mode, data=b"", rdev=(0, 0)):
        name_bytes = name.encode() + b"\0"
        # ino, mode, uid, gid, nlink, mtime, filesize, dev major/minor, rdev major/minor,
        # namesize, check: root owns everything, all times are 0 (the archive is reproducible).
        fields = [self.inode, mode, 0, 0, 1, 0, len(data), 0, 0, rdev[0], rdev[1],
                  len(name_bytes), 0]
        self.inode += 1
        self.out.write(b"070701" + b"".join(b"%08X" % f for f in fields) + name_bytes)
        self.out.write(b"\0" * (-(110 + len(name_bytes)) % 4))  # the header is 110 bytes
        self.out.write(data + b"\0" * (-len(data) % 4))

    def directory(self, path):
        """A directory and its parents, each once: the kernel's unpacker does not create parents."""
        parts = Path(path).parts[1:]
        for i in range(1, len(parts) + 1):
            name = "/".join(parts[:i])
            if name not in self.dirs:
                self.dirs.add(name)
                self._entry(name, stat.S_IFDIR | 0o755)

    def file(self, path, data, mode=0o644):
        self.directory(str(Path(path).parent))
        self._entry(path.lstrip("/"), stat.S_IFREG | mode, data)

    def char_device(self, path, mode, major, minor):
        self.directory(str(Path(path).parent))
        self._entry(path.lstrip("/"), stat.S_IFCHR | mode, rdev=(major, minor))

    def finish(self):
        self._entry("TRAILER!!!", 0)
        return self.out.getvalue()


def build_initramfs(path, busybox, modules, guest_script, binaries, files):
    cpio = Cpio()
    for directory in ["/bin", "/sbin", "/usr/bin", "/usr/sbin", "/proc", "/sys", "/dev", "/tmp",
                      "/root", "/lib/modules/guest"]:
        cpio.directory(directory)
    # The kernel opens /dev/console for init's stdin/stdout before devtmpfs is mounted.
    cpio.char_device("/dev/console", 0o600, 5, 1)
    cpio.file("/bin/busybox", busybox.read_bytes(), 0o755)
    init = INIT_SCRIPT.replace("@MODULES@", " ".join(name for name, _ in MODULES))
    cpio.file("/init", init.encode(), 0o755)
    cpio.file("/bin/emit", EMIT_SCRIPT.encode(), 0o755)
    for name, data in modules.items():
        cpio.file(f"/lib/modules/guest/{name}.ko", data)
    for binary in binaries:
        cpio.file(f"/bin/{binary.name}", binary.read_bytes(), 0o755)
    for source, guest_path in files:
        if source.is_file():
            sources = [source]
        else:
            sources = sorted(p for p in source.rglob("*") if p.is_file())
        for item in sources:
            target = guest_path if item == source else f"{guest_path}/{item.relative_to(source)}"
            cpio.file(target, item.read_bytes(), 0o755 if os.access(item, os.X_OK) else 0o644)
    cpio.file("/test.sh", guest_script.read_bytes(), 0o755)
    # Level 1: the archive is written on every run and read once; size matters less than time.
    path.write_bytes(gzip.compress(cpio.finish(), compresslevel=1, mtime=0))


# ----------------------------------------------------------------------------------------------
# Running QEMU and following its console


class Console:
    """Follows the guest's console line by line: writes console.log, notes when the markers
    arrive (host time), and collects the files the guest emits."""

    def __init__(self, log_path, out_dir, started):
        self.log = open(log_path, "w", encoding="utf-8", errors="replace")
        self.out_dir = out_dir
        self.started = started
        self.start_time = None   # host seconds since QEMU started, at the start marker
        self.guest_uptime_at_start = None
        self.end_time = None
        self.exit_code = None
        self.setup_failure = None
        self.panic = None        # the kernel's "Kernel panic - ..." line, if it printed one
        self.emitting = None     # (name, base64 lines) inside an emit block
        self.emitted = []
        self.damaged = []
        self.tail = []
        self.partial = b""

    def feed(self, data):
        self.partial += data
        *lines, self.partial = self.partial.split(b"\n")
        for line in lines:
            self._line(line.decode("utf-8", errors="replace").rstrip("\r"))

    def flush(self):
        if self.partial:
            self._line(self.partial.decode("utf-8", errors="replace").rstrip("\r"))
            self.partial = b""
        self.log.flush()

    def _record(self, line):
        self.log.write(line + "\n")
        self.tail = (self.tail + [line])[-TAIL_LINES:]

    def _line(self, line):
        now = time.monotonic() - self.started
        if self.emitting is not None:
            name, chunks = self.emitting
            end = EMIT_END_RE.search(line)
            if end and end.group(1) == name:
                self._finish_emit(name, chunks, int(end.group(2)), end.group(3))
                self._record(line)
            elif BASE64_LINE_RE.match(line):
                chunks.append(line)  # payload: out/NAME has it, console.log need not
            else:
                self._record(line)   # anything else that reached the console meanwhile
            return
        self._record(line)
        if self.panic is None and "Kernel panic - " in line:
            self.panic = line[line.index("Kernel panic - "):]
        if match := EMIT_BEGIN_RE.search(line):
            self.emitting = (match.group(1), [])
        elif match := START_RE.search(line):
            self.start_time = now
            self.guest_uptime_at_start = float(match.group(1))
        elif match := END_RE.search(line):
            self.end_time = now
            self.exit_code = int(match.group(1))
        elif match := SETUP_FAILED_RE.search(line):
            self.setup_failure = match.group(1)

    def _finish_emit(self, name, chunks, size, sha256):
        self.emitting = None
        self._record(f"[qemu_guest.py: {len(chunks)} lines of base64 for out/{name} elided]")
        try:
            data = base64.b64decode("".join(chunks), validate=True)
        except ValueError:
            data = None
        if not EMIT_NAME_RE.match(name) or name in (".", ".."):
            self.damaged.append(f"{name}: not a valid file name")
        elif data is None or len(data) != size or hashlib.sha256(data).hexdigest() != sha256:
            decoded = 0 if data is None else len(data)
            self.damaged.append(f"{name}: damaged in transit ({decoded} of "
                                f"{size} bytes decoded, checksum mismatch; kernel messages or "
                                f"other output interleaved?)")
        else:
            (self.out_dir / name).write_bytes(data)
            self.emitted.append(name)


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
        check_guest_program(binary, arch, {guest_path for _, guest_path in files})

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
