"""The project's version (CMakeLists.txt's project(VERSION)), carried by the generated table so
that a test catches a stale copy (tests/python/python.cmake)."""
from .protocol_table import PROJECT_VERSION as __version__
