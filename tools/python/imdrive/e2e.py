"""End-to-end protection of command frames, as firmware/protocol/e2e.hpp does it (AUTOSAR E2E
profile 1 style): byte 0 is a CRC-8 SAE J1850 (polynomial 0x1D, initial value 0xFF, final XOR
0xFF) over the 11-bit CAN identifier (low byte first) and bytes 1..length-1; the low nibble of
byte 1 is a 4-bit alive counter. The identifier in the CRC makes a frame that reached the wrong
node or message fail its check."""

COUNTER_MODULO = 16


def crc8_sae_j1850(data, crc=0xFF):
    """CRC-8 SAE J1850 without the final XOR (bitwise: a frame has at most 9 bytes to cover)."""
    for byte in data:
        crc ^= byte
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1D) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc


def e2e_crc(can_id, data, length):
    """The CRC of a command frame: over the data id and bytes 1..length-1 (byte 0 is the CRC)."""
    covered = bytes([can_id & 0xFF, (can_id >> 8) & 0xFF]) + bytes(data[1:min(length, 8)])
    return crc8_sae_j1850(covered) ^ 0xFF


def e2e_counter(data):
    return data[1] & 0x0F


def e2e_protect(can_id, data, length, counter):
    """Fills in the counter and the CRC of a command payload (a bytearray, already written)."""
    data[1] = (data[1] & 0xF0) | (counter & 0x0F)
    data[0] = e2e_crc(can_id, data, length)


def e2e_check(can_id, data, length):
    """Whether byte 0 is the right CRC for the rest of the frame."""
    return length >= 2 and data[0] == e2e_crc(can_id, data, length)
