"""The project's version. `__version__` is CMakeLists.txt's project(VERSION), carried by the
generated table so that a test catches a stale copy (tests/python/python.cmake).

build_version() is what `imdrive --version` prints: the build's text, as every other tool of
the project prints it ("0.1.0+g1a2b3c4d", ".dirty" for a modified tree), found by
tools/imd_version.py, which sits beside the package in the source tree and is installed with
the version text it reads (cmake/Install.cmake); without it, the table's version."""
import importlib.util
import pathlib

from .protocol_table import PROJECT_VERSION as __version__



def _version_scripts():
    """tools/python/imdrive -> tools/imd_version.py (the source tree);
    <prefix>/lib/python3/dist-packages/imdrive -> <prefix>/share/imdrive/tools/imd_version.py."""
    up = pathlib.Path(__file__).resolve().parent.parents
    if len(up) > 1:
        yield up[1] / "imd_version.py"
    if len(up) > 3:
        yield up[3] / "share" / "imdrive" / "tools" / "imd_version.py"


def build_version():
    for script in _version_scripts():
        if script.is_file():
            spec = importlib.util.spec_from_file_location("imd_version", script)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            text = module.text()
            if text != "unknown":  # installed without its version text
                return text
    return __version__
