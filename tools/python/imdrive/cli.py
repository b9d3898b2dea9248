"""python3 -m imdrive: watch, command, configure and plot a drive on CAN.

Exit codes, as drive_monitor's: 0 success, 2 bad input (flags, values, interface, log file),
3 the drive refused (a command rejected, a parameter refused, an identification failed), 4 no
answer in time (watch: no frame at all from the node).
"""
import argparse
import math
import os
import sys
import time

from . import capture_report, table
from ._version import build_version
from .bus_open import BusOpenError
from .bus_open import open_bus as open_named_bus
from .drive import Drive
from .errors import CommandRejected, DriveError, IdentifyFailed, NoAnswer, ParameterRefused
from .logbus import LogFormatError, LogReplayBus
from .monitor import Monitor
from .service import field_names
from .status import active_faults
from .telemetry import TelemetrySample

EXIT_BAD_INPUT, EXIT_REFUSED, EXIT_NO_ANSWER = 2, 3, 4

# Command words -> (message, payload signal or None). The value's meaning is the signal's.
COMMANDS = {
    "enable": ("enable", None), "disable": ("disable", None),
    "estop": ("emergency_stop", None), "clear-faults": ("clear_faults", None),
    "set-speed": ("set_speed", "speed_ref_rad_s"), "set-flux": ("set_flux", "flux2_ref_Wb2"),
    "select-controller": ("select_controller", "controller"),
    "set-telemetry-rate": ("set_telemetry_rate", "rate_Hz"),
}


class UsageError(Exception):
    pass


def _node(text):
    try:
        node = int(text)
    except ValueError:
        node = -1
    if not 0 <= node <= table.MAX_NODE_ID:
        raise argparse.ArgumentTypeError(f"must be a node id in 0..{table.MAX_NODE_ID}, "
                                         f"got {text}")
    return node


def _seconds(text):
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"must be a time in seconds > 0, got {text}")
    return value


def _bus_options(parser, log=False):
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument("--can", metavar="IFACE", help="SocketCAN interface, e.g. can0")
    group.add_argument("--socketcand", metavar="HOST:PORT",
                       help="a socketcand server, e.g. drive_hil --can socketcand:29536 on a "
                       "machine without SocketCAN")
    group.add_argument("--interface", metavar="NAME",
                       help="another python-can interface (with --channel), e.g. virtual")
    if log:
        group.add_argument("--log", metavar="FILE", help="a candump -L log instead of a bus")
    parser.add_argument("--channel", help="the channel of --interface")
    parser.add_argument("--node", type=_node, default=1, help="node id of the drive (default 1)")


def parser():
    p = argparse.ArgumentParser(prog="imdrive", description="Watch and command the "
                                "induction-motor drive over CAN (python-can).")
    p.add_argument("--version", action="version", version=build_version())
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    w = sub.add_parser("watch", help="print telemetry samples (or write them as CSV)")
    _bus_options(w, log=True)
    w.add_argument("--csv", metavar="PATH", help="write the samples as CSV ('-': stdout)")
    w.add_argument("--duration-s", type=_seconds, help="stop after this long (live bus)")
    s = sub.add_parser("send", help="send one command and print its acknowledgement")
    _bus_options(s)
    s.add_argument("word", choices=sorted(COMMANDS), metavar="WORD",
                   help="one of: " + ", ".join(COMMANDS))
    s.add_argument("value", nargs="?", help="the command's value (set-speed RAD_S, ...)")
    s.add_argument("--hold-s", type=_seconds,
                   help="then keep the drive's watchdog fed this long (set-speed, enable)")
    pa = sub.add_parser("param", help="read or write the motor record")
    psub = pa.add_subparsers(dest="op", required=True, metavar="OP")
    r = psub.add_parser("read", help="read fields (default: all)")
    _bus_options(r)
    r.add_argument("fields", nargs="*", metavar="FIELD")
    wr = psub.add_parser("write", help="write FIELD=VALUE pairs (the drive must be idle)")
    _bus_options(wr)
    wr.add_argument("assignments", nargs="+", metavar="FIELD=VALUE")
    wr.add_argument("--save", action="store_true", help="then store the record")
    i = sub.add_parser("identify", help="commission the motor from its nameplate")
    _bus_options(i)
    i.add_argument("--rotate", action="store_true", help="also turn the motor (J, friction)")
    i.add_argument("--timeout-s", type=_seconds, default=120.0)
    pl = sub.add_parser("plot", help="plot speed, flux, currents and state")
    _bus_options(pl, log=True)
    pl.add_argument("--save", metavar="PNG", help="draw to this PNG file instead of a window")
    pl.add_argument("--duration-s", type=_seconds, help="collect this long, then save (live)")
    return p


