"""The qemu guest's initramfs: its /init and /bin/emit scripts, the programs that go into it
(checked to run on the guest's CPU; the busybox that suits it), and the gzip-compressed cpio
archive that carries them with the kernel modules, the test script and the --file files."""
import gzip
import io
import os
import stat
import struct
from pathlib import Path

from guest_arches import ARCHES
from guest_packages import MODULES, SetupError, fetch_package

# Guest files that --binary and --file must not replace.
HARNESS_PATHS = {"/init", "/test.sh", "/bin/emit", "/bin/busybox", "/bin/sh", "/dev/console"}

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
