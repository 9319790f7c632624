"""The bit-exact scoreboard: the RTL's trace and records against the model's, reporting the first
mismatch field by field with the event index and the vector file lines that locate it."""

from __future__ import annotations

from evclust.vectors.pack import TRACE_FIELDS, unpack

ACTIONS = ("update", "create", "evict", "drop")


def describe_trace(word: int) -> str:
    action, slot = unpack(word, TRACE_FIELDS)
    return f"{ACTIONS[action]} slot {slot}"


def describe_event(word: int, fields) -> str:
    return ", ".join(f"{f[0]}={v}" for f, v in zip(fields, unpack(word, fields)))


def first_mismatch(name: str, events: list[int], event_fields, expected_trace: list[int], trace: list[int],
                   record_fields, expected: list[int], records: list[int], tags: list[int]) -> str | None:  # fmt: skip
    """None when the streams agree bit for bit; else one message on the first difference.
    `tags[j]`: how many events the RTL had traced when record j left it."""
    for i, (want, got) in enumerate(zip(expected_trace, trace)):
        if want != got:
            return (
                f"{name}: event {i} (events.hex/trace.hex line {i + 1}: {describe_event(events[i], event_fields)}): "
                f"RTL did '{describe_trace(got)}', the model '{describe_trace(want)}'"
            )
    if len(trace) != len(expected_trace):
        return f"{name}: the RTL traced {len(trace)} events, the model {len(expected_trace)}"
    for j, (want, got) in enumerate(zip(expected, records)):
        if want != got:
            event = tags[j] - 1 if j < len(tags) else -1
            diffs = [
                f"{f[0]}: RTL {g}, model {w}" for f, w, g in zip(record_fields, unpack(want, record_fields), unpack(got, record_fields)) if w != g
            ]  # fmt: skip
            return (
                f"{name}: record {j} (expected.hex line {j + 1}), emitted after event {event} "
                f"(trace.hex line {event + 1}): " + "; ".join(diffs)
            )
    if len(records) != len(expected):
        j = min(len(records), len(expected))
        extra = "the RTL's" if len(records) > len(expected) else "the model's"
        return f"{name}: the RTL emitted {len(records)} records, the model {len(expected)}; first unmatched is {extra} record {j}"
    return None
