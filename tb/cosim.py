"""The testbench's configurations. Building and running live in `evclust.rtl.cosim`, which the
report and the benches share; this module picks the simulators and the model-in-the-loop
parameter sets the tests run."""

from __future__ import annotations

import datetime
import hashlib
import os
import subprocess
from pathlib import Path

import numpy as np

from evclust.rtl.cosim import SIMULATORS, build, run, use_simulator  # noqa: F401  (the testbench's API)
from evclust.rtl.sources import RTL_DIR as RTL  # noqa: F401
from evclust.rtl.configurations import (  # noqa: F401  (the testbenches' API)
    CONFIGURATIONS, FORMAT_VARIANTS, OTHER_CONFIGURATIONS, configuration_params, random_config,
)  # fmt: skip


# What `make test` runs under each simulator, where it does not run both; `make test-full` (or
# `SIM=...`) runs both. docs/RTL.md, "What make test shares", has the times behind each choice.
# - TIMING_SIMULATORS: the checks of the core's timing and handshakes (back-pressure, sparse input,
#   cycles per sweep and per merge, registers between streams, the pipelined core through gaps and
#   stalls), the scoreboard's message, the switch-cover rows, the paper's configuration and a
#   team's own events, which Icarus took 25 to 85 s each to repeat.
# - LEAF_SIMULATORS: the leaf modules' benches and the AXI4-Stream wrapper's, 160 s in all under
#   Icarus and 306 s under Verilator, its builds included (a fresh CI run); the golden vectors, a
#   random stream, a reset and the built-in constants run the core under both in make test, and
#   Verilator lints every module.
# - PALETTE_SIMULATORS: the palette's bench, whose sweeps Icarus took 46 to 112 s over against
#   Verilator's 23 to 39 s with its build.
TIMING_SIMULATORS = ("verilator",)
LEAF_SIMULATORS = ("icarus",)
PALETTE_SIMULATORS = ("verilator",)


def selected_simulators(in_make_test: tuple[str, ...] = SIMULATORS) -> tuple[str, ...]:
    """The simulators a test runs under: `in_make_test` in `make test`, both in `make test-full`,
    the one `SIM` names (`make cosim SIM=...`) if it is set."""
    sim = os.environ.get("SIM")
    if not sim:
        return SIMULATORS if full() else tuple(s for s in SIMULATORS if s in in_make_test)
    if sim not in SIMULATORS:
        raise SystemExit(f"SIM={sim}: expected one of {', '.join(SIMULATORS)}")
    return (sim,)


def full() -> bool:
    """EVCLUST_COVER=all (`make test-full`, `make cosim-full`): every switch-cover row, vector case,
    stream, reset point and broken proof under both simulators, and the longer runs."""
    return os.environ.get("EVCLUST_COVER", "").lower() == "all"


def rotation_key() -> str:
    """What the rotating subsets follow: the checked-out commit, or today's date outside a git checkout."""
    try:
        return subprocess.run(["git", "rev-parse", "HEAD"], cwd=Path(__file__).parent, capture_output=True, text=True,
                              check=True, timeout=10).stdout.strip()  # fmt: skip
    except (OSError, subprocess.SubprocessError):
        return datetime.date.today().isoformat()


def rotating_subset(count: int, size: int, salt: str) -> list[int]:
    """`size` of the indices 0..count-1, sorted, drawn from the commit hash (and `salt`, so that two
    subsets of one commit are drawn apart): the same in every pytest-xdist worker, another set at
    the next commit, so that successive commits cover the whole list."""
    key = rotation_key() + (f":{salt}" if salt else "")
    seed = int.from_bytes(hashlib.sha256(key.encode()).digest()[:8], "little")
    return sorted(np.random.default_rng(seed).choice(count, min(size, count), replace=False).tolist())


# Icarus is far slower than Verilator on the core (bench/rtl: 348 against 26,253 events/s). In
# `make test` it runs each model-in-the-loop stream on a sensor that reports within
# ICARUS_EVENTS events, and no more of them; streams on the traffic sensor, which report nothing
# in their first 5,000 events, run under Verilator there. `make test-full` runs everything whole
# under both (docs/RTL.md, "What make test shares").
ICARUS_EVENTS = 1500


