"""The ECP5 timing flow's reading of a nextpnr report (evclust.rtl.timing), on a report written
here in nextpnr's JSON layout with known figures."""

import json

from evclust.rtl.timing import _critical_path, _figures, cache_key


def _step(kind, delay, cell, sources=()):
    return {"type": kind, "delay": delay, "from": {"cell": cell}, "to": {"cell": cell}, "sources": list(sources)}


REPORT = {
    "fmax": {"clk": {"achieved": 87.5, "constraint": 100}},
    "utilization": {
        "TRELLIS_COMB": {"used": 1200, "available": 83640},
        "TRELLIS_FF": {"used": 800, "available": 83640},
        "MULT18X18D": {"used": 12, "available": 156},
        "DP16KD": {"used": 0, "available": 208},
    },
    "critical_paths": [
        {"from": "posedge clk", "to": "<async>", "path": [_step("logic", 9.0, "port")]},  # not clk to clk: ignored
        {"from": "posedge clk", "to": "posedge clk", "path": [
            _step("clk-to-q", 0.5, "a_ff"),
            _step("routing", 1.0, "a_ff", ["evclust_core.v:10.1-10.5"]),
            _step("logic", 0.25, "x_CCU2C_S0$CCU2_COMB0"),
            _step("routing", 0.0, "x_CCU2C_S0$CCU2_COMB0"),
            _step("logic", 0.25, "x_CCU2C_S0$CCU2_COMB1"),
            _step("routing", 2.0, "lut", ["evclust_core.v:20.1-20.9"]),
            _step("logic", 1.5, "lut"),
            _step("setup", 0.5, "b_ff"),
        ]},
    ],
}  # fmt: skip


def test_the_clk_to_clk_path_is_counted_in_cells_carry_cells_and_nanoseconds():
    path = _critical_path(REPORT)
    assert path["from"] == "a_ff" and path["to"] == "b_ff"
    assert path["cells"] == 3 and path["carry_cells"] == 2  # two carry halves and one LUT
    assert path["logic_ns"] == 0.5 + 0.25 + 0.25 + 1.5 + 0.5
    assert path["routing_ns"] == 3.0
    assert path["sources"] == ["evclust_core.v:10.1-10.5", "evclust_core.v:20.1-20.9"]


def test_figures_give_fmax_resources_and_fit(tmp_path):
    (tmp_path / "report.json").write_text(json.dumps(REPORT))
    figures = _figures(tmp_path)
    assert figures["fmax_mhz"] == 87.5
    assert figures["resources"]["lut4"] == 1200 and figures["resources"]["mult18"] == 12
    assert figures["available"]["mult18"] == 156 and figures["fits"]
    assert figures["carry_cells"] == 0  # no Yosys statistics here
    (tmp_path / "stat.txt").write_text("   Number of cells:  2000\n     15982   CCU2C\n     61846   LUT4\n")
    assert _figures(tmp_path)["carry_cells"] == 15982
    over = json.loads(json.dumps(REPORT))
    over["utilization"]["MULT18X18D"]["used"] = 157
    (tmp_path / "report.json").write_text(json.dumps(over))
    assert not _figures(tmp_path)["fits"]


def test_the_cache_key_follows_the_header_the_sources_and_routing():
    sources = {"evclust_core.v": "module evclust_core; endmodule\n"}
    key = cache_key("localparam integer N_CLUSTERS = 16;\n", sources, True, "tools 1")
    assert key == cache_key("localparam integer N_CLUSTERS = 16;\n", dict(sources), True, "tools 1")
    assert key != cache_key("localparam integer N_CLUSTERS = 4;\n", sources, True, "tools 1")
    assert key != cache_key(
        "localparam integer N_CLUSTERS = 16;\n", {"evclust_core.v": "module evclust_core; wire w; endmodule\n"}, True, "tools 1"
    )
    assert key != cache_key("localparam integer N_CLUSTERS = 16;\n", sources, False, "tools 1")
    assert key != cache_key("localparam integer N_CLUSTERS = 16;\n", sources, True, "tools 2")


def test_a_design_too_large_for_the_part_is_a_result_with_its_utilisation(tmp_path):
    from evclust.rtl.timing import _unplaced

    (tmp_path / "nextpnr.log").write_text(
        "Info: Device utilisation:\n"
        "Info: \t          MULT18X18D:     144/    156    92%\n"
        "Info: \t          TRELLIS_FF:   17129/  83640    20%\n"
        "Info: \t        TRELLIS_COMB:   94699/  83640   113%\n"
        "ERROR: Unable to find legal placement for all cells, design is probably at utilisation limit.\n")  # fmt: skip
    figures = _unplaced(tmp_path)
    assert figures["fmax_mhz"] is None and not figures["fits"]
    assert figures["resources"]["lut4"] == 94699 and figures["available"]["lut4"] == 83640
    assert figures["resources"]["mult18"] == 144 and figures["resources"]["ff"] == 17129
    (tmp_path / "nextpnr.log").write_text("ERROR: something else\n")
    assert _unplaced(tmp_path) is None  # any other failure stays an error


