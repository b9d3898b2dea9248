"""What a heartbeat says about faults, whichever way the table carries them: a `fault_bits`
bit field (bit n = fault code n of first_fault's value table), or one one-bit signal per fault
named after it (e.g. `overcurrent` or `fault_overcurrent`)."""
from . import frames, table


def fault_names():
    """The fault names of the heartbeat's first_fault value table, by raw value ({} without)."""
    hb = table.message("heartbeat")
    first = table.find_signal(hb, "first_fault")
    return dict(first.values) if first is not None else {}


def active_faults(heartbeat):
    """The names of the latched faults a heartbeat frame reports, in code order."""
    names = fault_names()
    bits = getattr(heartbeat, "fault_bits", None)
    if isinstance(bits, int) and not isinstance(bits, bool):
        return [names.get(code, f"fault {code}") for code in range(bits.bit_length())
                if bits >> code & 1]
    active = []
    for s in heartbeat.MESSAGE.signals:
        if not table.is_flag(s):
            continue
        for code, name in sorted(names.items()):
            if code != 0 and s.name in (name, "fault_" + name, name + "_fault"):
                if getattr(heartbeat, frames.field_name(s.name)):
                    active.append(name)
    return active
