"""The end of `imdrive watch`, in drive_monitor's words (tools/drive_monitor/capture_report.cpp):
one line that counts every frame read and why each skipped one was skipped, the frames the
capture lost, and a warning when no frame came from the watched node (commands to it do not
count: another host sent them), naming the nodes heard instead."""

# FrameDecoder's skip reasons, as the summary line words them, in its order.
_REASONS = (("error_frame", "error frames"), ("extended_id", "with 29-bit ids"),
            ("fd_frame", "CAN FD"), ("remote_frame", "remote"), ("other_node", "of other nodes"),
            ("unknown_message", "of unknown messages"), ("wrong_length", "of wrong length"))


def _skipped(monitor, bus):
    """The monitor's skip counts plus those of a bus that filters before it (LogReplayBus)."""
    counts = dict(monitor.skipped)
    for reason, n in getattr(bus, "skipped", {}).items():
        counts[reason] = counts.get(reason, 0) + n
    return counts


def _other_nodes(monitor):
    """'node 2: 20, node 5: 3' for every other node heard."""
    heard = sorted(monitor.decoder.other_nodes.items())
    return ", ".join(f"node {node}: {n}" for node, n in heard)


def frames_from_node(monitor):
    decoder = monitor.decoder
    return decoder.decoded - decoder.commands


def summary_line(monitor, samples, bus=None):
    """'47 frames: 30 decoded (26 from node 1, 4 commands to it), 3 samples; skipped: 3 error
    frames, ...; the capture lost 2 frames' (the last part only when it lost some)."""
    decoder = monitor.decoder
    skipped = _skipped(monitor, bus)
    parts = []
    for reason, words in _REASONS:
        text = f"{skipped.get(reason, 0)} {words}"
        if reason == "other_node" and decoder.other_nodes:
            text += f" ({_other_nodes(monitor)})"
        parts.append(text)
    text = (f"{decoder.decoded + sum(skipped.values())} frames: {decoder.decoded} decoded "
            f"({frames_from_node(monitor)} from node {monitor.node_id}, {decoder.commands} "
            f"commands to it), {samples} samples; skipped: {', '.join(parts)}")
    lost = getattr(bus, "dropped", 0)
    if lost:
        text += f"; the capture lost {lost} frames"
    return text


def silent_node_warning(monitor, source):
    """The warning when no frame came from the node, else None."""
    if frames_from_node(monitor) > 0:
        return None
    text = f"warning: no frame from node {monitor.node_id} on {source}"
    if monitor.decoder.commands:
        text += f" ({monitor.decoder.commands} commands to it)"
    if monitor.decoder.other_nodes:
        text += f"; heard only other nodes ({_other_nodes(monitor)}): is --node right?"
    else:
        text += "; no other node either"
    return text
