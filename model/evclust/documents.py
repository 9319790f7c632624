"""Generated documents: each generator owns a section of a Markdown file between two marker
comments and rewrites only that section, so several generators can share one file
(docs/BENCHMARKS.md, the datasheet in docs/RTL.md, the coverage table in docs/VERIFICATION.md).
A section's first line after its start marker is its input stamp (evclust.stamps makes it), which
the generator passes here: tests/test_documents.py fails when those inputs have changed since."""

from __future__ import annotations

from pathlib import Path

from evclust.errors import EvclustError

NEW_BENCHMARKS = "# Benchmarks\n\nMeasured by `make bench`; each section is rewritten by the script that owns it.\n\n"


def write_section(path: Path, section: str, start: str, end: str, append: bool = True, stamp: str | None = None) -> None:
    """Replace the part of `path` from the marker `start` to the marker `end` with `section`
    (which begins with `start` and ends with `end`), `stamp` (a one-line comment: the inputs it
    was made from) on the line after `start`. Where the file has no such section it is appended
    (`append`), or the call fails with a one-line reason; a missing file is created."""
    path = Path(path)
    if stamp is not None:
        if not section.startswith(start) or "\n" in stamp:
            raise EvclustError(f"{path}: a stamped section begins with {start} and its stamp is one line")
        body = section[len(start) :].lstrip("\n")
        section = f"{start}\n{stamp}\n{body}"
    if path.exists():
        text = path.read_text()
        if start in text and end in text:
            head, rest = text.split(start, 1)
            tail = rest.split(end, 1)[1].lstrip("\n")
            text = head + section + ("\n" + tail if tail else "")
        elif append:
            text = text.rstrip("\n") + "\n\n" + section
        else:
            raise EvclustError(f"{path}: no {start} ... {end} section to replace")
    else:
        text = NEW_BENCHMARKS + section
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
