"""The RTL as the third clusterer: co-simulation of rtl/ against the fixed model (cocotb under
Icarus or Verilator) and its synthesis (Yosys), each for the header the formats table makes.
The Verilog lives in the repository beside this package (`rtl/`, `tb/`), not in the wheel."""

from evclust.rtl.sources import REPO, RTL_DIR, TB_DIR, require_repository

__all__ = ["REPO", "RTL_DIR", "TB_DIR", "require_repository"]
