"""The RTL as the third clusterer: co-simulation of rtl/ against the fixed model (cocotb under
Icarus or Verilator) and its synthesis (Yosys), each for the header the formats table makes.
The Verilog is the wheel's copy (evclust/rtl/hdl/) or, in an editable install, the repository's
`rtl/` and `tb/` (evclust.rtl.sources)."""

from evclust.rtl.sources import REPO, RTL_DIR, TB_DIR, require_repository, require_rtl

__all__ = ["REPO", "RTL_DIR", "TB_DIR", "require_repository", "require_rtl"]
