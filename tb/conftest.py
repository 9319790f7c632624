"""The switch cover's selection, printed at the end of a run that co-simulated any of it, so that a
failure can be run again with the same rows (tb/switch_cover.py)."""

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
