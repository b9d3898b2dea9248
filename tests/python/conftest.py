"""pytest set-up for the Python client: the package from tools/python, the fake drive from
here, the C++ programs from the build (tests/python/python.cmake passes their paths)."""
import subprocess
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1] / "tools" / "python"))
sys.path.insert(0, str(HERE))


def pytest_addoption(parser):
    parser.addoption("--drive-sim", help="build/bin/drive_sim")
    parser.addoption("--e2e-vectors", help="build/bin/e2e_vectors")
    parser.addoption("--source-dir", default=str(HERE.parents[1]))


def pytest_configure(config):
    config.addinivalue_line("markers", "sim: runs the simulator (drive_sim) to make CAN logs")
    # python-can 4.1 on Python 3.11 asks entry_points() the old way; not this project's to fix.
    config.addinivalue_line("filterwarnings", "ignore:SelectableGroups:DeprecationWarning")


def _program(config, option):
    path = config.getoption(option)
    if not path or not Path(path).is_file():
        pytest.fail(f"--{option.replace('_', '-')} must name the built program (got {path})")
    return path


@pytest.fixture(scope="session")
def source_dir(pytestconfig):
    return Path(pytestconfig.getoption("source_dir"))


@pytest.fixture(scope="session")
def e2e_vectors(pytestconfig):
    return _program(pytestconfig, "e2e_vectors")


@pytest.fixture(scope="session")
def realistic_log(pytestconfig, source_dir, tmp_path_factory):
    """drive_sim's CAN log of the seed-000 realistic scenario (8 s simulated, ~2700 frames)."""
    drive_sim = _program(pytestconfig, "drive_sim")
    log = tmp_path_factory.mktemp("logs") / "realistic.log"
    subprocess.run([drive_sim, str(source_dir / "hal_sim/scenarios/seed000_realistic.toml"),
                    "--can-log", str(log)], check=True, stdout=subprocess.DEVNULL)
    return log


_channel = [0]


@pytest.fixture
def fake_and_bus():
    """A FakeDrive (node 1) and a client bus on a fresh virtual channel."""
    import can
    from fake_drive import FakeDrive
    _channel[0] += 1
    channel = f"imdrive-test-{_channel[0]}"
    fake = FakeDrive(channel)
    fake.wait_idle()
    bus = can.Bus(interface="virtual", channel=channel)
    yield fake, bus
    bus.shutdown()
    fake.close()
