"""The switch cover's selection and the Icarus subsets' key, printed at the end of a run that
co-simulated any of them, so that a failure can be run again with the same rows and cases
(tb/switch_cover.py, tb/cosim.py)."""

from __future__ import annotations


def pytest_terminal_summary(terminalreporter):
    ran = [r for outcome in ("passed", "failed", "error") for r in terminalreporter.stats.get(outcome, ())
           if "test_switch_cover_row" in getattr(r, "nodeid", "")]  # fmt: skip
    if ran:
        import sys
        from pathlib import Path

        sys.path.insert(0, str(Path(__file__).parent))
        from switch_cover import cover, selected_rows

        rows, how = selected_rows()
        terminalreporter.write_line(f"switch cover: {len(rows)} of {len(cover())} rows ({how})")
    shared = ("test_vector_case_replays", "test_random_streams", "test_a_reset_in_the_middle", "test_the_core_with_its_constants_built_in")
    if any("[icarus" in r.nodeid and any(name in r.nodeid for name in shared)
           for outcome in ("passed", "failed", "error") for r in terminalreporter.stats.get(outcome, ()) if hasattr(r, "nodeid")):  # fmt: skip
        import sys
        from pathlib import Path

        sys.path.insert(0, str(Path(__file__).parent))
        from cosim import full, rotation_key

        if not full():
            terminalreporter.write_line(f"icarus: the subsets of vector cases and streams drawn from {rotation_key()[:12]} "
                                        "(make cosim-full runs them all)")  # fmt: skip
