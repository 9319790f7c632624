"""How a co-simulation starts: what the simulator's Python spends time on before the first edge."""

from __future__ import annotations

from _pytest.pathlib import fnmatch_ex

from evclust.rtl.cosim import BENCHES, rewritten_files


def test_pytest_rewrites_the_asserts_of_the_test_module_alone():
    # cocotb's default ("*.py") rewrote every module the simulator imported, numba's and numpy's
    # included: 12 s more at the start of every co-simulation. fnmatch_ex is the match pytest's
    # import hook makes against COCOTB_REWRITE_ASSERTION_FILES.
    for _, _, module in BENCHES.values():
        pattern = rewritten_files(module)
        own = module.rsplit(".", 1)[-1] + ".py"
        assert fnmatch_ex(pattern, f"/somewhere/{own}")
        for other in ("numba/core/dispatcher.py", "numpy/__init__.py", "evclust/fixed/fixed_model.py", "cocotb/task.py"):
            assert not fnmatch_ex(pattern, f"/site-packages/{other}"), (module, other)