def test_the_tools_see_their_run_folder_by_relative_paths_only(tmp_path, monkeypatch):
    """yowasp maps its own temporary folder over /tmp, so a clone under /tmp could not run `make
    timing` while the tools were given absolute paths: every path they see is relative to their
    run folder (the place-and-route step is stubbed out; the scripts and arguments are real)."""
    from evclust.rtl import timing

    build = tmp_path / "clone" / "build"  # an absolute path, like a clone in the system temporary folder
    seen = []

    def fake_run(tool, args, out, log, heartbeat):
        seen.append((tool, args, (out / "synth.ys").read_text()))
        raise timing.EvclustError("stop here")

    monkeypatch.setattr(timing, "BUILD", build)
    monkeypatch.setattr(timing, "tool_identity", lambda: "yowasp (stub)")
    monkeypatch.setattr(timing, "_run", fake_run)
    try:
        timing.place_and_route("// header\n", "check", snapshot=({"evclust_core.v": "module m; endmodule\n"}, "abc1234"))
    except timing.EvclustError:
        pass
    ((tool, args, script),) = seen
    assert tool == "yosys"
    text = " ".join(args) + "\n" + script
    assert str(tmp_path) not in text and "/tmp" not in text
    assert "read_verilog -defer -Isrc src/" in script and " src/evclust_core.v" in script and "-json netlist.json" in script
    assert all(not a.startswith("/") for a in timing.nextpnr_args(timing.Path("."), True))


def test_a_run_may_stop_after_placement(timing_script):
    script = timing_script
    assert script.parse_run("defaults:64:placed") == ("defaults", 64, True)
    assert script.parse_run("paper:16") == ("paper", 16, False)
    for bad in ("defaults", "defaults:x", "nope:16", "paper:16:routed"):
        try:
            script.parse_run(bad)
        except Exception as exc:  # argparse.ArgumentTypeError: a one-line reason
            assert bad in str(exc)
        else:
            raise AssertionError(f"{bad!r} accepted")


def test_a_placement_only_run_gives_nextpnrs_estimate_from_its_log(tmp_path):
    # Without routing nextpnr's report leaves `fmax` empty; the log has the estimate.
    placed = json.loads(json.dumps(REPORT)) | {"fmax": {}}
    (tmp_path / "report.json").write_text(json.dumps(placed))
    (tmp_path / "nextpnr.log").write_text(
        "Info: Max frequency for clock 'clk': 4.10 MHz (FAIL at 100.00 MHz)\n...\nInfo: Max frequency for clock 'clk': 5.70 MHz (FAIL at 100.00 MHz)\n"
    )
    assert _figures(tmp_path)["fmax_mhz"] == 5.7  # the last estimate: after the placer's refinement
    (tmp_path / "nextpnr.log").write_text("Info: Program finished normally.\n")
    try:
        _figures(tmp_path)
    except Exception as exc:  # EvclustError: a one-line reason naming the log
        assert "no Fmax" in str(exc) and "nextpnr.log" in str(exc)
    else:
        raise AssertionError("a report and a log without Fmax must not give a figure")


def test_a_finished_run_whose_figures_were_not_written_is_read_not_rerun(tmp_path, monkeypatch):
    import os

    from evclust.rtl import timing

    header, sources = "// header\n", {"evclust_core.v": "module m; endmodule\n"}
    monkeypatch.setattr(timing, "BUILD", tmp_path)
    monkeypatch.setattr(timing, "tool_identity", lambda: "yowasp (stub)")
    monkeypatch.setattr(timing, "_run", lambda *a: (_ for _ in ()).throw(AssertionError("the tools ran again")))
    out = tmp_path / "timing" / f"check-{timing.cache_key(header, sources, False, 'yowasp (stub)', False)}"
    out.mkdir(parents=True)
    for name, text, when in (("synth.ys", "", 1000), ("netlist.json", "{}", 1300), ("report.json", json.dumps(REPORT), 2000),
                             ("nextpnr.log", "Info: Program finished normally.\n", 2000)):  # fmt: skip
        (out / name).write_text(text)
        os.utime(out / name, (when, when))
    figures = timing.place_and_route(header, "check", route=False, snapshot=(sources, "abc1234"))
    assert figures["fmax_mhz"] == 87.5 and figures["cached"]
    assert (figures["synth_s"], figures["pnr_s"]) == (300, 700)  # from the files' times
    assert json.loads((out / "figures.json").read_text())["rtl"] == "abc1234"
