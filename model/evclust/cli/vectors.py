"""evclust vectors [-o vectors] [--check]"""

from __future__ import annotations

from pathlib import Path

from evclust.errors import EvclustError
from evclust.vectors import CASES, check_vectors, write_vectors


def add_parser(sub) -> None:
    p = sub.add_parser(
        "vectors",
        help="write the golden vectors the RTL is checked against",
        description=(
            "Run the fixed-point model on every vector case (clips of the built-in scenes and directed hard "
            f"cases: {', '.join(CASES)}) and write vectors/<case>/ with manifest.json, events.hex, expected.hex "
            "and trace.hex (vectors/README.md documents the formats). Regeneration is bit-identical; --check "
            "only compares."
        ),
    )
    p.add_argument("-o", "--output", default="vectors", metavar="DIR", help="folder of the cases (default: vectors)")
    p.add_argument("--check", action="store_true", help="do not write: fail if a committed case differs from the model")
    p.set_defaults(run=run)


def run(args) -> int:
    root = Path(args.output)
    if args.check:
        stale = check_vectors(root)
        if stale:
            raise EvclustError(f"{root}: {len(stale)} stale vector file(s), e.g. {stale[0]}: run `make vectors`")
        print(f"{root}: {len(CASES)} cases up to date")
        return 0
    manifests = write_vectors(root)
    events = sum(m["counts"]["events"] for m in manifests.values())
    records = sum(m["counts"]["records"] for m in manifests.values())
    print(f"{root}: {len(manifests)} cases, {events} events, {records} expected records")
    return 0
