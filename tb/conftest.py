"""The rotating shares' key, printed at the end of a run that ran any of them (tests marked
`rotating`: the switch cover's rows, and the vector cases, streams, reset points, built-in
constants, pipelined streams, leaf builds and broken proofs of tb/cosim.py's cosim_share), so that a failure can be run again
with the same selection."""

from __future__ import annotations


def pytest_collection_modifyitems(config, items):
    """A rotating test whose group is not on turn in this commit (tb/cosim.py: turn_share) has no
    parameter set, and pytest would report it as skipped ("got empty parameter set"). It is not
    part of this commit's tier: it is deselected, as `-k` would, and `make test-full` runs it.
    An empty parameter set anywhere else still shows as a skip."""
    idle = [
        item
        for item in items
        if item.get_closest_marker("rotating")
        and any(str(mark.kwargs.get("reason", "")).startswith("got empty parameter set") for mark in item.iter_markers("skip"))
    ]
    if idle:
        config.hook.pytest_deselected(items=idle)
        items[:] = [item for item in items if item not in idle]


def pytest_terminal_summary(terminalreporter):
    # Test reports only: a collection's report (--collect-only, a collection error) has no keywords.
    ran = [r for outcome in ("passed", "failed", "error") for r in terminalreporter.stats.get(outcome, ()) if hasattr(r, "keywords")]
    if not any("rotating" in r.keywords for r in ran):
        return
    from cosim import full, rotation_key  # tb/, on the path as the conftest's folder
    from switch_cover import cover, selected_rows

    if any("test_switch_cover_row" in r.nodeid for r in ran):
        rows, how = selected_rows()
        terminalreporter.write_line(f"switch cover: {len(rows)} of {len(cover())} rows ({how})")
    if not full():
        from cosim import TAKING_TURNS, group_on_turn

        turns = ", ".join(f"{pool}: {group_on_turn(pool)}" for pool in TAKING_TURNS)
        terminalreporter.write_line(f"rotating shares (vector cases, streams, resets, built-in constants, pipelined streams, palette and update builds, "
                                    f"broken proofs) drawn from {rotation_key()[:12]}, groups on turn {turns}; "
                                    f"make test-full runs them all")  # fmt: skip
