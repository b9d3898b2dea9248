"""The Debian packages a qemu guest is made of: asking apt which kernel package is current,
fetching packages with `apt-get download` into a cache and unpacking the parts wanted, and finding
the kernel and the SocketCAN modules (MODULES) in the unpacked kernel package."""
import fcntl
import json
import lzma
import os
import re
import shutil
import subprocess
import tarfile
import tempfile
from pathlib import Path

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


class SetupError(Exception):
    """A problem with the host, the arguments or the packages: exit code 2 and this message."""


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
                             f"update MODULES in guest_packages.py")
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
                             f"qemu_guest.py does not load before it: update MODULES in "
                             f"guest_packages.py")
        loaded.add(name)
