"""The alive counter shared by several threads: commands from many threads at once, starting
from a counter not yet learnt, must leave in counter order and learn the counter once."""
import threading
import time

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


def test_a_sender_starved_past_a_counter_wrap_still_gets_its_own_ack(fake_and_bus):
    """The alive counter has 16 values, so a sender that is not scheduled between its ack's
    arrival and its wake-up can find its (message, counter) key taken by the 16th command after
    it. Here it is held until that command is acked; it must still return its own ack."""
    fake, bus = fake_and_bus
    with imdrive.Drive(bus, 1) as drive:
        drive.learn_counter()
        starved = threading.Event()
        release = threading.Event()
        plain_wait = drive.wait

        def held_wait(predicate, timeout_s, what):
            if threading.current_thread().name == "starved":
                starved.set()
                release.wait(10.0)
            return plain_wait(predicate, timeout_s, what)
        drive.wait = held_wait
        outcome = []

        def starved_sender():
            try:
                outcome.append(drive.clear_faults())
            except Exception as error:  # noqa: BLE001 - any failure is the finding
                outcome.append(error)
        thread = threading.Thread(target=starved_sender, name="starved")
        thread.start()
        assert starved.wait(5.0)
        deadline = time.monotonic() + 5.0
        while not fake.received and time.monotonic() < deadline:
            time.sleep(0.001)  # its ack has come: the case is the one of a sender not woken
        assert fake.received, "the held sender's command was never answered"
        first_counter = fake.arrivals[0][2]
        for _ in range(16):  # the 16th takes the starved command's counter again
            drive.clear_faults()
        release.set()
        thread.join(10.0)
    assert len(outcome) == 1 and not isinstance(outcome[0], Exception), outcome
    assert outcome[0].result == "accepted" and outcome[0].counter == first_counter
    assert [r for _, r in fake.received] == ["accepted"] * 17
