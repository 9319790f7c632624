"""The FuseSoC description (evclust.core) lists the Verilog that the tools read: a source the
co-simulation and synthesis read (evclust.rtl.sources) but the core file leaves out would build
for us and fail for a FuseSoC user."""

from __future__ import annotations

import re

from evclust.rtl.sources import REPO, RTL_INCLUDES, RTL_SOURCES

HEADER = "evclust_params.vh"


def fileset(name: str, text: str | None = None) -> list[str]:
    """The files of one fileset of evclust.core (or of `text`, a core file's), by name, in order."""
    text = (REPO / "evclust.core").read_text() if text is None else text
    body = re.search(rf"^  {name}:\n    files:\n((?:      - .*\n)+)", text, re.MULTILINE)
    assert body, f"evclust.core has no fileset {name}"
    return [re.match(r"      - ([^:\s]+)", line).group(1) for line in body.group(1).splitlines()]


def unlisted(listed: list[str]) -> tuple[set[str], set[str]]:
    """(what the tools read but the core file leaves out, what it lists that they do not read)."""
    read = {f"rtl/{name}" for name in (*RTL_SOURCES, *RTL_INCLUDES, HEADER)}
    return read - set(listed), set(listed) - read


def test_the_core_file_lists_every_source_and_include_the_tools_read():
    listed = fileset("rtl")
    assert unlisted(listed) == (set(), set())
    assert len(listed) == len(set(listed))


def test_each_listed_file_exists_and_the_waivers_are_listed():
    for path in (*fileset("rtl"), *fileset("lint_waivers")):
        assert (REPO / path).is_file(), path
    assert fileset("lint_waivers") == ["rtl/evclust_lint.vlt"]


def test_a_source_left_out_of_the_core_file_is_named():
    """The check names a source a core file leaves out (here the seek window)."""
    text = (REPO / "evclust.core").read_text().replace("      - rtl/evclust_seek_window.v\n", "")
    assert unlisted(fileset("rtl", text)) == ({"rtl/evclust_seek_window.v"}, set())
