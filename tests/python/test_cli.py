"""The command line: --version, clear errors for bad flags and values, and send / param /
identify against the fake drive (in-process: the virtual bus lives in this process)."""
import argparse
import importlib.util
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import imdrive
from imdrive.cli import _check_plot_target, main

PACKAGE_DIR = Path(imdrive.__path__[0]).parent


def cli(*args):
    return subprocess.run([sys.executable, "-B", "-m", "imdrive", *args], capture_output=True,
                          text=True, cwd=PACKAGE_DIR)


def _load_imd_version(source_dir):
    path = source_dir / "tools/imd_version.py"
    spec = importlib.util.spec_from_file_location("imd_version", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_version_is_the_builds_as_every_tool_prints_it(source_dir):
    """From the source tree: what tools/imd_version.py prints for the other tools,
    0.1.0+g<commit>[.dirty], the project() version first."""
    cmake = (source_dir / "CMakeLists.txt").read_text()
    version = cmake.split("project(imdrive VERSION ")[1].split()[0]
    result = cli("--version")
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == _load_imd_version(source_dir).text()
    assert re.fullmatch(re.escape(version) + r"\+g([0-9a-f]{8}|unknown)(\.dirty)?",
                        result.stdout.strip())


def test_version_installed_and_bare(source_dir, tmp_path):
    """Installed as cmake/Install.cmake lays it out, with the build's version text; and the
    package alone (as the qemu test ships it): the table's version."""
    installed = tmp_path / "prefix"
    shutil.copytree(PACKAGE_DIR / "imdrive", installed / "lib/python3/dist-packages/imdrive")
    tools = installed / "share/imdrive/tools"
    tools.mkdir(parents=True)
    shutil.copy(source_dir / "tools/imd_version.py", tools)
    (tools / "imd_version.txt").write_text("0.1.0+g0123abcd.dirty\n")
    bare = tmp_path / "bare"
    shutil.copytree(PACKAGE_DIR / "imdrive", bare / "imdrive")
    for where, expected in ((installed / "lib/python3/dist-packages", "0.1.0+g0123abcd.dirty"),
                            (bare, imdrive.__version__)):
        result = subprocess.run([sys.executable, "-B", "-m", "imdrive", "--version"],
                                capture_output=True, text=True, cwd=where)
        assert result.returncode == 0 and result.stdout.strip() == expected, result.stderr


def test_watch_a_shared_bus_capture_counts_every_frame(source_dir, capsys):
    """tests/data/can/shared_bus.log, whose composition test_logs.py lists: the summary counts
    what drive_monitor's does (docs/can/protocol.md quotes its line), and the 2 lost frames."""
    assert main(["watch", "--log", str(source_dir / "tests/data/can/shared_bus.log")]) == 0
    err = capsys.readouterr().err
    assert ("imdrive: 47 frames: 30 decoded (26 from node 1, 4 commands to it), 5 samples; "
            "skipped: 3 error frames, 3 with 29-bit ids, 2 CAN FD, 2 remote, 6 of other nodes "
            "(node 2: 6), 1 of unknown messages, 0 of wrong length; the capture lost 2 frames"
            in err), err


def test_watch_of_a_silent_node_warns_and_exits_4(source_dir, capsys):
    log = source_dir / "tests/data/can/node2_only.log"
    assert main(["watch", "--log", str(log)]) == 4
    err = capsys.readouterr().err
    assert f"imdrive: warning: no frame from node 1 on {log}; heard only other nodes " \
           f"(node 2: 7): is --node right?" in err, err
    assert main(["watch", "--log", str(log), "--node", "2"]) == 0


@pytest.mark.parametrize("args, message", [
    (["send", "--can", "vcan0", "--node", "64", "enable"], "--node: must be a node id in 0..63"),
    (["send", "--can", "vcan0", "launch"], "argument WORD: invalid choice: 'launch'"),
    (["watch"], "one of the arguments --can --socketcand --interface --log is required"),
    (["watch", "--log", "/nonexistent.log"], "/nonexistent.log: cannot open file"),
    (["plot", "--log", "x.log", "--duration-s", "-1"], "--duration-s: must be a time"),
    (["send", "--interface", "virtual", "enable"], "--interface virtual needs --channel"),
    (["plot", "--log", "x.log", "--save", "out.txt"], "--save out.txt: the file name must end in .png"),
    (["plot", "--log", "x.log", "--save", "/nonexistent/p.png"], "no directory /nonexistent"),
    (["watch", "--log", "../../tests/data/can/shared_bus.log", "--csv", "/nonexistent/x.csv"],
     "--csv /nonexistent/x.csv: cannot write the file"),
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


def test_watch_warns_of_a_drive_on_another_protocol(tmp_path, capsys):
    from imdrive import frames, table

    def line(time_s, message):
        return f"({time_s:.6f}) can0 {message.arbitration_id:03X}#{message.data.hex().upper()}"
    log = tmp_path / "other_protocol.log"
    log.write_text("\n".join([
        line(0.0, frames.encode_message("version", 1, protocol_version=table.PROTOCOL_VERSION + 1,
                                        firmware_minor=2, git_hash=0xA2E14617)),
        line(0.0001, frames.encode_message("heartbeat", 1, state="calibrating"))]) + "\n")
    assert main(["watch", "--log", str(log)]) == 0
    assert (f"imdrive: warning: node 1 speaks protocol {table.PROTOCOL_VERSION + 1} (firmware "
            f"0.2.0+ga2e14617), this client protocol {table.PROTOCOL_VERSION}"
            in capsys.readouterr().err)


def test_a_live_plot_without_a_display_says_to_save_on_linux(monkeypatch, capsys):
    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert main(["plot", "--log", "x.log"]) == 2
    assert "give --save FILE.png" in capsys.readouterr().err


def test_a_live_plot_needs_no_display_variable_on_macos(monkeypatch):
    monkeypatch.setattr(sys, "platform", "darwin")
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    _check_plot_target(argparse.Namespace(save=None))  # no UsageError
