"""The project's version for the Python tools' --version, in the C++ tools' form
("0.1.0+g1a2b3c4d", ".dirty" for a modified tree: cmake/WriteVersion.cmake).

Installed (cmake/Install.cmake), the text is the file imd_version.txt beside this module,
written from the build's generated version header. In the source tree it is read from the one
source of truth, the project() line of the top CMakeLists.txt, and git.
"""
import argparse
import pathlib
import re
import subprocess

_HERE = pathlib.Path(__file__).resolve().parent


def _git(*args):
    try:
        done = subprocess.run(["git", "-C", str(_HERE.parent), *args], capture_output=True,
                              text=True, check=False)
    except OSError:  # no git
        return None
    return done.stdout if done.returncode == 0 else None


def text():
    installed = _HERE / "imd_version.txt"
    if installed.is_file():
        return installed.read_text(encoding="utf-8").strip()
    cmake = _HERE.parent / "CMakeLists.txt"
    match = re.search(r"project\(\s*imdrive\s+VERSION\s+(\d+\.\d+\.\d+)",
                      cmake.read_text(encoding="utf-8") if cmake.is_file() else "")
    if not match:  # neither installed nor in the source tree
        return "unknown"
    version = match.group(1)
    # The first 8 digits of the full hash, as cmake/WriteVersion.cmake takes them.
    commit = (_git("rev-parse", "HEAD") or "").strip()[:8]
    if not re.fullmatch(r"[0-9a-f]+", commit):
        return f"{version}+gunknown"
    status = _git("status", "--porcelain", "--untracked-files=no")
    return f"{version}+g{commit}" + (".dirty" if status else "")


class _VersionAction(argparse.Action):
    """Prints text() and exits; asks git only when given."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS,
                 help="print the version and exit"):
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        print(text())
        parser.exit()


def add_argument(parser):
    """Adds --version to an argparse parser."""
    parser.add_argument("--version", action=_VersionAction)
