"""The bit-exact scoreboard: the RTL's trace and records against the model's, reporting the first
mismatch field by field with the event index and the vector file lines that locate it."""

from __future__ import annotations

from evclust.fixed.layouts import TRACE_ACTIONS, TRACE_FIELDS
from evclust.vectors.pack import unpack


def describe_trace(word: int) -> str:
    action, slot = unpack(word, TRACE_FIELDS)
    return f"{TRACE_ACTIONS[action]} slot {slot}"


def describe_event(word: int, fields) -> str:
    return ", ".join(f"{f[0]}={v}" for f, v in zip(fields, unpack(word, fields)))


def first_mismatch(name: str, events: list[int], event_fields, expected_trace: list[int], trace: list[int],
                   record_fields, expected: list[int], records: list[int], tags: list[int]) -> str | None:  # fmt: skip
    """None when the streams agree bit for bit; else one message on the first difference, in
    stream order: a record that left after event i is reported before a trace difference at a
    later event. `tags[j]`: how many events the RTL had traced when record j left it."""
    trace_at = next((i for i, (want, got) in enumerate(zip(expected_trace, trace)) if want != got), None)
    record_at = next((j for j, (want, got) in enumerate(zip(expected, records)) if want != got), None)
    record_event = (tags[record_at] - 1 if record_at < len(tags) else -1) if record_at is not None else None
    if record_at is not None and (trace_at is None or record_event < trace_at):
        diffs = [
            f"{f[0]}: RTL {g}, model {w}"
            for f, w, g in zip(record_fields, unpack(expected[record_at], record_fields), unpack(records[record_at], record_fields)) if w != g
        ]  # fmt: skip
        return (
            f"{name}: record {record_at} (expected.hex line {record_at + 1}), emitted after event {record_event} "
            f"(trace.hex line {record_event + 1}): " + "; ".join(diffs)
        )
    if trace_at is not None:
        i = trace_at
        return (
            f"{name}: event {i} (events.hex/trace.hex line {i + 1}: {describe_event(events[i], event_fields)}): "
            f"RTL did '{describe_trace(trace[i])}', the model '{describe_trace(expected_trace[i])}'"
        )
    if len(trace) != len(expected_trace):
        return f"{name}: the RTL traced {len(trace)} events, the model {len(expected_trace)}"
    if len(records) != len(expected):
        j = min(len(records), len(expected))
        extra = "the RTL's" if len(records) > len(expected) else "the model's"
        return f"{name}: the RTL emitted {len(records)} records, the model {len(expected)}; first unmatched is {extra} record {j}"
    return None


def first_object_mismatch(name: str, object_fields, expected: list[int], objects: list[int], tags: list[int],
                          tagged: str = "event", source: str = "objects.hex") -> str | None:  # fmt: skip
    """None when the object records agree bit for bit; else the first difference, field by field,
    with the events traced (or the `tagged` things counted) when the RTL's object record left
    (check the cluster records first: a cluster record that differs makes every object record
    after it differ). `source`: where the expected records are written."""
    at = next((j for j, (want, got) in enumerate(zip(expected, objects)) if want != got), None)
    if at is not None:
        diffs = [
            f"{f[0]}: RTL {g}, model {w}"
            for f, w, g in zip(object_fields, unpack(expected[at], object_fields), unpack(objects[at], object_fields)) if w != g
        ]  # fmt: skip
        after = f", emitted after {tagged} {tags[at] - 1}" if at < len(tags) else ""
        return f"{name}: object record {at} ({source} line {at + 1}){after}: " + "; ".join(diffs)
    if len(objects) != len(expected):
        extra = "the RTL's" if len(objects) > len(expected) else "the model's"
        return f"{name}: the RTL emitted {len(objects)} object records, the model {len(expected)}; first unmatched is {extra} record {min(len(objects), len(expected))}"
    return None
