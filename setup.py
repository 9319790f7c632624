"""The wheel's Verilog: a build_py step that copies the repository's rtl/ and the co-simulation's
testbench top (tb/evclust_core/evclust_tb.v) into evclust/rtl/hdl/ of the build, keeping their
layout, so an installed wheel co-simulates (evclust.rtl.sources finds the copy first).

Everything else is in pyproject.toml. An editable install copies nothing: it reads the repository's
rtl/ itself, so edits there are seen without reinstalling (docs/DESIGN.md, "The wheel carries the RTL").
"""

from __future__ import annotations

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
PACKAGED = ("evclust", "rtl", "hdl")  # the copy's folder inside the package
# (folder of the repository, file patterns): rtl/ whole (sources, includes, the lint configuration,
# the register map's C header) and the testbench top the cocotb harness drives.
HDL_FILES = (("rtl", ("*.v", "*.vh", "*.vlt", "*.h")), ("tb/evclust_core", ("evclust_tb.v",)))


def hdl_files() -> list[Path]:
    """The files to package, relative to the repository; an error when rtl/ is not beside setup.py."""
    files = [path.relative_to(ROOT) for folder, patterns in HDL_FILES for pattern in patterns for path in sorted((ROOT / folder).glob(pattern))]  # fmt: skip
    for needed in ("rtl/evclust_core.v", "tb/evclust_core/evclust_tb.v"):
        if Path(needed) not in files:
            raise SystemExit(f"setup.py: {ROOT / needed} is missing: build the wheel from a clone of the evclust repository or its sdist")
    return files


class BuildPyWithHdl(build_py):
    """build_py, then the Verilog into build_lib/evclust/rtl/hdl/ (a wheel or a plain install)."""

    def run(self):
        super().run()
        if self.editable_mode:  # the editable install reads the repository's rtl/
            return
        target = Path(self.build_lib, *PACKAGED)
        shutil.rmtree(target, ignore_errors=True)  # no stale file of an earlier build
        for path in hdl_files():
            (target / path).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(ROOT / path, target / path)

    def get_outputs(self, include_bytecode=True):
        outputs = super().get_outputs(include_bytecode)
        if self.editable_mode:
            return outputs
        return [*outputs, *(str(Path(self.build_lib, *PACKAGED, path)) for path in hdl_files())]


setup(cmdclass={"build_py": BuildPyWithHdl})
