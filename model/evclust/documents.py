"""Generated documents: each generator owns a section of a Markdown file between two marker
comments and rewrites only that section, so several generators can share one file
(docs/BENCHMARKS.md, the datasheet in docs/RTL.md, the coverage table in docs/VERIFICATION.md).
A section's first line after its start marker is its input stamp (evclust.stamps makes it), which
the generator passes here: tests/test_documents.py fails when those inputs have changed since.
Generators may run at once (`python -m evclust.stamps --regenerate --jobs 2`): a section is read,
replaced and written under the file's lock, so that two writers of one file lose nothing."""

from __future__ import annotations

import fcntl
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
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "a+", encoding="utf-8") as handle:  # created if missing; the lock is the file's own
        fcntl.flock(handle, fcntl.LOCK_EX)
        handle.seek(0)
        text = handle.read()
        if not text:
            text = NEW_BENCHMARKS + section
        elif start in text and end in text:
            head, rest = text.split(start, 1)
            tail = rest.split(end, 1)[1].lstrip("\n")
            text = head + section + ("\n" + tail if tail else "")
        elif append:
            text = text.rstrip("\n") + "\n\n" + section
        else:
            raise EvclustError(f"{path}: no {start} ... {end} section to replace")
        handle.truncate(0)  # "a+" writes at the end, which is now the start
        handle.write(text)
