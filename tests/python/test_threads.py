"""The alive counter shared by several threads: commands from many threads at once, starting
from a counter not yet learnt, must leave in counter order and learn the counter once."""
import threading

import imdrive

THREADS = 6
COMMANDS_EACH = 5


def test_concurrent_commands_keep_the_counter_in_step(fake_and_bus):
    fake, bus = fake_and_bus
    errors = []
    with imdrive.Drive(bus, 1) as drive:
        start = threading.Barrier(THREADS)

        def commands():
            start.wait()
            try:
                for _ in range(COMMANDS_EACH):
                    drive.clear_faults()
            except imdrive.DriveError as error:
                errors.append(error)
        threads = [threading.Thread(target=commands) for _ in range(THREADS)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(timeout=10.0)
    assert not errors
    # Every frame was the next counter: no rejection, no retry.
    assert [r for _, r in fake.received] == ["accepted"] * (THREADS * COMMANDS_EACH)
