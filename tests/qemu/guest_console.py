"""Following a qemu guest's serial console: the markers its /init and /bin/emit print
(guest_initramfs.py), console.log, and the files the guest emits."""
import base64
import hashlib
import re
import time

# Console markers between the guest's /init, /bin/emit (INIT_SCRIPT and EMIT_SCRIPT in
# guest_initramfs.py) and this module. Distinctive enough that a test's own output does not
# contain them by accident.
MARK = "@@qemu_guest:"
START_RE = re.compile(re.escape(MARK) + r"start uptime_s=(\S+)")
END_RE = re.compile(re.escape(MARK) + r"end rc=(\d+) uptime_s=(\S+)")
SETUP_FAILED_RE = re.compile(re.escape(MARK) + r"setup-failed (.*)")
EMIT_BEGIN_RE = re.compile(re.escape(MARK) + r"emit-begin (\S+)")
EMIT_END_RE = re.compile(re.escape(MARK) + r"emit-end (\S+) (\d+) ([0-9a-f]{64})")
BASE64_LINE_RE = re.compile(r"^[A-Za-z0-9+/=]+$")
EMIT_NAME_RE = re.compile(r"^[A-Za-z0-9._-]+$")

# Lines of the console printed when the run fails.
TAIL_LINES = 40


class Console:
    """Follows the guest's console line by line: writes console.log, notes when the markers
    arrive (host time), and collects the files the guest emits."""

    def __init__(self, log_path, out_dir, started):
        self.log = open(log_path, "w", encoding="utf-8", errors="replace")
        self.out_dir = out_dir
        self.started = started
        self.start_time = None   # host seconds since QEMU started, at the start marker
        self.guest_uptime_at_start = None
        self.end_time = None
        self.exit_code = None
        self.setup_failure = None
        self.panic = None        # the kernel's "Kernel panic - ..." line, if it printed one
        self.emitting = None     # (name, base64 lines) inside an emit block
        self.emitted = []
        self.damaged = []
        self.tail = []
        self.partial = b""

    def feed(self, data):
        self.partial += data
        *lines, self.partial = self.partial.split(b"\n")
        for line in lines:
            self._line(line.decode("utf-8", errors="replace").rstrip("\r"))

    def flush(self):
        if self.partial:
            self._line(self.partial.decode("utf-8", errors="replace").rstrip("\r"))
            self.partial = b""
        self.log.flush()

    def _record(self, line):
        self.log.write(line + "\n")
        self.tail = (self.tail + [line])[-TAIL_LINES:]

    def _line(self, line):
        now = time.monotonic() - self.started
        if self.emitting is not None:
            name, chunks = self.emitting
            end = EMIT_END_RE.search(line)
            if end and end.group(1) == name:
                self._finish_emit(name, chunks, int(end.group(2)), end.group(3))
                self._record(line)
            elif BASE64_LINE_RE.match(line):
                chunks.append(line)  # payload: out/NAME has it, console.log need not
            else:
                self._record(line)   # anything else that reached the console meanwhile
            return
        self._record(line)
        if self.panic is None and "Kernel panic - " in line:
            self.panic = line[line.index("Kernel panic - "):]
        if match := EMIT_BEGIN_RE.search(line):
            self.emitting = (match.group(1), [])
        elif match := START_RE.search(line):
            self.start_time = now
            self.guest_uptime_at_start = float(match.group(1))
        elif match := END_RE.search(line):
            self.end_time = now
            self.exit_code = int(match.group(1))
        elif match := SETUP_FAILED_RE.search(line):
            self.setup_failure = match.group(1)

    def _finish_emit(self, name, chunks, size, sha256):
        self.emitting = None
        self._record(f"[qemu_guest.py: {len(chunks)} lines of base64 for out/{name} elided]")
        try:
            data = base64.b64decode("".join(chunks), validate=True)
        except ValueError:
            data = None
        if not EMIT_NAME_RE.match(name) or name in (".", ".."):
            self.damaged.append(f"{name}: not a valid file name")
        elif data is None or len(data) != size or hashlib.sha256(data).hexdigest() != sha256:
            decoded = 0 if data is None else len(data)
            self.damaged.append(f"{name}: damaged in transit ({decoded} of "
                                f"{size} bytes decoded, checksum mismatch; kernel messages or "
                                f"other output interleaved?)")
        else:
            (self.out_dir / name).write_bytes(data)
            self.emitted.append(name)
