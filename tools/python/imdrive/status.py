"""What a heartbeat (or a fault_report) says about faults: the table carries one 1-bit signal
per fault code, `fault_<name>` (fault_overcurrent, fault_encoder, ...), named after
first_fault's value table; code 0 (none) has none."""
from . import frames, table


def fault_names():
    """The fault names of the heartbeat's first_fault value table, by raw value."""
    return dict(table.find_signal(table.message("heartbeat"), "first_fault").values)


def active_faults(frame):
    """The names of the latched faults a heartbeat or fault_report frame reports, in code
    order."""
    return [name for code, name in sorted(fault_names().items())
            if code != 0 and getattr(frame, frames.field_name("fault_" + name), False)]
