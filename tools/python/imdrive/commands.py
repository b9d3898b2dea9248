"""Command frames: any host-to-drive message of the table, with its values checked locally, the
next alive counter and the CRC (firmware/protocol/commands.hpp's CommandEncoder, in Python).

Values are given by signal name. An enumerated signal takes its value name (or raw number); the
others take the physical value in the signal's unit. A value the signal's bits cannot carry, or
outside the range the table gives for it, is refused here with the signal and its range named,
before anything goes on the bus.
"""
import math
import threading

import can

from . import e2e, table

# Byte 0 (CRC) and the low nibble of byte 1 (counter): filled in by e2e_protect.
E2E_HEADER_BITS = 12


def is_e2e_signal(signal):
    return signal.start_bit + signal.length_bits <= E2E_HEADER_BITS


def payload_signals(msg):
    """The signals a caller gives values for (not the E2E header)."""
    return [s for s in msg.signals if not is_e2e_signal(s)]


def _format(value):
    return f"{value:g}"


def check_value(msg, signal, value):
    """The raw value for `value`, or ValueError naming the message, the signal and the range."""
    where = f"{msg.name}.{signal.name}"
    if signal.values:
        if isinstance(value, str):
            return table.value_raw(signal, value)
        if isinstance(value, bool) or not isinstance(value, int) or \
                table.value_name(signal, value) is None:
            known = ", ".join(f"{n} ({r})" for r, n in signal.values)
            raise ValueError(f"{where}: {value!r} is not one of {known}")
        return value
    if isinstance(value, bool):
        value = int(value)
    if not isinstance(value, (int, float)):
        raise ValueError(f"{where}: {value!r} is not a number")
    if signal.is_float:
        if not math.isfinite(value) or abs(value) > 3.4028234e38:
            raise ValueError(f"{where}: {value!r} is not a finite single-precision number")
        return None
    unit = f" {signal.unit}" if signal.unit else ""
    low = signal.minimum if signal.minimum is not None else -math.inf
    high = signal.maximum if signal.maximum is not None else math.inf
    if not (math.isfinite(value) and table.in_range(signal, value) and low <= value <= high):
        raise ValueError(f"{where}: {value!r}{unit} is outside "
                         f"{_format(low)}..{_format(high)}{unit}")
    return None


def payload(msg, values):
    """The payload bytes (E2E header zero) of a command message with `values` by signal name;
    every payload signal must be given."""
    if not table.is_command(msg):
        raise ValueError(f"{msg.name} is not a command (it goes from the drive to the host)")
    signals = {s.name: s for s in payload_signals(msg)}
    unknown = sorted(set(values) - set(signals))
    if unknown:
        raise ValueError(f"{msg.name}: no signal {', '.join(unknown)} "
                         f"(it has: {', '.join(signals) or 'none'})")
    missing = [name for name in signals if name not in values]
    if missing:
        raise ValueError(f"{msg.name}: give {', '.join(missing)}")
    data = bytearray(8)
    for name, signal in signals.items():
        raw = check_value(msg, signal, values[name])
        if raw is not None:
            table.set_raw(data, signal, raw)
        else:
            table.set_physical(data, signal, values[name])
    return data


class CommandEncoder:
    """Frames for one node, each with the next alive counter (mod 16). Thread-safe: one counter
    covers every command to a node, whoever sends it."""

    def __init__(self, node_id, first_counter=0):
        if not 0 <= node_id <= table.MAX_NODE_ID:
            raise ValueError(f"node id {node_id}: must be in 0..{table.MAX_NODE_ID}")
        self.node_id = node_id
        self._counter = first_counter % e2e.COUNTER_MODULO
        self._lock = threading.Lock()

    @property
    def next_counter(self):
        """The counter the next frame will carry."""
        return self._counter

    @next_counter.setter
    def next_counter(self, counter):
        with self._lock:
            self._counter = counter % e2e.COUNTER_MODULO

    def encode(self, message_name, **values):
        """A python-can Message of command `message_name`; values by signal name."""
        msg = table.message(message_name)
        data = payload(msg, values)
        arbitration_id = table.can_id(self.node_id, msg)
        with self._lock:
            counter = self._counter
            self._counter = (counter + 1) % e2e.COUNTER_MODULO
        e2e.e2e_protect(arbitration_id, data, msg.length, counter)
        return can.Message(arbitration_id=arbitration_id, is_extended_id=False,
                           data=bytes(data[:msg.length]), dlc=msg.length)
