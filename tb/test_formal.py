"""The formal proofs (formal/*/*.sby, SymbiYosys k-induction) pass, and a broken interface fails
its proof: the properties can catch what they claim to."""

from __future__ import annotations

import shutil

import pytest

from evclust.rtl.formal import FORMAL_DIR, jobs, prove
from evclust.rtl.sources import RTL_DIR


@pytest.mark.parametrize("sby", jobs(), ids=lambda p: p.stem)
def test_the_interface_properties_are_proved(sby):
    result = prove(sby)
    assert result["status"] == "PASS", result["log"][-3000:]
    assert "successful proof by k-induction" in result["log"]


# Each breakage names the properties that may catch it first (the proof stops at the first
# failing step; a clocked assertion reports a step after the combinational invariants).
BREAKAGES = {
    "response dropped before it is taken": (
        "            if (s_axil_bvalid && s_axil_bready)\n                s_axil_bvalid <= 1'b0;",
        "            if (s_axil_bvalid)\n                s_axil_bvalid <= 1'b0;",
        ("assert (s_axil_bvalid);", "assert (f_aw_open ==", "assert (f_w_open =="),
    ),
    "a second read accepted while the first is on offer": (
        "s_axil_arready <= !s_axil_rvalid && !s_axil_arready && s_axil_arvalid;",
        "s_axil_arready <= !s_axil_arready && s_axil_arvalid;",
        ("assert (f_ar_open ==", "!(s_axil_arready && s_axil_rvalid)", "assert (!s_axil_rvalid || f_ar_open"),
    ),
}


@pytest.mark.parametrize("breakage", sorted(BREAKAGES))
def test_a_broken_register_slave_fails_its_proof(breakage, tmp_path):
    old, new, properties = BREAKAGES[breakage]
    (tmp_path / "rtl").mkdir()
    for path in RTL_DIR.iterdir():
        if path.suffix in (".v", ".vh"):
            shutil.copy(path, tmp_path / "rtl" / path.name)
    source = (tmp_path / "rtl" / "evclust_regs.v").read_text()
    assert source.count(old) == 1
    (tmp_path / "rtl" / "evclust_regs.v").write_text(source.replace(old, new))
    shutil.copytree(FORMAL_DIR / "evclust_regs", tmp_path / "formal" / "evclust_regs")
    result = prove(tmp_path / "formal" / "evclust_regs" / "evclust_regs.sby", tmp_path / "run")
    assert result["status"] == "FAIL", result["log"][-3000:]
    props = (FORMAL_DIR / "evclust_regs" / "evclust_regs_props.vh").read_text().splitlines()
    lines = {i + 1 for i, text in enumerate(props) if any(p in text for p in properties)}
    assert len(lines) == len(properties)
    caught = {int(where.split("evclust_regs_props.vh:")[1].split(".")[0]) for where in result["failed"] if "evclust_regs_props.vh:" in where}
    assert caught and caught <= lines, (caught, lines)
