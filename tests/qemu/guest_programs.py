"""The project's programs for a qemu guest, as qemu_guest.py ships them.

A static program (the aarch64 cross build) goes as it is. A dynamically linked one (the host
build's own drive_hil and drive_monitor, for the x86_64 guest, whose kernel runs the host's
binaries) goes without its debug information (the host preset builds with -g: 50 MB instead of
4), with the dynamic loader and the shared libraries that ldd lists for it, each at its own
path, as on the host. The guest then runs the programs the host tests also run, as a user on a
Debian machine would, and no second build of them is needed."""
import re
import subprocess
from pathlib import Path

from guest_initramfs import elf_info


class ShipError(Exception):
    pass


def ldd_paths(binary):
    """The files the dynamic loader maps for `binary`, by their ldd paths."""
    result = subprocess.run(["ldd", str(binary)], capture_output=True, text=True)
    paths = []
    for line in result.stdout.splitlines():
        if "not found" in line:
            raise ShipError(f"{binary}: {line.strip()} (ldd): install the library first")
        match = re.search(r"(/\S+) \(0x", line)
        if match:
            paths.append(match.group(1))
    return paths


def dynamically_linked(binary):
    info = elf_info(binary)
    return info is not None and info[1] is not None


def stage(programs, directory, already_shipped=()):
    """Copies the programs into `directory` (stripped of debug information if dynamic) and
    returns (programs to pass as --binary, SRC:GUEST_PATH specs to pass as --file) for
    qemu_guest.py. Libraries whose guest path is in `already_shipped` are not repeated."""
    directory.mkdir(parents=True, exist_ok=True)
    binaries, libraries = [], set()
    for program in programs:
        if not dynamically_linked(program):
            binaries.append(program)
            continue
        shipped = directory / program.name
        subprocess.run(["objcopy", "--strip-debug", str(program), str(shipped)], check=True)
        binaries.append(shipped)
        libraries.update(ldd_paths(program))
    files = [f"{Path(library).resolve()}:{library}" for library in sorted(libraries)
             if library not in already_shipped]
    return binaries, files
