"""The RTL is clean under `verilator --lint-only -Wall` for every parameter set we ship."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest


from lint import lint

from evclust.vectors.read import load_case

VECTORS = Path(__file__).resolve().parents[1] / "vectors"


@pytest.mark.parametrize("top", ["evclust_axis", "evclust_core"])
def test_the_reference_rtl_is_lint_clean(top):
    assert lint(top=top) == ""


@pytest.mark.parametrize("case", ["table_full", "palette_tie", "pedestrian_clip", "suite_clip", "creation_support", "merge_edges",
                                  "pipelined_traffic"])  # fmt: skip
def test_the_rtl_is_lint_clean_for_other_parameter_sets(case):
    # N = 4; nearest palette with a fixed background; another sensor and other formats; the
    # default configuration (merging, scaled seek, noise gate, warm-up); the support map; merging
    # with a warm-up table; the commit one event later (update_delay = 1).
    assert lint(load_case(VECTORS / case).header) == ""


def test_lint_reports_a_real_problem(tmp_path):
    # The check is not vacuous: a header that breaks a width is reported.
    header = (Path(__file__).resolve().parents[1] / "rtl" / "evclust_params.vh").read_text()
    assert lint(header.replace("localparam integer FILTER_EVERY = 64;", "localparam integer FILTER_EVERY = 64;\nwire spare;")) != ""


@pytest.mark.parametrize("target", ["lint", "axis_lint"])
def test_the_fusesoc_core_file_lints_through_edalize(tmp_path, target):
    import os
    import shutil
    import subprocess

    from cosim import use_simulator

    use_simulator("verilator")
    fusesoc = shutil.which("fusesoc", path=str(Path(sys.executable).parent)) or "fusesoc"
    root = Path(__file__).resolve().parents[1]
    done = subprocess.run([fusesoc, "--cores-root", str(root), "run", "--target", target, "evclust:evclust:core"],
                          cwd=tmp_path, capture_output=True, text=True, env=os.environ)  # fmt: skip
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    assert "%Warning" not in done.stdout + done.stderr


def test_the_fusesoc_core_file_lists_every_rtl_file():
    # a file the RTL needs but the core file leaves out fails only where a FuseSoC user builds it
    import re

    from evclust.rtl.sources import RTL_INCLUDES, RTL_SOURCES

    text = (Path(__file__).resolve().parents[1] / "evclust.core").read_text()
    listed = set(re.findall(r"^\s+- (rtl/[\w.]+)", text, flags=re.M))
    assert {f"rtl/{name}" for name in (*RTL_SOURCES, *RTL_INCLUDES, "evclust_params.vh")} <= listed
