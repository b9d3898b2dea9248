"""drive_sim's CAN logs through the client: decoding, sample assembly, the log replay bus and
its skipped-frame counts, the command line and the headless plot."""
import struct
import subprocess
import sys

import pytest

import imdrive
from imdrive import table
from imdrive.cli import main

pytestmark = pytest.mark.sim

# seed000_realistic.toml: 8 s simulated, fast telemetry at the default 100 Hz, heartbeat at
# 10 Hz; the simulator logs every frame the drive sent, none lost.
SAMPLES = 800
HEARTBEATS = 80


def replay(path, node_id=1):
    bus = imdrive.LogReplayBus(path, node_id=node_id)
    monitor = imdrive.Monitor(node_id)
    samples = [s for m in iter(lambda: bus.recv(0), None) for s in [monitor.feed(m)[1]] if s]
    return bus, monitor, samples


def test_realistic_log_decodes_to_every_sample(realistic_log):
    bus, monitor, samples = replay(realistic_log)
    assert len(samples) == SAMPLES and monitor.counts["heartbeat"] == HEARTBEATS
    assert monitor.assembler.stale == 0 and monitor.assembler.incomplete == 0
    assert sum(bus.skipped.values()) == 0
    assert [s.state for s in samples][-1] == "running"
    # The scenario's reference peaks at 100 rad/s; the telemetry carries it in 0.01 rad/s.
    assert max(s.speed_ref_rad_s for s in samples) == pytest.approx(100.0, abs=0.01)


def test_samples_match_drive_monitor(realistic_log, tmp_path, pytestconfig):
    """The same log decoded by the C++ monitor (drive_monitor watch --csv) gives the same values
    up to the CSV's decimals (drive_monitor prints the signal's own resolution)."""
    monitor_bin = __import__("pathlib").Path(pytestconfig.getoption("drive_sim")).with_name(
        "drive_monitor")
    csv_path = tmp_path / "monitor.csv"
    subprocess.run([monitor_bin, "watch", "--log", realistic_log, "--csv", csv_path,
                    "--no-table"], check=True)
    rows = csv_path.read_text().splitlines()
    header = rows[0].split(",")
    _, _, samples = replay(realistic_log)
    assert len(rows) - 1 == len(samples)
    for line, sample in zip(rows[1:], samples):
        cpp = dict(zip(header, line.split(",")))
        for field in ("speed_rad_s", "flux2_Wb2", "iA_A", "v_bus_V", "u_beta_V"):
            # Half the last printed decimal: the C++ text is the value rounded to it.
            decimals = len(cpp[field].partition(".")[2])
            assert getattr(sample, field) == pytest.approx(float(cpp[field]),
                                                           abs=0.5 * 10 ** -decimals + 1e-12)
        assert sample.state == cpp["state"]


def test_frames_that_are_not_the_drives_are_skipped_and_counted(realistic_log, tmp_path):
    lines = realistic_log.read_text().splitlines()[:300]
    foreign = ["(0.000001) can0 20000080#0000000000000000",  # error frame
               "(0.000002) can0 18FF0001#0102",                 # 29-bit identifier
               "(0.000003) can0 022##1" + "00" * 12,            # CAN FD
               "(0.000004) can0 022#R",                         # remote frame
               f"(0.000005) can0 {table.can_id(2, table.message('heartbeat')):03X}#"
               + "00" * 8,                                      # node 2
               "(0.000006) can0 03F#00",                        # node 1, no such message
               "(0.000007) can0 022#0000"]                      # heartbeat of 2 bytes
    log = tmp_path / "mixed.log"
    log.write_text("\n".join(foreign + lines + [""]))
    bus, monitor, _ = replay(log)
    assert dict(bus.skipped) == {"error_frame": 1, "extended_id": 1, "fd_frame": 1,
                                 "remote_frame": 1, "other_node": 1, "unknown_message": 1,
                                 "wrong_length": 1}
    assert monitor.decoder.decoded == len(lines)


