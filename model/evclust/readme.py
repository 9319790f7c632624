"""The README's tables, copied from the generated documents: each is a table of one document (the
first table after a heading, or after a section's marker), cut to some of its rows and columns, a
column optionally cut to one part of its " / "-separated cells. The README holds each between two
markers, with its source's input stamp (evclust.stamps), so a table is as current as its source:
tests/test_documents.py checks the README against `readme_tables` and the stamps against today's
inputs.

    python -m evclust.readme --write README.md    # after make results, generalize, report or bench
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import NamedTuple

from evclust.documents import write_section
from evclust.errors import EvclustError
from evclust.stamps import BY_NAME, STAMP_RE, read_stamp

REPO = Path(__file__).resolve().parents[2]


class Column(NamedTuple):
    header: str  # the source's header
    title: str | None = None  # the README's (None: the source's)
    part: int | None = None  # keep only this part of a "a / b / c" cell


class Table(NamedTuple):
    name: str  # the README's markers: <!-- readme:NAME:start --> ... <!-- readme:NAME:end -->
    source: str  # the document, relative to the repository
    stamp_of: str  # the name of its source in evclust.stamps.DOCUMENTS, whose stamp it carries
    after: str  # the heading or marker line the table follows (its first table after it)
    columns: tuple[Column, ...] | None = None  # None: every column
    rows: tuple[str, ...] | None = None  # first cells to keep, in the source's order (None: every row)


def _c(header: str, title: str | None = None, part: int | None = None) -> Column:
    return Column(header, title, part)


TABLES = (
    Table("results", "docs/RESULTS.md", "RESULTS", "## Targets"),
    Table("generalization", "docs/GENERALIZATION.md", "GENERALIZATION", "## Overall: what each configuration reports",
          (_c("configuration"), _c("model"), _c("records"), _c("recall"), _c("precision"), _c("tracks/object"), _c("HOTA"),
           _c("IDF1"), _c("position / half-diag."), _c("velocity NRMSE"), _c("palette class"))),
    Table("generalization-clusters", "docs/GENERALIZATION.md", "GENERALIZATION", "## Overall: cluster records",
          (_c("configuration"), _c("model"), _c("records"), _c("recall"), _c("precision"), _c("tracks/object"), _c("HOTA"),
           _c("IDF1"), _c("position / half-diag."), _c("velocity NRMSE"), _c("palette class")), ("default",)),
    Table("budget", "docs/report/REPORT.md", "REPORT", "### traffic",
          (_c("source", "traffic, RMS error against the float model"),
           _c("position: max LSB / RMS / bias / SQNR dB / share", "position (px)", 1),
           _c("size: max LSB / RMS / bias / SQNR dB / share", "size (px)", 1),
           _c("velocity: max LSB / RMS / bias / SQNR dB / share", "velocity (px/frame)", 1),
           _c("colour: max LSB / RMS / bias / SQNR dB / share", "colour", 1)),
          ("**all sources (emulated)**", "**fixed model (bit-exact)**")),
    Table("hardware", "docs/report/REPORT.md", "REPORT", "### Word lengths and N: accuracy against area and cycles",
          (_c("configuration"), _c("cycles/event"), _c("traffic: velocity NRMSE"), _c("traffic: position RMSE (px)"),
           _c("pedestrian: velocity NRMSE"), _c("pedestrian: position RMSE (px)"), _c("LUT (+INV)"), _c("FF"), _c("DSP48E1"))),
    Table("clusterer", "docs/BENCHMARKS.md", "BENCHMARKS:clusterer", "<!-- bench:clusterer:start -->",
          (_c("scene"), _c("parameters"), _c("model"), _c("N"), _c("events"), _c("Mevents/s (median)")), ("traffic",)),
    Table("speed", "docs/BENCHMARKS.md", "BENCHMARKS:simulator", "<!-- bench:simulator:start -->",
          (_c("case"), _c("frames"), _c("size"), _c("events per pixel-frame"), _c("Mpx-frames/s"), _c("Mev/s")),
          ("traffic ideal", "video ideal")),
)  # fmt: skip


def _cells(line: str) -> list[str]:
    return [cell.strip() for cell in line.strip().strip("|").split("|")]


def _row(cells) -> str:
    return "| " + " | ".join(cells) + " |"


def source_table(text: str, after: str, where: str) -> tuple[list[str], str, list[list[str]]]:
    """The first Markdown table after the line `after`: its header, its alignment row, its rows."""
    lines = text.split("\n")
    try:
        start = next(i for i, line in enumerate(lines) if line.strip() == after)
    except StopIteration:
        raise EvclustError(f"{where}: no line {after!r}") from None
    try:
        top = next(i for i in range(start + 1, len(lines)) if lines[i].startswith("|"))
    except StopIteration:
        raise EvclustError(f"{where}: no table after {after!r}") from None
    end = next((i for i in range(top, len(lines)) if not lines[i].startswith("|")), len(lines))
    return _cells(lines[top]), lines[top + 1], [_cells(line) for line in lines[top + 2 : end]]


def extract(table: Table, text: str) -> str:
    """The README's table: the source's table cut to the chosen rows and columns."""
    where = f"{table.source} (README table {table.name})"
    header, align, rows = source_table(text, table.after, where)
    columns = table.columns or tuple(Column(h) for h in header)
    missing = [c.header for c in columns if c.header not in header]
    if missing:
        raise EvclustError(f"{where}: no column {missing[0]!r}")
    if table.rows is not None:
        absent = [r for r in table.rows if r not in {row[0] for row in rows}]
        if absent:
            raise EvclustError(f"{where}: no row {absent[0]!r}")
        rows = [row for row in rows if row[0] in table.rows]
    aligns = _cells(align)
    index = [header.index(c.header) for c in columns]

    def cell(row, c, i):
        value = row[i] if i < len(row) else ""
        return value.split(" / ")[c.part] if c.part is not None and " / " in value else value

    out = [_row(c.title or c.header for c in columns), "|" + "|".join(aligns[i] for i in index) + "|"]
    out += [_row(cell(row, c, i) for c, i in zip(columns, index, strict=True)) for row in rows]
    return "\n".join(out)


def markers(table: Table) -> tuple[str, str]:
    return f"<!-- readme:{table.name}:start -->", f"<!-- readme:{table.name}:end -->"


def readme_section(table: Table, root: Path = REPO) -> str:
    """The README's section for `table`, markers and its source's stamp line included."""
    text = (root / table.source).read_text()
    stamp = read_stamp(BY_NAME[table.stamp_of], text)
    start, end = markers(table)
    line = "<!-- inputs: " + " ".join(f"{k}={v}" for k, v in stamp.items()) + " -->" if stamp else None
    assert line is None or STAMP_RE.fullmatch(line)
    return "\n".join([start, *([line] if line else []), extract(table, text), end])


def write(readme: Path, root: Path = REPO) -> None:
    for table in TABLES:
        start, end = markers(table)
        write_section(readme, readme_section(table, root) + "\n", start, end, append=False)


def stale(readme: Path, root: Path = REPO) -> list[str]:
    """README tables that differ from what their sources now say (empty: all current)."""
    text = Path(readme).read_text()
    out = []
    for table in TABLES:
        start, end = markers(table)
        if start not in text or end not in text:
            out.append(f"{readme}: no README table {table.name} ({start})")
            continue
        now = start + text.split(start, 1)[1].split(end, 1)[0] + end
        if now != readme_section(table, root):
            out.append(
                f"{readme}: the {table.name} table is not what {table.source} says now: run `python -m evclust.readme --write README.md`"
            )
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m evclust.readme", description=__doc__.split("\n\n")[0])
    ap.add_argument("--write", metavar="README.md", type=Path, help="rewrite the README's tables from the documents")
    args = ap.parse_args(argv)
    try:
        if args.write:
            write(args.write)
        for line in stale(args.write or REPO / "README.md") or ["the README's tables are current"]:
            print(line)
    except EvclustError as exc:
        print(f"evclust.readme: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
