"""A wheel that works (issue 25): `pip install .` carries the RTL, and the installed package
co-simulates it from any folder: `evclust track --model rtl` and `evclust vectors --replay`.

The wheel is built from a copy of the checkout (setuptools' build/lib in the checkout may hold an
earlier build's files, which would hide a wheel that lost its RTL) and installed with --no-deps
into a venv under build/wheel-test/. Its dependencies are this interpreter's: a .pth file in the
venv's site-packages names this interpreter's site-packages folder. A path line in a .pth does not
process the .pth files in that folder, so the editable install's (which points at the checkout)
stays off: the test checks that `evclust` is imported from the venv.

Cost: building the wheel takes about 2 s (with this interpreter's setuptools if it is 77 or later,
else pip's isolated build, which fetches it from PyPI). The venv is
kept while the wheel's files are the same (numba's cache lives in it), and the co-simulation's
build in build/wheel-test/cache/evclust/ (the installed package's default, $XDG_CACHE_HOME/evclust)
while the RTL and its header are the same, so a warm run is the models' and the simulator's run
time (about 17 s). A new wheel adds numba's compilation in the fresh venv (about 30 s), and a fresh
clone one Verilator build too (about 50 s without ccache; the Verilator runtime's objects come
from the checkout's build/ccache when the other co-simulations have put them there).
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest
from filelock import FileLock

from evclust.cli import main

REPO = Path(__file__).resolve().parents[2]
WORK = REPO / "build" / "wheel-test"
VENV = WORK / "venv"
# The checkout's top-level folders the wheel does not need (the copy stays small); setup.py and
# MANIFEST.in name what it does need from rtl/ and tb/.
NOT_COPIED = {".git", ".venv", "build", "docs", "vectors", "bench", "synth", "formal", "tests"}
EXPECTED_HDL = sorted(
    [f"rtl/{p.name}" for p in (REPO / "rtl").iterdir() if p.suffix in (".v", ".vh", ".vlt", ".h")] + ["tb/evclust_core/evclust_tb.v"]
)


def _ignore(folder: str, names: list[str]) -> list[str]:
    top = Path(folder) == REPO
    return [n for n in names if (top and n in NOT_COPIED) or n == "__pycache__" or n.endswith(".egg-info") or n == "hdl"]


def _purelib(python: Path | str) -> Path:
    code = "import sysconfig; print(sysconfig.get_paths()['purelib'])"
    return Path(subprocess.run([str(python), "-c", code], capture_output=True, text=True, check=True, env=_env()).stdout.strip())


def _setuptools_major() -> int:
    try:
        return int(importlib.metadata.version("setuptools").split(".")[0])
    except importlib.metadata.PackageNotFoundError:
        return 0


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    """The wheel, built from a copy of the checkout."""
    tmp = tmp_path_factory.mktemp("wheel")
    shutil.copytree(REPO, tmp / "src", ignore=_ignore)
    # This interpreter's setuptools if it is recent enough (offline), else pip's isolated build (fetches it from PyPI).
    local = ["--no-build-isolation"] if _setuptools_major() >= 77 else []
    build = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", *local, "-w", str(tmp / "dist"), str(tmp / "src")],
                           capture_output=True, text=True, timeout=600, env=_env())  # fmt: skip
    assert build.returncode == 0, (
        f"pip wheel failed{'' if local else ' (its isolated build fetches setuptools from PyPI)'}:\n{build.stderr}"
    )
    (path,) = (tmp / "dist").glob("evclust-*.whl")
    return path


@pytest.fixture(scope="module")
def venv(wheel) -> Path:
    """A venv with only the wheel installed (kept while the wheel's files are the same)."""
    with zipfile.ZipFile(wheel) as z:
        record = next(n for n in z.namelist() if n.endswith(".dist-info/RECORD"))
        digest = hashlib.sha256(z.read(record)).hexdigest()  # every file's hash
    stamp = VENV / "evclust-wheel.sha256"
    WORK.mkdir(parents=True, exist_ok=True)
    with FileLock(WORK / "venv.lock"):
        if not (stamp.exists() and stamp.read_text() == digest):
            shutil.rmtree(VENV, ignore_errors=True)
            subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(VENV)], check=True)
            # The wheel first, with nothing else in sight (pip would take the editable install
            # beside the dependencies for this one), then the dependencies' folder.
            pip = [sys.executable, "-m", "pip", "--python", str(VENV / "bin" / "python")]
            subprocess.run(
                [*pip, "install", "-q", "--no-deps", "--no-index", str(wheel)], check=True, capture_output=True, text=True, env=_env()
            )
            site = _purelib(VENV / "bin" / "python")
            assert (site / "evclust" / "__init__.py").exists(), f"pip installed no evclust into {site}"
            deps = dict.fromkeys(sysconfig.get_paths()[k] for k in ("purelib", "platlib"))  # this interpreter's
            (site / "_evclust_test_dependencies.pth").write_text("".join(f"{p}\n" for p in deps))
            stamp.write_text(digest)
    return VENV


