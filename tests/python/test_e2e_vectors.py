"""The client's command frames against the firmware's CommandEncoder, bit for bit: every row of
e2e_vectors (all commands, every counter, nodes 0, 1, 7 and 63, rounding halves, saturation,
NaN) is rebuilt here and must match exactly: no tolerance, these are bytes."""
import collections
import csv
import io
import math
import subprocess

from imdrive import commands, e2e, table

# The rows e2e_vectors.cpp writes, counted from how it builds them:
NODES = 4                  # 0, 1, 7, 63
PLAIN = NODES * 16 * 4     # every counter x emergency_stop, disable, enable, clear_faults
VALUED_COUNTERS = 4        # counters 0, 5, 10, 15
# Per node and counter: 17 speeds, 8 fluxes, 7 rates, 3 controllers, 2 identify values,
# 3 ops x 4 fields (0, 3, 6, 9) of parameter_access, and one with a NaN value.
VALUED_ROWS = {"set_speed": 17, "set_flux": 8, "set_telemetry_rate": 7, "select_controller": 3,
               "identify": 2, "parameter_access": 3 * 4 + 1}
# Of those the table refuses: speeds +-1e6, NaN, +-inf (beyond +-2000 rad/s or not finite);
# fluxes 5000, NaN, -1 (outside 0..4 Wb^2); rates 70000, NaN (outside 10..1000 Hz); the NaN
# parameter value (not a finite single).
REFUSED_ROWS = {"set_speed": 5, "set_flux": 3, "set_telemetry_rate": 2, "parameter_access": 1}
ROWS = PLAIN + NODES * VALUED_COUNTERS * sum(VALUED_ROWS.values())        # 256 + 800 = 1056
REFUSED = NODES * VALUED_COUNTERS * sum(REFUSED_ROWS.values())             # 176


def vectors(program):
    text = subprocess.run([program], check=True, capture_output=True, text=True).stdout
    return list(csv.DictReader(io.StringIO(text)))


def low_level_frame(row):
    """The payload built as commands.cpp's encode does: op and field raw, the value physical."""
    msg = table.message(row["message"])
    data = bytearray(8)
    value = float(row["value"])
    signals = commands.payload_signals(msg)
    if msg.name == "parameter_access":
        op, field, val = (table.find_signal(msg, n) for n in ("op", "field", "value"))
        table.set_raw(data, op, int(row["op"]))
        table.set_raw(data, field, int(row["field"]))
        table.set_physical(data, val, value)
    elif signals:
        table.set_physical(data, signals[0], value)
    can_id = table.can_id(int(row["node"]), msg)
    e2e.e2e_protect(can_id, data, msg.length, int(row["counter"]))
    return can_id, bytes(data[:msg.length])


def test_every_cpp_frame_is_rebuilt_exactly(e2e_vectors):
    rows = vectors(e2e_vectors)
    assert len(rows) == ROWS
    mismatches = []
    for row in rows:
        can_id, data = low_level_frame(row)
        if can_id != int(row["can_id"], 16) or data.hex().upper() != row["data"]:
            mismatches.append((row, f"{can_id:03X}#{data.hex().upper()}"))
    assert not mismatches, f"{len(mismatches)} of {len(rows)} differ, first: {mismatches[0]}"


def outside(signal, value):
    """Whether the table refuses a value: not finite, or beyond the signal's range."""
    if signal.values:
        return False
    if not math.isfinite(value):
        return True
    return signal.minimum is not None and not signal.minimum <= value <= signal.maximum


def test_the_typed_encoder_matches_for_values_the_drive_accepts(e2e_vectors):
    """CommandEncoder (values checked, counter kept) gives the same frames wherever the value
    is one the table admits; the others it refuses before sending."""
    compared = 0
    refused = collections.Counter()
    for row in vectors(e2e_vectors):
        msg = table.message(row["message"])
        value = float(row["value"])
        values = {}
        for s in commands.payload_signals(msg):
            if s.name == "op":
                values["op"] = int(row["op"])
            elif s.name == "field":
                values["field"] = int(row["field"])
            elif s.values:
                values[s.name] = int(value)
            else:
                values[s.name] = value
        encoder = commands.CommandEncoder(int(row["node"]), int(row["counter"]))
        try:
            frame = encoder.encode(msg.name, **values)
        except ValueError:
            refused[msg.name] += 1
            assert any(outside(s, values[s.name]) for s in commands.payload_signals(msg)), row
            continue
        compared += 1
        assert f"{frame.arbitration_id:03X}" == row["can_id"]
        assert frame.data.hex().upper() == row["data"], row
        assert encoder.next_counter == (int(row["counter"]) + 1) % 16
    assert refused == {name: NODES * VALUED_COUNTERS * n for name, n in REFUSED_ROWS.items()}
    assert compared == ROWS - REFUSED


def test_crc_covers_the_identifier():
    """The same payload for another node fails the CRC: the data id is in it."""
    data = bytearray(8)
    e2e.e2e_protect(table.can_id(1, table.message("enable")), data, 2, 3)
    assert e2e.e2e_check(table.can_id(1, table.message("enable")), data, 2)
    assert not e2e.e2e_check(table.can_id(2, table.message("enable")), data, 2)
