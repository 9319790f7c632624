"""The census of a routed core's endpoints (evclust.rtl.census), on a report written here in
nextpnr's JSON layout (`--detailed-timing-report`) with known arrival times."""

import json

from evclust.rtl.census import compare, comparison_table, endpoint_census, main, register_of


def _net(driver, *endpoints, event="posedge clk"):
    """A net of the report: each endpoint (cell, port, arrival ns) with its own routing delay."""
    return {"driver": driver, "event": event, "net": f"{driver}_net", "port": "F", "sources": [],
            "endpoints": [{"cell": c, "port": p, "delay": [0.5, t], "event": event} for c, p, t in endpoints]}  # fmt: skip


REPORT = {
    "detailed_net_timings": [
        _net("lut0", ("speed_TRELLIS_FF_Q", "DI", 5.0), ("speed_TRELLIS_FF_Q_1", "DI", 25.0)),
        _net("lut1", ("speed_TRELLIS_FF_Q_2", "CE", 9.5)),
        _net("ramw", ("rows.1.2$DPRAM_COMB0", "WD", 12.0), ("rows.0.7$DPRAM_COMB1", "WAD0", 10.5)),
        _net("lut2", ("seek.slot[3].key[2]_TRELLIS_FF_Q", "M", 9.9), ("seek.slot[12].key[0]_TRELLIS_FF_Q", "M", 10.0)),
        _net("io", ("port_TRELLIS_FF_Q", "DI", 99.0), event="<async>"),  # not on the clock: not counted
    ]
}  # fmt: skip


def test_endpoint_cells_are_grouped_by_the_register_they_belong_to():
    assert register_of("speed_TRELLIS_FF_Q") == "speed"
    assert register_of("speed_TRELLIS_FF_Q_11") == "speed"
    assert register_of("valid[12]_TRELLIS_FF_Q") == "valid"
    assert register_of("slot_rows.rows.1.45$DPRAM_COMB1") == "slot_rows.rows"
    assert register_of("seek.slot[15].slot_key.centre_x_TRELLIS_FF_Q_3") == "seek.slot[i].slot_key.centre_x"
    assert register_of("update.s2_TRELLIS_FF_Q") == "update.s2"


def test_the_census_counts_endpoints_past_the_period_and_orders_registers_slowest_first():
    census = endpoint_census(json.loads(json.dumps(REPORT)), 100.0)
    assert census.endpoints == 7  # the asynchronous endpoint is left out
    # 10 ns at 100 MHz: 25, 12 and 10.5 miss; 10.0 is exactly the period and meets it
    assert census.missing == 3
    assert [r.name for r in census.registers] == ["speed", "rows", "seek.slot[i].key"]
    speed, rows, key = census.registers
    assert (speed.endpoints, speed.worst_ns, speed.missing) == (3, 25.0, 1)
    assert (rows.endpoints, rows.worst_ns, rows.missing) == (2, 12.0, 2)
    assert (key.endpoints, key.worst_ns, key.missing) == (2, 10.0, 0)
    assert census.registers_missing == 2
    # cycles of the target clock the slowest input takes: 25 ns is three 10 ns periods, 10 ns one
    assert (speed.cycles(100.0), rows.cycles(100.0), key.cycles(100.0)) == (3, 2, 1)
    assert speed.cycles(40.0) == 1  # 25 ns in a 25 ns period


def test_a_report_without_detailed_timings_has_no_census():
    assert endpoint_census({"fmax": {}, "critical_paths": []}, 100.0) is None


def test_the_share_of_endpoints_within_a_clock_counts_arrivals_up_to_its_period():
    census = endpoint_census(REPORT, 100.0)
    assert census.arrivals_ns == sorted(census.arrivals_ns) and len(census.arrivals_ns) == census.endpoints
    assert census.share_within(100.0) == 4 / 7  # 5, 9.5, 9.9 and 10.0 ns
    assert census.share_within(40.0) == 1.0  # 25 ns
    assert census.share_within(1000.0) == 0.0  # 1 ns: none


def _row(n, lut4, ff, mult18, lutram_w, census=None, routed=False, fmax=5.0):
    return {"configuration": "defaults", "n_clusters": n, "static": False, "routed": routed, "fmax_mhz": fmax, "census": census,
            "resources": {"lut4": lut4, "ff": ff, "mult18": mult18, "lutram_w": lutram_w, "bram": 0},
            "available": {"lut4": 1000, "ff": 1000, "mult18": 100, "lutram_w": 100, "bram": 10}}  # fmt: skip