@pytest.fixture(scope="module")
def outside(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("outside")
    assert not folder.resolve().is_relative_to(REPO), "the commands must run outside the checkout"
    return folder


def _env() -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "EVCLUST_BUILD_DIR") and not k.startswith("NUMBA_")}
    env["XDG_CACHE_HOME"] = str(WORK / "cache")  # the installed package's builds: $XDG_CACHE_HOME/evclust
    env.setdefault("CCACHE_DIR", str(REPO / "build" / "ccache"))  # the Verilator runtime's objects, as the checkout's builds
    return env


def _run(venv: Path, cwd: Path, *argv: str) -> str:
    run = subprocess.run([str(venv / "bin" / "evclust"), *argv], cwd=cwd, env=_env(), capture_output=True, text=True, timeout=900)
    assert run.returncode == 0, f"evclust {' '.join(argv)}: exit {run.returncode}\n{run.stderr.strip()}"
    return run.stdout


def test_the_wheel_carries_the_rtl_and_the_testbench_top(wheel):
    with zipfile.ZipFile(wheel) as z:
        hdl = sorted(n.removeprefix("evclust/rtl/hdl/") for n in z.namelist() if n.startswith("evclust/rtl/hdl/"))
        assert "evclust/rtl/harness.py" in z.namelist()
    assert hdl == EXPECTED_HDL, "the wheel's evclust/rtl/hdl/ is not rtl/ and tb/evclust_core/evclust_tb.v (setup.py)"
    for name in hdl:
        with zipfile.ZipFile(wheel) as z:
            assert z.read(f"evclust/rtl/hdl/{name}") == (REPO / name).read_bytes(), name


def test_the_installed_wheel_runs_the_rtl_from_outside_the_checkout(venv, outside):
    site = _purelib(venv / "bin" / "python")
    probe = "import evclust; from evclust.paths import BUILD; from evclust.rtl.sources import RTL_DIR, TB_DIR as TB; print(evclust.__file__, RTL_DIR, TB, BUILD, sep=chr(10))"
    where = subprocess.run([str(venv / "bin" / "python"), "-c", probe], cwd=outside, env=_env(), capture_output=True, text=True)
    assert where.returncode == 0, where.stderr
    package, rtl, tb, build = (Path(line) for line in where.stdout.splitlines())
    assert package == site / "evclust" / "__init__.py", "evclust is not the wheel's (the editable install's .pth was processed?)"
    assert rtl == site / "evclust" / "rtl" / "hdl" / "rtl" and tb == site / "evclust" / "rtl" / "hdl" / "tb" / "evclust_core"
    assert build == WORK / "cache" / "evclust", "an installed package's builds go to $XDG_CACHE_HOME/evclust"
    hdl = sorted(str(p.relative_to(rtl.parent)) for p in rtl.parent.rglob("*") if p.is_file())

    # The events and the fixed model's tracks from the checkout (its numba cache is warm); the RTL's from the wheel.
    events = outside / "events.npz"
    assert main(["simulate", "crossing", "-o", str(events), "-q"]) == 0
    assert main(["track", str(events), "--model", "fixed", "-o", str(outside / "fixed.csv"), "-q"]) == 0
    _run(venv, outside, "track", "events.npz", "--model", "rtl", "-o", "rtl.csv", "-q")
    fixed, rtl_tracks = ((outside / f"{m}.csv").read_text().splitlines()[1:] for m in ("fixed", "rtl"))
    assert len(fixed) > 30 and rtl_tracks == fixed, "the RTL's track file is not the fixed model's"

    out = _run(venv, outside, "vectors", "--events", "events.npz", "--max-events", "3000", "-o", "vectors", "--replay", "verilator")
    assert "RTL (verilator) matches the fixed model bit for bit" in out, out
    assert (outside / "vectors" / "events" / "manifest.json").exists()

    assert (build / "cosim" / "verilator").is_dir()
    assert sorted(str(p.relative_to(rtl.parent)) for p in rtl.parent.rglob("*") if p.is_file()) == hdl, "a run wrote into the package"
    assert not (outside / "build").exists()
