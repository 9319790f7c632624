"""Generated documents stay current: each records, in one comment line, fingerprints of the inputs
it was made from (evclust.stamps: the formats, the RTL, the fixed and the float model by what they
do), and fails here, naming the input and the make target, when one has changed since."""

from __future__ import annotations

import pytest

from evclust import stamps
from evclust.documents import write_section


@pytest.mark.parametrize("doc", stamps.DOCUMENTS, ids=lambda d: d.name)
def test_the_document_is_made_from_the_current_inputs(doc):
    problems = stamps.check([doc])
    assert not problems, problems[0]


def test_the_fingerprints_are_twelve_hex_digits_and_repeat():
    first = stamps.fingerprints()
    assert list(first) == list(stamps.INPUTS)
    assert all(len(v) == stamps.DIGITS and int(v, 16) >= 0 for v in first.values())
    assert stamps.float_fingerprint()[: stamps.DIGITS] == first["float"]  # the probe is deterministic


def test_a_stale_or_unstamped_document_fails_with_its_input_and_target(tmp_path):
    whole = stamps.Document("W", "w.md", None, None, ("formats", "float"), "make w")
    part = stamps.Document("S", "s.md", "<!-- s:start -->", "<!-- s:end -->", ("rtl",), "make s")
    now = {"formats": "a" * 12, "rtl": "b" * 12, "fixed": "c" * 12, "float": "d" * 12}
    (tmp_path / "w.md").write_text(stamps.stamped(whole, "# W\n\ntext\n", stamps.stamp_line(whole, now)))
    write_section(tmp_path / "s.md", "<!-- s:start -->\ntable\n<!-- s:end -->\n", part.start, part.end, stamp=stamps.stamp_line(part, now))
    assert stamps.check([whole, part], now, tmp_path) == []
    assert (tmp_path / "w.md").read_text().startswith("<!-- inputs: formats=aaaaaaaaaaaa float=dddddddddddd -->\n# W\n")

    later = now | {"float": "e" * 12}
    assert stamps.check([whole, part], later, tmp_path) == ["w.md (W): made from other float than now; regenerate it with make w"]

    # a regenerated section replaces its stamp, not adds a second one
    write_section(tmp_path / "s.md", "<!-- s:start -->\ntable 2\n<!-- s:end -->\n", part.start, part.end,
                  stamp=stamps.stamp_line(part, later | {"rtl": "f" * 12}))  # fmt: skip
    assert (tmp_path / "s.md").read_text().count("<!-- inputs:") == 1
    assert stamps.check([part], now, tmp_path) == ["s.md (S): made from other rtl than now; regenerate it with make s"]

    (tmp_path / "w.md").write_text("# W\n\nedited by hand\n")
    assert stamps.check([whole], now, tmp_path) == ["w.md (W): no input stamp; regenerate it with make w"]


def test_restamping_keeps_the_document_and_changes_only_its_stamp(tmp_path):
    part = stamps.Document("S", "s.md", "<!-- s:start -->", "<!-- s:end -->", ("rtl",), "make s")
    (tmp_path / "s.md").write_text("# Top\n\n<!-- s:start -->\n## S\n\nrows\n<!-- s:end -->\n\nafter\n")
    stamps.stamp_document(part, {"rtl": "1" * 12}, tmp_path)
    stamps.stamp_document(part, {"rtl": "2" * 12}, tmp_path)
    want = "# Top\n\n<!-- s:start -->\n<!-- inputs: rtl=222222222222 -->\n## S\n\nrows\n<!-- s:end -->\n\nafter\n"
    assert (tmp_path / "s.md").read_text() == want
