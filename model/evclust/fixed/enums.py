"""The RTL's enumerations, one table: the codes the models and the vectors share with the core (the
trace's actions, a record's flags) and the state codes of the core's and the object unit's
machines. Each is written as the one `localparam` line its module declares (`declaration`), and
tests/fixed/test_enums.py checks every module's declaration against this table, so that a code
cannot change on one side alone. (The γ modes are the formats table's: evclust_params.vh.)"""

from __future__ import annotations

from typing import NamedTuple

from evclust.fixed.layouts import TRACE_ACTIONS, TRACE_FIELDS
from evclust.tracks.record import TrackFlags


class VerilogEnum(NamedTuple):
    prefix: str  # the names' prefix in the RTL
    width: int  # bits of the localparam
    codes: dict[str, int]  # name (without the prefix) -> code, in declaration order

    def names(self) -> dict[str, int]:
        return {self.prefix + name: code for name, code in self.codes.items()}


ENUMS = {
    "evclust_core": (
        # what an event did; a track record's flags; the core's machine; the filter step's phase unit
        VerilogEnum("TRACE_", {f[0]: f[1] for f in TRACE_FIELDS}["action"], {a.upper(): i for i, a in enumerate(TRACE_ACTIONS)}),
        VerilogEnum("FLAG_", 4, {f.name: int(f) for f in TrackFlags}),
        VerilogEnum("ST_", 3, {s: i for i, s in enumerate(("INIT", "IDLE", "EXEC", "SCAN", "EVICT", "SWEEP", "MERGE", "PHASE"))}),
        VerilogEnum("PHASE_", 2, {"DECIDE": 0, "BY_TAU": 1, "FRAME": 2}),
    ),
    "evclust_objects": (
        # the object unit's machine (code 2 is no longer used: the codes are kept as they were
        # built); the association's scans
        VerilogEnum(
            "S_",
            4,
            {
                "COLLECT": 0,
                "DT": 1,
                "PREDICT": 3,
                "PREP": 4,
                "LINK": 5,
                "GROUP": 6,
                "OWNER": 7,
                "CLAIM": 8,
                "ASSOC": 9,
                "JOIN": 10,
                "UPDATE": 11,
                "MERGE": 12,
                "OUT": 13,
            },
        ),  # fmt: skip
        VerilogEnum("SCAN_", 2, {"INSIDE": 0, "GATE": 1, "FREE": 2, "TAKE": 3}),
    ),
}


def declaration(enum: VerilogEnum) -> str:
    """The enum as one Verilog-2005 `localparam` statement."""
    body = ", ".join(f"{name} = {enum.width}'d{code}" for name, code in enum.names().items())
    return f"localparam [{enum.width - 1}:0] {body};"
