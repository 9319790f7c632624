"""`make lint`: the RTL under `verilator --lint-only -Wall`, with the waivers of
rtl/evclust_lint.vlt, for a header (default: the committed rtl/evclust_params.vh)."""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from cosim import RTL, use_simulator

from evclust.rtl.sources import RTL_INCLUDES, RTL_SOURCES


def lint(header: str | None = None, top: str = "evclust_axis") -> str:
    """Verilator's complaints ('' when clean) on `top` and everything below it (the integration
    top by default: the register file and the core)."""
    use_simulator("verilator")
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp)
        for name in (*RTL_SOURCES, *RTL_INCLUDES, "evclust_lint.vlt", "evclust_params.vh"):
            shutil.copy(RTL / name, src / name)
        if header is not None:
            (src / "evclust_params.vh").write_text(header)
        done = subprocess.run(
            ["verilator", "--lint-only", "-Wall", f"-I{src}", "--top-module", top, "evclust_lint.vlt", *RTL_SOURCES],
            cwd=src, capture_output=True, text=True,
        )  # fmt: skip
        return (done.stdout + done.stderr).strip() if done.returncode or done.stderr.strip() else ""


if __name__ == "__main__":
    complaints = lint()
    print(complaints or "lint: clean (verilator --lint-only -Wall, rtl/evclust_lint.vlt waivers)")
    sys.exit(1 if complaints else 0)
