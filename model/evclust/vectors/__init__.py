"""Golden vectors (SPEC §6): the fixed model's inputs, outputs and per-event trace, packed as the
RTL sees them, for cocotb to replay bit for bit.

vectors/<case>/: manifest.json, events.hex, expected.hex, trace.hex. Field layouts are in the
manifest and in vectors/README.md; widths come from the formats table, so they follow it.
"""

from evclust.vectors.cases import CASES
from evclust.fixed.layouts import TRACE_FIELDS, event_fields, record_fields
from evclust.vectors.write import check_vectors, write_case, write_vectors

__all__ = ["CASES", "TRACE_FIELDS", "event_fields", "record_fields", "check_vectors", "write_case", "write_vectors"]
