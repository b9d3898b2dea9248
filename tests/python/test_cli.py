"""The command line: --version, clear errors for bad flags and values, and send / param /
identify against the fake drive (in-process: the virtual bus lives in this process)."""
import subprocess
import sys
from pathlib import Path

import pytest

import imdrive
from imdrive.cli import main

PACKAGE_DIR = Path(imdrive.__path__[0]).parent


def cli(*args):
    return subprocess.run([sys.executable, "-B", "-m", "imdrive", *args], capture_output=True,
                          text=True, cwd=PACKAGE_DIR)


def test_version_is_the_projects(source_dir):
    cmake = (source_dir / "CMakeLists.txt").read_text()
    version = cmake.split("project(imdrive VERSION ")[1].split()[0]
    result = cli("--version")
    assert result.returncode == 0 and result.stdout.strip() == f"imdrive {version}"


@pytest.mark.parametrize("args, message", [
    (["send", "--can", "vcan0", "--node", "64", "enable"], "--node: must be a node id in 0..63"),
    (["send", "--can", "vcan0", "launch"], "argument WORD: invalid choice: 'launch'"),
    (["watch"], "one of the arguments --can --interface --log is required"),
    (["watch", "--log", "/nonexistent.log"], "/nonexistent.log: cannot open file"),
    (["plot", "--log", "x.log", "--duration-s", "-1"], "--duration-s: must be a time"),
    (["send", "--interface", "virtual", "enable"], "--interface virtual needs --channel"),
])
def test_bad_input_exits_2_and_says_why(args, message):
    result = cli(*args)
    assert result.returncode == 2 and message in result.stderr, result.stderr




def test_send_param_identify_on_the_fake(fake_and_bus, capsys):
    fake, bus = fake_and_bus
    channel = fake.bus.channel_info.split()[-1]  # "Virtual bus channel NAME"
    common = ["--interface", "virtual", "--channel", channel]
    lines = []

    class Out:
        def write(self, text):
            lines.append(text)
    assert main(["send", *common, "set-speed", "12.5"], Out()) == 0
    assert "set_speed speed_ref_rad_s=12.5: accepted" in "".join(lines)
    assert main(["send", *common, "set-speed", "fast"], Out()) == 2
    assert "set-speed: 'fast' is not a number" in capsys.readouterr().err
    assert main(["param", "write", *common, "Rs_Ohm=14", "--save"], Out()) == 0
    assert main(["param", "read", *common, "Rs_Ohm"], Out()) == 0
    assert "Rs_Ohm = 14\n" in "".join(lines)
    assert main(["param", "write", *common, "Ls_H=-1"], Out()) == 3
    assert "write Ls_H: not_positive" in capsys.readouterr().err
    assert main(["identify", *common], Out()) == 0
    assert "identify: done" in "".join(lines)
    fake.refuse = "not_allowed"
    assert main(["send", *common, "enable"], Out()) == 3
    assert "rejected: not_allowed" in capsys.readouterr().err
