"""Every file the formats table drives, generated in one place: the RTL's parameter header, the
modules' enumerations and the register map's files (SystemRDL, and from it with PeakRDL the C
header, the Markdown map and IP-XACT), each under its path in the repository, for the reference
configuration the committed files are made from (`make params`, `evclust formats --generate`).
tests/fixed/test_generated_files.py checks that each committed file is what this writes now.

This module sits above the table (formats.py), the register map (registers.py, rdl.py), the
stream layouts (layouts.py) and the enumerations (enums.py); none of them imports it."""

from __future__ import annotations

from pathlib import Path

from evclust.errors import atomic_output
from evclust.fixed import enums, rdl
from evclust.fixed.formats import FormatTable
from evclust.fixed.header import verilog_header

# The reference configuration of the committed RTL header: preset, sensor width and height, and the
# frame period (µs) when the preset has none.
REFERENCE = ("traffic", 480, 270, 50000.0)
# Where each of the register map's files is committed, by rdl.generated's kind.
REGISTER_MAP_FILES = {"rdl": "rtl/evclust_regs.rdl", "c_header": "rtl/evclust_regs.h", "markdown": "docs/REGISTERS.md",
                      "ipxact": "rtl/evclust_regs.xml"}  # fmt: skip
HEADER = "rtl/evclust_params.vh"


def reference_table() -> FormatTable:
    from evclust.clusterer import load_params
    from evclust.fixed import build_formats

    params, _ = load_params(REFERENCE[0])
    return build_formats(params, REFERENCE[1], REFERENCE[2], params.t_frame_us or REFERENCE[3])


def generated(table: FormatTable) -> dict[str, str]:
    """Each generated file's path in the repository -> its text for `table`."""
    texts = {HEADER: verilog_header(table)}
    texts |= {f"rtl/{enums.header_name(module)}": enums.header(module) for module in enums.ENUMS}
    texts |= {REGISTER_MAP_FILES[kind]: text for kind, text in rdl.generated(table).items()}
    return texts


def write(root: str | Path, table: FormatTable | None = None) -> list[Path]:
    """Write every generated file under `root` (a repository's top); the paths written."""
    written = []
    for relative, text in generated(table or reference_table()).items():
        path = Path(root) / relative
        with atomic_output(path) as tmp:
            tmp.write_text(text)
        written.append(path)
    return written
