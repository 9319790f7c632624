"""The formats table is the single source: each of its rows is read by the RTL (through its
generated STEM_W / STEM_FRAC) or by the fixed model, so no row documents a width nothing uses."""

import re

from evclust.clusterer import ClustererParams
from evclust.fixed.formats import build_formats
from evclust.rtl.sources import REPO, RTL_DIR, RTL_SOURCES


def _readers():
    rtl = "".join((RTL_DIR / name).read_text() for name in RTL_SOURCES)
    model = "".join((REPO / "model" / "evclust" / "fixed" / name).read_text() for name in ("fixed_model.py", "model.py"))
    return rtl, model


def test_every_format_row_is_read_by_the_rtl_or_the_fixed_model():
    table = build_formats(ClustererParams(), 480, 270, 50000.0)
    rtl, model = _readers()
    unread = [name for name, fmt in table.formats.items() if name not in table.constants
              and not re.search(rf"\b{name.upper()}_(W|FRAC)\b", rtl) and f'"{name}"' not in model]  # fmt: skip
    assert unread == []


def test_the_rtl_names_no_mode_code_or_fraction_by_a_literal():
    # The γ mode codes and the fractions the issue named come from the header, not literals.
    rtl, _ = _readers()
    assert not re.search(r"GAMMA_MODE\s*[!=]=\s*\d", rtl)
    assert "COS_SQ_F = 16" not in rtl and "(FW - 20)" not in rtl and "<<< 16)" not in rtl
