"""The protocol table (protocol_table.py, generated from firmware/protocol/messages.hpp) with
lookups by id and name, and the bit-level codec of one signal.

Signals are Intel (little-endian) bit order in classic CAN frames, as in the DBC file:
physical = raw * scale_num / scale_den + offset, or an IEEE single for float signals.
"""
import math
import struct

from . import protocol_table as _t

Signal = _t.Signal
Message = _t.Message
MESSAGES = _t.MESSAGES
NODE_STRIDE = _t.NODE_STRIDE
MAX_NODE_ID = _t.MAX_NODE_ID
PROTOCOL_VERSION = _t.PROTOCOL_VERSION
MAX_COUNTER_STEP = _t.MAX_COUNTER_STEP
FAST_TELEMETRY_MIN_HZ = _t.FAST_TELEMETRY_MIN_HZ
FAST_TELEMETRY_MAX_HZ = _t.FAST_TELEMETRY_MAX_HZ

_BY_ID = {m.id: m for m in MESSAGES}
_BY_NAME = {m.name: m for m in MESSAGES}


def message_by_id(message_id):
    """The message with this 5-bit id, or None."""
    return _BY_ID.get(message_id)


def message(name):
    """The message of this name; KeyError names the known ones."""
    try:
        return _BY_NAME[name]
    except KeyError:
        raise KeyError(f"no message '{name}' in the protocol table "
                       f"(known: {', '.join(sorted(_BY_NAME))})") from None


def has_message(name):
    return name in _BY_NAME


def find_signal(msg, name):
    """The signal of this name in `msg`, or None."""
    for s in msg.signals:
        if s.name == name:
            return s
    return None


def is_command(msg):
    """Host-to-drive messages carry the E2E header (CRC-8 and alive counter)."""
    return msg.direction == "host_to_drive"


def can_id(node_id, msg):
    return node_id * NODE_STRIDE + msg.id


def node_of(can_id_):
    return can_id_ // NODE_STRIDE


def message_id_of(can_id_):
    return can_id_ % NODE_STRIDE


def value_name(signal, raw):
    """The name of an enumerated raw value, or None."""
    for value, name in signal.values:
        if value == raw:
            return name
    return None


def value_raw(signal, name):
    """The raw value of an enumerated name; ValueError lists the known names."""
    for value, known in signal.values:
        if known == name:
            return value
    raise ValueError(f"{signal.name}: unknown value '{name}' "
                     f"(known: {', '.join(n for _, n in signal.values)})")


def is_flag(signal):
    """A one-bit unsigned signal without value names reads as a bool."""
    return signal.length_bits == 1 and not signal.is_signed and not signal.values


def is_integer(signal):
    """Whole raw values with unit scale read as int."""
    return (not signal.is_float and signal.scale_num == 1 and signal.scale_den == 1
            and signal.offset == 0)


def raw_min(signal):
    return -(1 << (signal.length_bits - 1)) if signal.is_signed else 0


def raw_max(signal):
    n = signal.length_bits
    return (1 << (n - 1)) - 1 if signal.is_signed else (1 << n) - 1


def get_raw(data, signal):
    """The raw bits of a signal from the payload bytes (sign-extended for signed signals)."""
    bits = int.from_bytes(bytes(data[:8]).ljust(8, b"\0"), "little")
    mask = (1 << signal.length_bits) - 1
    raw = (bits >> signal.start_bit) & mask
    if signal.is_signed and raw >> (signal.length_bits - 1):
        raw -= 1 << signal.length_bits
    return raw


def set_raw(data, signal, raw):
    """Writes the raw bits of a signal into the bytearray `data` (8 bytes)."""
    bits = int.from_bytes(bytes(data[:8]).ljust(8, b"\0"), "little")
    mask = (1 << signal.length_bits) - 1
    bits &= ~(mask << signal.start_bit)
    bits |= (raw & mask) << signal.start_bit
    data[:8] = bits.to_bytes(8, "little")


def f32(x):
    """x rounded to IEEE single precision, as the MCU and the C++ encoder compute."""
    try:
        return struct.unpack("<f", struct.pack("<f", x))[0]
    except OverflowError:  # beyond float's range: the C++ conversion gives an infinity
        return math.copysign(math.inf, x)


def _round_half_away(x):
    """std::round: halves away from zero."""
    return math.floor(x + 0.5) if x >= 0 else -math.floor(-x + 0.5)


def to_raw(signal, value):
    """The nearest raw value for a physical value, saturated to the signal's range, computed in
    single precision step by step as can_signal.hpp's to_raw does, so that a frame is the C++
    encoder's bit for bit (each float operation done in double and rounded once to single is
    exact: double has more than 2 * 24 + 2 bits). NaN becomes raw_min."""
    v = f32(value)
    if math.isnan(v):
        return raw_min(signal)
    scaled = f32(f32(f32(v - f32(signal.offset)) * f32(signal.scale_den)) / f32(signal.scale_num))
    if math.isinf(scaled):
        return raw_min(signal) if scaled < 0 else raw_max(signal)
    raw = f32(_round_half_away(scaled))
    if not raw >= f32(raw_min(signal)):
        return raw_min(signal)
    if raw >= f32(raw_max(signal)):
        return raw_max(signal)
    return int(raw)


def in_range(signal, value):
    """Whether a physical value fits the signal's bits without saturation."""
    if signal.is_float:
        return True
    v = f32(value)
    if math.isnan(v):
        return False
    scaled = f32(f32(f32(v - f32(signal.offset)) * f32(signal.scale_den)) / f32(signal.scale_num))
    if math.isinf(scaled):
        return False
    raw = _round_half_away(scaled)
    return raw_min(signal) <= raw <= raw_max(signal)


def get_physical(data, signal):
    """The physical value (float), in double precision as the host tools decode."""
    raw = get_raw(data, signal)
    if signal.is_float:
        return struct.unpack("<f", (raw & 0xFFFFFFFF).to_bytes(4, "little"))[0]
    return raw * signal.scale_num / signal.scale_den + signal.offset


def set_physical(data, signal, value):
    if signal.is_float:
        set_raw(data, signal, int.from_bytes(struct.pack("<f", value), "little"))
    else:
        set_raw(data, signal, to_raw(signal, value))
