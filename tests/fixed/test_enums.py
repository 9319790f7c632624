"""The RTL declares the enumerations of evclust.fixed.enums, code for code: the trace actions and the
flags the models write, and the machines' states."""

from __future__ import annotations

import re

import pytest

from evclust.fixed.enums import ENUMS, declaration
from evclust.fixed.fixed_model import TRACE_CREATE, TRACE_DROP, TRACE_EVICT, TRACE_UNSUPPORTED, TRACE_UPDATE
from evclust.rtl.sources import RTL_DIR

CASES = [(module, enum) for module, enums in ENUMS.items() for enum in enums]


def _statement(text: str, prefix: str) -> str:
    """The `localparam [..:0] PREFIX... = ..;` statement of a module, its whitespace normalised."""
    found = re.findall(rf"localparam\s*\[\d+:0\]\s*{prefix}\w+\s*=[^;]*;", text)
    assert len(found) == 1, f"{prefix}*: {len(found)} declarations"
    return " ".join(found[0].split())


@pytest.mark.parametrize("module, enum", CASES, ids=[f"{m}-{e.prefix}" for m, e in CASES])
def test_the_module_declares_the_enum_as_the_table_says(module, enum):
    rtl = _statement((RTL_DIR / f"{module}.v").read_text(), enum.prefix)
    codes = {name: int(code) for name, code in re.findall(r"(\w+)\s*=\s*\d+'d(\d+)", rtl)}
    assert codes == enum.names()
    assert rtl == declaration(enum)


def test_the_fixed_models_trace_codes_are_the_tables():
    trace = ENUMS["evclust_core"][0].names()
    model = {"TRACE_UPDATE": TRACE_UPDATE, "TRACE_CREATE": TRACE_CREATE, "TRACE_EVICT": TRACE_EVICT, "TRACE_DROP": TRACE_DROP,
             "TRACE_UNSUPPORTED": TRACE_UNSUPPORTED}  # fmt: skip
    assert trace == model


def test_a_changed_code_is_caught():
    text = (RTL_DIR / "evclust_core.v").read_text().replace("TRACE_EVICT = 3'd2", "TRACE_EVICT = 3'd5")
    assert _statement(text, "TRACE_") != declaration(ENUMS["evclust_core"][0])
