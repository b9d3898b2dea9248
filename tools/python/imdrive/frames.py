"""Decoded frames as typed dataclasses, one class per message of the protocol table.

Each class is named after its message in CamelCase (heartbeat -> Heartbeat, command_ack ->
CommandAck) and has the fields `time_s` (the frame's timestamp, s) and `node_id`, then one field
per signal under the signal's name, which carries its unit (speed_rad_s, time_ms, v_bus_V). A
name that is a Python keyword gets a trailing underscore (state_change's `from` is `from_`).
Enumerated signals read as their value name (str; an int if the raw value has no name), one-bit
signals without names as bool, unit-scale integers as int, the rest as float in the signal's
unit. The classes are built from the table when this module loads: a new message or signal in
firmware/protocol/messages.hpp needs no change here, only a regenerated protocol_table.py.
"""
import collections
import dataclasses
import keyword

import can

from . import table

FIXED_FIELDS = ("time_s", "node_id")


def field_name(signal_name):
    """The dataclass field of a signal: its name, with '_' appended to a Python keyword."""
    return signal_name + "_" if keyword.iskeyword(signal_name) else signal_name


def class_name(message_name):
    return "".join(part.capitalize() for part in message_name.split("_"))


def signal_value(data, signal):
    """A signal's value as its frame class holds it."""
    raw = table.get_raw(data, signal)
    if signal.values:
        name = table.value_name(signal, raw)
        return name if name is not None else raw
    if table.is_flag(signal):
        return bool(raw)
    if table.is_integer(signal):
        return raw
    return table.get_physical(data, signal)


def _field_type(signal):
    if signal.values:
        return str
    if table.is_flag(signal):
        return bool
    if table.is_integer(signal):
        return int
    return float


def _make_class(msg):
    fields = [("time_s", float), ("node_id", int)]
    for s in msg.signals:
        name = field_name(s.name)
        if name in FIXED_FIELDS:
            raise ValueError(f"protocol table: message {msg.name} has a signal named {s.name}, "
                             f"which its frame class uses for itself")
        fields.append((name, _field_type(s)))
    doc = f"{msg.name} (id 0x{msg.id:02X}, {msg.direction}): {msg.comment}"
    return dataclasses.make_dataclass(class_name(msg.name), fields, frozen=True,
                                      namespace={"__doc__": doc, "MESSAGE": msg,
                                                 "__module__": __name__})



FRAME_CLASSES = {m.name: _make_class(m) for m in table.MESSAGES}
globals().update({cls.__name__: cls for cls in FRAME_CLASSES.values()})


def frame_class(message_name):
    """The frame class of a message (KeyError names the known messages)."""
    table.message(message_name)  # a clear KeyError for an unknown name
    return FRAME_CLASSES[message_name]


def decode_payload(msg, data, time_s=0.0, node_id=0):
    """A frame object from a message's payload bytes."""
    values = {field_name(s.name): signal_value(data, s) for s in msg.signals}
    return FRAME_CLASSES[msg.name](time_s=time_s, node_id=node_id, **values)


# Why a frame was not decoded (FrameDecoder.skipped's keys).
SKIP_REASONS = ("error_frame", "remote_frame", "fd_frame", "extended_id", "other_node",
                "unknown_message", "wrong_length")


class FrameDecoder:
    """Decodes one node's frames (python-can Messages); counts the others by reason, and those
    of other nodes by node. `decoded` includes the commands other hosts sent to the node
    (`commands`): the frames from the drive itself are decoded - commands."""

    def __init__(self, node_id):
        if not 0 <= node_id <= table.MAX_NODE_ID:
            raise ValueError(f"node id {node_id}: must be in 0..{table.MAX_NODE_ID}")
        self.node_id = node_id
        self.decoded = 0
        self.commands = 0
        self.skipped = collections.Counter()
        self.other_nodes = collections.Counter()  # node id -> its frames

    def skip_reason(self, message):
        """Why a frame is not one of this node's protocol frames, or None."""
        if message.is_error_frame:
            return "error_frame"
        if message.is_remote_frame:
            return "remote_frame"
        if getattr(message, "is_fd", False):
            return "fd_frame"
        if message.is_extended_id or message.arbitration_id > 0x7FF:
            return "extended_id"
        if table.node_of(message.arbitration_id) != self.node_id:
            return "other_node"
        msg = table.message_by_id(table.message_id_of(message.arbitration_id))
        if msg is None:
            return "unknown_message"
        if message.dlc != msg.length:
            return "wrong_length"
        return None

    def decode(self, message):
        """The frame object of a python-can Message, or None (counted in `skipped`)."""
        reason = self.skip_reason(message)
        if reason is not None:
            self.skipped[reason] += 1
            if reason == "other_node":
                self.other_nodes[table.node_of(message.arbitration_id)] += 1
            return None
        msg = table.message_by_id(table.message_id_of(message.arbitration_id))
        self.decoded += 1
        self.commands += table.is_command(msg)
        return decode_payload(msg, message.data, float(message.timestamp), self.node_id)


def encode_message(message_name, node_id, **values):
    """A python-can Message of any message with `values` by signal name (missing ones are 0;
    enumerated ones by name or raw value, flags as bool). No E2E header: commands go through
    commands.CommandEncoder; this is for simulated drives and tests."""
    msg = table.message(message_name)
    signals = {s.name: s for s in msg.signals}
    unknown = sorted(set(values) - set(signals))
    if unknown:
        raise ValueError(f"{message_name}: no signal {', '.join(unknown)}")
    data = bytearray(8)
    for name, value in values.items():
        s = signals[name]
        if s.values and isinstance(value, str):
            table.set_raw(data, s, table.value_raw(s, value))
        elif s.values or table.is_flag(s) or table.is_integer(s):
            table.set_raw(data, s, int(value))
        else:
            table.set_physical(data, s, value)
    return can.Message(arbitration_id=table.can_id(node_id, msg), is_extended_id=False,
                       data=bytes(data[:msg.length]), dlc=msg.length)