def open_bus(args):
    """The bus the flags name; UsageError says why it cannot be opened. A log is read whole:
    the Monitor decodes the node's frames and counts the others, by reason and by node."""
    if getattr(args, "log", None):
        return LogReplayBus(args.log)
    try:
        return open_named_bus(args.can, args.interface, args.channel, args.socketcand)
    except BusOpenError as error:
        raise UsageError(str(error)) from None


def command_values(word, text):
    """The values of a command word; UsageError names what is wrong."""
    message, signal_name = COMMANDS[word]
    if signal_name is None:
        if text is not None:
            raise UsageError(f"{word} takes no value, got '{text}'")
        return message, {}
    if text is None:
        raise UsageError(f"{word} needs a value ({signal_name})")
    signal = table.find_signal(table.message(message), signal_name)
    if signal.values:
        return message, {signal_name: text}
    try:
        value = float(text)
    except ValueError:
        raise UsageError(f"{word}: '{text}' is not a number") from None
    return message, {signal_name: value}


def run_watch(args, out):
    bus = open_bus(args)
    monitor = Monitor(args.node)
    csv = None
    fields = list(TelemetrySample.__dataclass_fields__)
    if args.csv:
        csv = sys.stdout if args.csv == "-" else _open_output(args.csv, "--csv")
        csv.write(",".join(fields) + "\n")
    end = time.monotonic() + args.duration_s if args.duration_s else math.inf
    samples = 0
    try:
        while time.monotonic() < end:
            message = bus.recv(timeout=0.1)
            if message is None:
                if getattr(bus, "ended", False):
                    break
                continue
            frame, sample = monitor.feed(message)
            if sample is None:
                continue
            samples += 1
            if csv:
                csv.write(",".join(str(getattr(sample, f)) for f in fields) + "\n")
            elif not args.log:
                out.write(f"{sample}\n")
    except KeyboardInterrupt:
        pass
    finally:
        if csv and csv is not sys.stdout:
            csv.close()
        bus.shutdown()
    return finish_watch(monitor, samples, bus, args)


def finish_watch(monitor, samples, bus, args):
    """The summary on standard error, as drive_monitor's; 4 when the node was not heard."""
    print(f"imdrive: {capture_report.summary_line(monitor, samples, bus)}", file=sys.stderr)
    hb = monitor.heartbeat()
    if hb is not None:
        print(f"imdrive: node {args.node}: state {hb.state}, first fault {hb.first_fault}, "
              f"latched: {', '.join(active_faults(hb)) or 'none'}", file=sys.stderr)
    if monitor.protocol_error is not None:
        print(f"imdrive: warning: {monitor.protocol_error}", file=sys.stderr)
    source = args.log or args.can or (args.socketcand and f"socketcand {args.socketcand}") \
        or f"{args.interface} {args.channel}"
    warning = capture_report.silent_node_warning(monitor, source)
    if warning is not None:
        print(f"imdrive: {warning}", file=sys.stderr)
        return EXIT_NO_ANSWER
    return 0


def run_send(drive, args, out):
    message, values = command_values(args.word, args.value)
    ack = drive.send(message, **values)
    out.write(f"{message} {' '.join(f'{k}={v}' for k, v in values.items())}: {ack.result} "
              f"(counter {ack.counter})\n")
    if args.hold_s:
        if message == "set_speed":
            drive.keep_alive.speed_rad_s = values["speed_ref_rad_s"]
        drive.keep_alive.start()
        time.sleep(args.hold_s)
        drive.keep_alive.stop()
        out.write(f"keep-alive: {drive.keep_alive.sent} frames, "
                  f"{dict(drive.keep_alive.results)}\n")
    return 0


