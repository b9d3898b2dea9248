"""What the client raises. Every message says what was asked, of which node, and why it failed."""


class DriveError(Exception):
    """Base of the client's errors."""


class NoAnswer(DriveError, TimeoutError):
    """The drive did not answer in time (no heartbeat, no command_ack, no parameter_value)."""


class CommandRejected(DriveError):
    """The drive answered a command with a command_ack whose result is not `accepted`.

    `result` is the result's name (wrong_length, bad_crc, repeated_counter, stale_counter,
    out_of_range, not_allowed, unknown_message, not_in_image; docs/can/protocol.md)."""

    def __init__(self, text, message_name, counter, result):
        super().__init__(text)
        self.message_name = message_name
        self.counter = counter
        self.result = result


class ParameterRefused(DriveError):
    """A parameter_value answered with a status other than ok; `status` is its name."""

    def __init__(self, text, op, field, status):
        super().__init__(text)
        self.op = op
        self.field = field
        self.status = status


class IdentifyFailed(DriveError):
    """The commissioning ended in step `failed`; `failure` is the reason's name."""

    def __init__(self, text, failure, progress):
        super().__init__(text)
        self.failure = failure
        self.progress = progress


class ProtocolMismatch(DriveError):
    """The drive's version frame names another protocol version than this client's table: its
    frames would decode wrongly. `drive` and `client` are the two protocol versions."""

    def __init__(self, text, drive, client):
        super().__init__(text)
        self.drive = drive
        self.client = client