def test_bad_log_line_names_file_and_line(tmp_path):
    log = tmp_path / "bad.log"
    log.write_text("(0.000000) can0 022#0000000000000000\n(0.1) can0 022#00\n")
    with pytest.raises(imdrive.LogFormatError, match=r"bad.log:2: expected '\(SECONDS.MICROS"):
        replay(log)


def test_cli_watch_writes_csv(realistic_log, tmp_path, capsys):
    csv_path = tmp_path / "watch.csv"
    assert main(["watch", "--log", str(realistic_log), "--csv", str(csv_path)]) == 0
    assert len(csv_path.read_text().splitlines()) == SAMPLES + 1
    err = capsys.readouterr().err
    assert (f"), {SAMPLES} samples; skipped: 0 error frames, 0 with 29-bit ids, 0 CAN FD, "
            f"0 remote, 0 of other nodes, 0 of unknown messages, 0 of wrong length\n") in err, err


def test_plot_saves_a_png_of_the_log(realistic_log, tmp_path):
    from imdrive import plot
    _, _, samples = replay(realistic_log)
    png = tmp_path / "plot.png"
    drawn = plot.save_png(samples, png)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = struct.unpack(">II", png.read_bytes()[16:24])
    assert (width, height) == (9 * 90, 8 * 90)  # figsize in inches times dpi
    assert len(drawn.figure.axes) == 4
    assert [f for _, f in drawn.lines] == ["speed_rad_s", "speed_ref_rad_s", "flux2_Wb2",
                                           "flux2_ref_Wb2", "iA_A", "iB_A"]
    for line, field in drawn.lines:
        assert len(line.get_xdata()) == SAMPLES
        assert list(line.get_ydata()) == [getattr(s, field) for s in samples]
    states = set(drawn.state_line.get_ydata())
    assert plot.state_names()[max(states)] == "running"


def test_cli_plot_headless(realistic_log, tmp_path):
    png = tmp_path / "cli.png"
    result = subprocess.run([sys.executable, "-m", "imdrive", "plot", "--log", str(realistic_log),
                             "--save", str(png)], capture_output=True, text=True,
                            cwd=imdrive.__path__[0] + "/..")
    assert result.returncode == 0, result.stderr
    assert f"{SAMPLES} samples" in result.stdout and png.read_bytes()[:4] == b"\x89PNG"


def test_shared_bus_capture_counts_as_the_cpp_monitor_does(source_dir):
    """The checked-in capture of a shared bus (tests/data/can/shared_bus.log: candump -L -x with
    -d). Its composition, which tests/tools/test_drive_monitor_capture.cpp counts the same way:
    3 error frames, 3 with 29-bit ids, 2 CAN FD, 2 remote (one R8 with its raw DLC), 6 of node 2,
    1 of an unknown message, and a DROPCOUNT line saying 2 frames were lost."""
    bus, monitor, _ = replay(source_dir / "tests/data/can/shared_bus.log")
    assert dict(bus.skipped) == {"error_frame": 3, "extended_id": 3, "fd_frame": 2,
                                 "remote_frame": 2, "other_node": 6, "unknown_message": 1}
    assert bus.dropped == 2
    assert bus.frames == 47


def test_remote_frame_with_raw_dlc_and_bad_dropcount(tmp_path):
    from imdrive.logbus import parse_line
    message = parse_line("(0.000001) can0 022#R8_C R")
    assert message.is_remote_frame and message.dlc == 8 and message.is_rx
    with pytest.raises(ValueError, match="raw DLC"):
        parse_line("(0.000001) can0 022#R8_3")
    log = tmp_path / "drop.log"
    log.write_text("DROPCOUNT: dropped 2 CAN frames on can0 socket (total drops 2)\n")
    with pytest.raises(imdrive.LogFormatError, match=r"drop.log:1: bad DROPCOUNT line"):
        replay(log)
