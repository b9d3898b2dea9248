"""imdrive: a Python client for the induction-motor drive's CAN protocol, on python-can.

    import can, imdrive
    with can.Bus(interface="socketcan", channel="can0") as bus, imdrive.Drive(bus, 1) as drive:
        drive.enable()
        drive.set_speed(30.0)
        sample = drive.wait_for_sample(lambda s: abs(s.speed_rad_s - 30.0) < 1.0, timeout_s=5)

The protocol comes from protocol_table.py, generated from firmware/protocol/messages.hpp by
dbc_gen --python, the same table the firmware and docs/can/drive.dbc come from.
"""
from ._version import __version__
from .commands import CommandEncoder
from .drive import Drive
from .errors import (CommandRejected, DriveError, IdentifyFailed, NoAnswer, ParameterRefused,
                     ProtocolMismatch)
from .frames import FrameDecoder
from .logbus import LogFormatError, LogReplayBus, read_log
from .monitor import Monitor
from .socketcand_bus import SocketcandBus, SocketcandError
from .status import active_faults
from .telemetry import TelemetrySample

__all__ = ["__version__", "CommandEncoder", "CommandRejected", "Drive", "DriveError",
           "FrameDecoder", "IdentifyFailed", "LogFormatError", "LogReplayBus", "Monitor",
           "NoAnswer", "ParameterRefused", "ProtocolMismatch", "SocketcandBus", "SocketcandError",
           "TelemetrySample", "active_faults", "read_log"]
