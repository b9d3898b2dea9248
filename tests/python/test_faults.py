"""Faults by name: the table's one 1-bit fault_<name> signal per fault code, in the heartbeat and
the fault_report, read back by active_faults one by one and all at once."""
import pytest

import imdrive
from imdrive import frames, status, table

FAULTS = [name for code, name in sorted(status.fault_names().items()) if code != 0]


@pytest.mark.parametrize("message", ["heartbeat", "fault_report"])
def test_every_fault_has_its_bit_and_reads_back_by_name(message):
    msg = table.message(message)
    for name in FAULTS:
        signal = table.find_signal(msg, "fault_" + name)
        assert signal is not None and table.is_flag(signal), f"{message}: no fault_{name} bit"
    decoder = frames.FrameDecoder(1)
    for name in FAULTS:
        frame = decoder.decode(frames.encode_message(message, 1, **{"fault_" + name: True}))
        assert imdrive.active_faults(frame) == [name]
    every = decoder.decode(frames.encode_message(message, 1, **{"fault_" + n: True
                                                                for n in FAULTS}))
    assert imdrive.active_faults(every) == FAULTS
    assert imdrive.active_faults(decoder.decode(frames.encode_message(message, 1))) == []