def test_the_datasheet_extrapolates_the_defaults_to_256_slots_on_the_line_through_the_runs(timing_script):
    script = timing_script
    # 10 cells a slot from N = 16 to 64: 640 + 10 * (256 - 64) = 2560 cells, 256 % of a 1000-cell part
    line = "\n".join(script.extrapolated([_row(16, 160, 32, 4, 16), _row(64, 640, 128, 10, 64)]))
    assert "2,560 logic cells (256 % of the part; 10.00 a slot)" in line
    assert "512 flip-flops (51 % of the part; 2.00 a slot)" in line
    assert "34 multipliers (34 % of the part; 0.12 a slot)" in line  # 10 + 0.125 * 192
    assert "256 distributed RAM write ports (256 % of the part; 1.00 a slot)" in line
    assert script.extrapolated([_row(16, 160, 32, 4, 16)]) == []  # one size gives no line


def test_the_datasheet_gives_the_share_of_endpoints_within_the_target(timing_script):
    script = timing_script
    census = endpoint_census(REPORT, 100.0)
    assert script.within(_row(16, 1, 1, 1, 1, census, routed=True)) == "4 of 7 (57 %)"
    assert "not routed" in script.within(_row(16, 1, 1, 1, 1))
    assert script.within(_row(64, 1, 1, 1, 1, fmax=None)) == "not placed"
    lines = script.census_lines([_row(16, 1, 1, 1, 1, census, routed=True)])
    assert "| defaults, N = 16 | 7 | 3 (43 %) | 3 | 2 | 1, 1, 1 |" in lines  # registers at 1, 2 and 3 cycles
    assert "| `speed` | 3 | 25.0 | 3 |" in lines


def test_cells_yosys_named_after_the_logic_they_sit_in_belong_to_that_register():
    assert register_of("state_TRELLIS_FF_Q_2_DI_LUT4_C_Z_TRELLIS_FF_DI") == "state"
    assert register_of("div_frame.done_LUT4_A_1_Z_LUT4_D_Z_PFUMX_BLUT_Z_TRELLIS_FF_DI") == "div_frame.done"
    assert register_of("div_vmx.tag_q[3]_LUT4_C_1_Z_TRELLIS_FF_DI") == "div_vmx.tag_q"
    assert register_of("seek_w_key.slot_TRELLIS_FF_Q_1_DI_LUT4_C_Z_TRELLIS_FF_DI") == "seek_w_key.slot"


def test_a_comparison_lists_each_register_in_either_run_by_its_change():
    after_report = {"detailed_net_timings": [
        _net("lut0", ("speed_TRELLIS_FF_Q", "DI", 8.0)),  # cut: 25 -> 8
        _net("ramw", ("rows.1.2$DPRAM_COMB0", "WD", 13.0)),  # 12 -> 13
        _net("lut3", ("look_TRELLIS_FF_Q", "DI", 11.0)),  # new
    ]}  # fmt: skip
    before, after = endpoint_census(REPORT, 100.0), endpoint_census(after_report, 100.0)
    changes = compare(before, after)
    assert [(c.register, c.before_ns, c.after_ns) for c in changes] == [
        ("speed", 25.0, 8.0), ("look", None, 11.0), ("seek.slot[i].key", 10.0, None), ("rows", 12.0, 13.0)]  # fmt: skip
    assert changes[0].delta_ns == -17.0
    table = comparison_table(before, after, top=2)
    assert "| missing 100 MHz | 3 | 2 |" in table  # 25, 12, 10.5 before; 13, 11 after
    assert "| slowest arrival (ns) | 25.0 | 13.0 |" in table
    assert "| `speed` | 25.0 | 8.0 |" in table and "| `look` | – | 11.0 |" in table
    assert "| `rows` | 12.0 | 13.0 |" in table  # the slowest after


def test_the_comparison_command_reads_two_reports_and_refuses_one_without_timings(tmp_path, capsys):
    before, after, bare = tmp_path / "before.json", tmp_path / "after.json", tmp_path / "bare.json"
    before.write_text(json.dumps(REPORT))
    after.write_text(json.dumps(REPORT))
    bare.write_text(json.dumps({"fmax": {}}))
    assert main([str(before), str(after), "--top", "1"]) == 0
    assert "| endpoints | 7 | 7 |" in capsys.readouterr().out
    assert main([str(before), str(bare)]) == 2
    assert "no detailed net timings" in capsys.readouterr().err
    assert main([str(before), str(tmp_path / "missing.json")]) == 2
    assert "cannot read" in capsys.readouterr().err
