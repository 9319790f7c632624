"""The RTL's enumerations are generated from evclust.fixed.enums: each module includes its
rtl/<module>_enums.vh, the committed file is the generator's output byte for byte, and no module
declares one of those codes by hand."""

from __future__ import annotations

import re

import pytest

from evclust.fixed.enums import ENUMS, declaration, enum, header, header_name
from evclust.fixed.fixed_model import TRACE_CREATE, TRACE_DROP, TRACE_EVICT, TRACE_UNSUPPORTED, TRACE_UPDATE
from evclust.rtl.sources import RTL_DIR, RTL_INCLUDES

CASES = [(module, e) for module, enums in ENUMS.items() for e in enums]


@pytest.mark.parametrize("module", ENUMS)
def test_the_committed_include_is_the_generators_output(module):
    # regenerate with `make params`
    assert (RTL_DIR / header_name(module)).read_text() == header(module)
    assert header_name(module) in RTL_INCLUDES  # so co-simulation, synthesis and the wheel carry it


@pytest.mark.parametrize("module", ENUMS)
def test_the_module_includes_its_enums_once(module):
    rtl = (RTL_DIR / f"{module}.v").read_text()
    assert len(re.findall(rf'^`include "{header_name(module)}"', rtl, flags=re.M)) == 1


@pytest.mark.parametrize("module, e", CASES, ids=[f"{m}-{e.prefix}" for m, e in CASES])
def test_no_module_declares_an_enums_code_by_hand(module, e):
    for source in RTL_DIR.glob("*.v"):
        for name in e.names():
            assert not re.search(rf"\blocalparam\b[^;]*\b{name}\s*=", source.read_text()), f"{source.name} declares {name}"


@pytest.mark.parametrize("module, e", CASES, ids=[f"{m}-{e.prefix}" for m, e in CASES])
def test_each_declaration_holds_every_code_in_its_width(module, e):
    line = declaration(e)
    codes = {name: int(code) for name, code in re.findall(rf"(\w+) = {e.width}'d(\d+)", line)}
    assert codes == e.names()
    assert all(0 <= code < 2**e.width for code in codes.values())
    assert len(set(codes.values())) == len(codes)  # distinct codes: a machine's states never alias


def test_the_fixed_models_trace_codes_are_the_tables():
    model = {"TRACE_UPDATE": TRACE_UPDATE, "TRACE_CREATE": TRACE_CREATE, "TRACE_EVICT": TRACE_EVICT, "TRACE_DROP": TRACE_DROP,
             "TRACE_UNSUPPORTED": TRACE_UNSUPPORTED}  # fmt: skip
    assert enum("evclust_core", "TRACE_").names() == model


def test_a_changed_code_changes_the_include():
    changed = dict(enum("evclust_core", "TRACE_").codes, EVICT=5)
    assert "TRACE_EVICT = 3'd5" in declaration(enum("evclust_core", "TRACE_")._replace(codes=changed))
    assert "TRACE_EVICT = 3'd2" in header("evclust_core")