def short_icarus(sim: str) -> bool:
    """Whether this run is Icarus in `make test`, which takes the short streams above."""
    return sim == "icarus" and not full()


def cosim_share(items, size: int, salt: str, sim: str = "") -> list:
    """What `make test` runs of `items` under simulator `sim`: a rotating subset of `size`, drawn
    apart for each simulator (so that one commit covers more of the list); all of them under
    `make test-full` (EVCLUST_COVER=all). Tests that take a share carry the `rotating` marker."""
    items = list(items)
    return items if full() else [items[i] for i in rotating_subset(len(items), size, f"{salt}:{sim}" if sim else salt)]


# Rotating groups take turns in `make test`: in each pool one group per commit (drawn from the
# commit hash) takes its share, the others none, so that a commit pays for one long run a pool
# rather than one a group (their draws cost 9 to 123 s each; docs/RTL.md, "What make test
# shares"). The pools: the core's groups under each simulator, and the switch cover's row with
# the broken proof. The leaf builds keep their own draws: they are their benches' only runs.
TAKING_TURNS = {
    "icarus": ("vectors", "built-in", "streams", "reset"),
    "verilator": ("vectors", "built-in", "reset", "pipelined"),  # its streams are pinned, not drawn
    "checks": ("switch-cover", "breakages"),
}


def group_on_turn(pool: str) -> str:
    """The group of TAKING_TURNS[pool] whose share this commit runs."""
    groups = TAKING_TURNS[pool]
    return groups[rotating_subset(len(groups), 1, f"turn:{pool}")[0]]


def turn_share(items, size: int, group: str, pool: str) -> list:
    """`cosim_share` for a group of TAKING_TURNS[pool] (a simulator's pool draws apart for that
    simulator): its share when the group is on turn (under `make test-full`, everything), else
    nothing."""
    if not full() and group_on_turn(pool) != group:
        return []
    return cosim_share(items, size, group, pool if pool in SIMULATORS else "")


# The builds the step-3 leaf benches (tb/evclust_update, tb/evclust_commit) run: the traffic
# preset and the defaults on a suite-sized sensor, N = 4 (the modules are per slot).
LEAF_BUILDS = {"traffic": (480, 270, 50000.0), "defaults": (160, 120, 16666.0)}


def leaf_model(name: str):
    """The fixed model of a LEAF_BUILDS build: its formats, constants and globals are what the
    leaf benches drive the module with and compare against."""
    from evclust.clusterer import ClustererParams, load_params
    from evclust.fixed.model import FixedClusterer

    width, height, t_frame = LEAF_BUILDS[name]
    params = ClustererParams(n_clusters=4) if name == "defaults" else load_params(name)[0].model_copy(update={"n_clusters": 4})
    return FixedClusterer(params, width, height, t_frame)


def header_width(header: str, name: str) -> int:
    """A `localparam integer` of an evclust_params.vh: what a module's ports are sized by."""
    import re

    return int(re.search(rf"localparam integer {name} = (\d+);", header).group(1))


async def pipeline_edge(dut, advance: int) -> None:
    """One clock edge of a leaf with a pipeline register (`clk`, `advance`), driven by hand: the
    register takes its inputs only if `advance` is high."""
    from cocotb.triggers import Timer

    dut.advance.value = advance
    dut.clk.value = 1
    await Timer(1, unit="ns")
    dut.clk.value = 0
    dut.advance.value = 0
    await Timer(1, unit="ns")


async def checked_vectors(dut, body) -> None:
    """A unit testbench's cocotb side: `await body(dut, config)` gives (error or None, cases
    checked); both go where the pytest side reads them (config["out"]), and an error fails the test."""
    import json
    from pathlib import Path

    config = json.loads(os.environ["EVCLUST_TB"])
    try:
        error, checked = await body(dut, config)
    except Exception as exc:
        error, checked = f"{type(exc).__name__}: {exc}", 0
    Path(config["out"]).write_text(json.dumps({"checked": checked, "error": error}))
    assert error is None, error
