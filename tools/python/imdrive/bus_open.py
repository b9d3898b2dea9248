"""How the command line opens a bus: SocketCAN (--can), a socketcand server such as drive_hil
--can socketcand:PORT (--socketcand), or any python-can interface (--interface, --channel).
BusOpenError says what failed and what to do instead."""
import errno

import can

from .socketcand_bus import SocketcandBus, SocketcandError

DEFAULT_HOST = "127.0.0.1"


class BusOpenError(Exception):
    pass


def parse_host_port(text):
    """'PORT' (host 127.0.0.1), 'HOST:PORT' or '[V6]:PORT' -> (host, port), by the same rules
    as drive_monitor's parse_socketcand_address (hal/linux/socketcand_client.cpp)."""
    host, colon, port = text.rpartition(":")
    if not colon:
        host = DEFAULT_HOST
    elif host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
    # ASCII digits only, at most 5 of them, as the C++ parser takes them.
    if not host or not (port.isascii() and port.isdigit() and len(port) <= 5) \
            or not 0 < int(port) <= 65535:
        raise BusOpenError(f"--socketcand {text}: expected PORT, HOST:PORT or [V6]:PORT with a "
                           f"port in 1..65535, e.g. 127.0.0.1:29536")
    return host, int(port)


def socketcan_error_text(channel, error):
    """The message for a SocketCAN interface that cannot be opened."""
    number = getattr(error, "errno", None)
    if number in (errno.EAFNOSUPPORT, errno.EPROTONOSUPPORT):
        return (f"cannot open socketcan {channel}: this kernel has no CAN support "
                f"({error.strerror}). Without SocketCAN, run drive_hil --can socketcand:29536 "
                f"and use --socketcand 127.0.0.1:29536; or load the virtual CAN module: "
                f"sudo modprobe vcan; sudo ip link add dev vcan0 type vcan; "
                f"sudo ip link set vcan0 up")
    if number == errno.ENODEV:
        return (f"cannot open socketcan {channel}: no such CAN interface (ip link show; for a "
                f"virtual one: sudo ip link add dev {channel} type vcan)")
    return f"cannot open socketcan {channel}: {error}"


def open_bus(can_iface=None, interface=None, channel=None, socketcand=None):
    """The bus one of the options names; BusOpenError says why it cannot be opened."""
    if socketcand:
        host, port = parse_host_port(socketcand)
        try:
            return SocketcandBus(host, port)
        except SocketcandError as error:
            raise BusOpenError(str(error)) from None
    if interface and not channel:
        raise BusOpenError(f"--interface {interface} needs --channel")
    interface, channel = ("socketcan", can_iface) if can_iface else (interface, channel)
    try:
        return can.Bus(interface=interface, channel=channel)
    except (can.CanError, OSError, ValueError, ImportError) as error:
        if interface == "socketcan":
            raise BusOpenError(socketcan_error_text(channel, error)) from None
        raise BusOpenError(f"cannot open {interface} {channel}: {error}") from None
