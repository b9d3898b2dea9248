"""The host's Python for the qemu guest: /usr/bin/python3 with the shared libraries ldd lists for
it and for the extension modules shipped, the standard library without what a test never
imports (tests, IDLE, tkinter, ensurepip, lib2to3, pydoc_data, bytecode caches), and python3-can
with the Debian packages it depends on. Staged as a directory tree that mirrors the guest's
root, to be shipped with qemu_guest.py --file DIR:/ (one --file per top-level directory)."""
import shutil
import sys
from pathlib import Path

from guest_programs import ldd_paths

STDLIB_SKIP = {"test", "idlelib", "tkinter", "ensurepip", "lib2to3", "pydoc_data", "turtledemo",
               "__pycache__", "site-packages", "dist-packages", "unittest", "distutils"}
# python3-can and what it imports (its Depends: python3-pkg-resources, -serial, -msgpack,
# -packaging, -typing-extensions, -wrapt).
DIST_PACKAGES = ["can", "pkg_resources", "serial", "msgpack", "packaging", "wrapt",
                 "typing_extensions.py"]
DIST_DIR = Path("/usr/lib/python3/dist-packages")


def copy_tree(source, target, skip=()):
    for item in sorted(source.rglob("*")):
        relative = item.relative_to(source)
        if any(part in skip for part in relative.parts) or not item.is_file():
            continue
        destination = target / relative
        destination.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(item, destination)


def stage(root, package_dir):
    """Writes the tree under `root`; returns the top-level directories to ship."""
    shutil.rmtree(root, ignore_errors=True)
    version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    interpreter = Path("/usr/bin") / version
    (root / "usr/bin").mkdir(parents=True)
    shutil.copy2(interpreter, root / "usr/bin/python3")
    stdlib = Path("/usr/lib") / version
    copy_tree(stdlib, root / "usr/lib" / version, STDLIB_SKIP)
    for name in DIST_PACKAGES:
        source = DIST_DIR / name
        if source.is_dir():
            copy_tree(source, root / "usr/lib/python3/dist-packages" / name, {"__pycache__"})
        else:
            (root / "usr/lib/python3/dist-packages").mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, root / "usr/lib/python3/dist-packages" / name)
    copy_tree(package_dir / "imdrive", root / "py/imdrive", {"__pycache__"})
    libraries = set(ldd_paths(interpreter))
    for extension in root.rglob("*.so"):
        libraries.update(ldd_paths(extension))
    for library in sorted(libraries):
        destination = root / library.lstrip("/")
        destination.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(Path(library).resolve(), destination)
        destination.chmod(0o755)
    return sorted(p for p in root.iterdir() if p.is_dir())