def run_param(drive, args, out):
    known = field_names()
    if args.op == "read":
        for name in args.fields:
            if name not in known:
                raise UsageError(f"'{name}' is not a motor parameter (known: {', '.join(known)})")
        values = drive.read_parameters() if not args.fields else \
            {name: drive.read_parameter(name) for name in args.fields}
        for name, value in values.items():
            out.write(f"{name} = {'(none)' if math.isnan(value) else f'{value:.9g}'}\n")
        return 0
    pairs = []
    for text in args.assignments:
        name, eq, number = text.partition("=")
        if not eq:
            raise UsageError(f"'{text}': expected FIELD=VALUE, e.g. Rr_Ohm=10.1")
        if name not in known:
            raise UsageError(f"'{name}' is not a motor parameter (known: {', '.join(known)})")
        try:
            value = float(number)
        except ValueError:
            raise UsageError(f"{name}: '{number}' is not a number") from None
        if not math.isfinite(value):
            raise UsageError(f"{name}: '{number}' is not a finite number")
        pairs.append((name, value))
    for name, value in pairs:
        out.write(f"write {name} = {drive.write_parameter(name, value):.9g}: ok\n")
    if args.save:
        drive.save_parameters()
        out.write("saved\n")
    return 0


def run_identify(drive, args, out):
    def show(frame):
        out.write(f"{frame.step} {100 * frame.fraction:.0f} % ({frame.seconds:.1f} s)\n")
    last = drive.identify(rotate=args.rotate, timeout_s=args.timeout_s, progress=show)
    out.write(f"identify: {last.step} ({last.seconds:.1f} s)\n")
    return 0


def _open_output(path, flag):
    """A file to write, or a UsageError naming the flag and why it cannot be written."""
    try:
        return open(path, "w")
    except OSError as error:
        raise UsageError(f"{flag} {path}: cannot write the file ({error.strerror})") from None


def _check_plot_target(args):
    """Before any frame is read: a --save name matplotlib writes as PNG in a directory that
    exists, or a display for the live window. Only on Linux does a window need DISPLAY or
    WAYLAND_DISPLAY: macOS and Windows draw without either."""
    if args.save:
        if not args.save.lower().endswith(".png"):
            raise UsageError(f"--save {args.save}: the file name must end in .png")
        folder = os.path.dirname(os.path.abspath(args.save))
        if not os.path.isdir(folder):
            raise UsageError(f"--save {args.save}: no directory {folder}")
    elif sys.platform.startswith("linux") and not (os.environ.get("DISPLAY")
                                                   or os.environ.get("WAYLAND_DISPLAY")):
        raise UsageError("no display for a live window (DISPLAY is not set): "
                         "give --save FILE.png")


def run_plot(args, out):
    from . import plot
    _check_plot_target(args)
    bus = open_bus(args)
    if args.log:
        monitor = Monitor(args.node)
        samples = []
        for message in iter(lambda: bus.recv(timeout=0), None):
            _, sample = monitor.feed(message)
            if sample is not None:
                samples.append(sample)
        if not samples:
            raise UsageError(f"{args.log}: no telemetry samples of node {args.node}")
        if args.save:
            plot.save_png(samples, args.save, title=f"{args.log}, node {args.node}")
            out.write(f"{args.save}: {len(samples)} samples\n")
            return 0
        iterator = iter([samples])
        plot.animate(lambda: next(iterator, []), window=None)
        return 0
    with Drive(bus, args.node) as drive:
        if args.save:
            duration_s = args.duration_s or 10.0
            time.sleep(duration_s)
            samples = list(drive.samples(timeout_s=0))
            plot.save_png(samples, args.save, title=f"node {args.node}")
            out.write(f"{args.save}: {len(samples)} samples in {duration_s:g} s\n")
            return 0
        plot.animate(lambda: list(drive.samples(timeout_s=0)))
    bus.shutdown()
    return 0


def main(argv=None, out=None):
    out = out or sys.stdout
    args = parser().parse_args(argv)
    try:
        if args.command == "watch":
            return run_watch(args, out)
        if args.command == "plot":
            return run_plot(args, out)
        bus = open_bus(args)
        try:
            with Drive(bus, args.node) as drive:
                run = {"send": run_send, "param": run_param, "identify": run_identify}
                return run[args.command](drive, args, out)
        finally:
            bus.shutdown()
    except (UsageError, LogFormatError, ValueError, KeyError) as error:
        text = error.args[0] if isinstance(error, KeyError) else error
        print(f"imdrive: {text}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except (CommandRejected, ParameterRefused, IdentifyFailed) as error:
        print(f"imdrive: {error}", file=sys.stderr)
        return EXIT_REFUSED
    except NoAnswer as error:
        print(f"imdrive: {error}", file=sys.stderr)
        return EXIT_NO_ANSWER
    except DriveError as error:
        print(f"imdrive: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
