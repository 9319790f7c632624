"""A read-only install, where numba can write no cache, still runs every command (evclust.jit).

numba with cache=True needs one writable folder among NUMBA_CACHE_DIR, the __pycache__ beside the
source and the user-wide cache ($XDG_CACHE_HOME/numba), or importing the module fails. The tests
run the CLI in a subprocess on a copy of the package in which none can be written, even by root
(file permissions do not stop root): every __pycache__ of the copy is a regular file, and the two
cache folders lie under a regular file (or under /dev/null), so no folder can be made there.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import evclust

PACKAGE = Path(evclust.__file__).parent
WARNING = "evclust: warning: no writable numba cache folder (set NUMBA_CACHE_DIR to one); compiling without a cache\n"
BLOCKER = b"not a folder\n"


@pytest.fixture(scope="module")
def readonly(tmp_path_factory) -> Path:
    """A copy of the package whose every __pycache__ is a file, beside a file `blocked`."""
    root = tmp_path_factory.mktemp("readonly")
    copy = root / "site" / "evclust"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    for folder in [copy, *(p for p in copy.rglob("*") if p.is_dir())]:
        (folder / "__pycache__").write_bytes(BLOCKER)
    # A module of the copy compiled by numba's own decorator: the precondition check below.
    (root / "site" / "plain_numba.py").write_text("import numba\n\n@numba.njit(cache=True)\ndef f(x):\n    return x + 1\n")
    (root / "site" / "__pycache__").write_bytes(BLOCKER)
    (root / "blocked").write_bytes(BLOCKER)
    return root


def blocked_env(root: Path, numba_cache_dir: str | None = "under-a-file") -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env["PYTHONPATH"] = str(root / "site")  # the copy, not the editable install
    env["XDG_CACHE_HOME"] = str(root / "blocked" / "cache")  # numba's user-wide cache: cannot be made
    env["HOME"] = str(root / "blocked" / "home")
    if numba_cache_dir == "under-a-file":
        env["NUMBA_CACHE_DIR"] = str(root / "blocked" / "numba")
    elif numba_cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = numba_cache_dir
    return env


def evclust_cli(argv: list[str], cwd: Path, env: dict | None = None) -> subprocess.CompletedProcess:
    code = "import sys; from evclust.cli import main; sys.exit(main())"
    return subprocess.run([sys.executable, "-c", code, *argv], cwd=cwd, env=env, capture_output=True, text=True, timeout=600)


def assert_nothing_cached(root: Path) -> None:
    assert (root / "blocked").read_bytes() == BLOCKER
    for pycache in (root / "site").rglob("__pycache__"):
        assert pycache.is_file() and pycache.read_bytes() == BLOCKER, pycache
    assert not [p for p in root.rglob("*") if p.suffix in (".nbi", ".nbc", ".pyc")]


def without_times(text: str) -> str:
    # The times, and where the compiled code came from: compiled here, loaded from a cache there.
    return re.sub(r"compiled code ready in [^;]*\)|[0-9]+\.[0-9]+ s\b|[0-9.]+ Mevents/s", "#", text)


def test_every_compiled_function_goes_through_evclust_jit():
    """numba's own decorators would bring the failure back: only evclust/jit/ may call them."""
    decorators = r"(njit|jit|vectorize|guvectorize|cfunc|stencil)\b"
    direct = re.compile(rf"\bnumba\.{decorators}|^\s*from numba import .*\b{decorators}")
    offenders = [
        f"{path.relative_to(PACKAGE)}:{number}: {line.strip()}"
        for path in PACKAGE.rglob("*.py")
        if path.parent != PACKAGE / "jit"
        for number, line in enumerate(path.read_text().splitlines(), 1)
        if direct.search(line)
    ]
    assert offenders == []


@pytest.fixture(scope="module")
def formats_table(tmp_path_factory) -> str:
    run = evclust_cli(["formats"], tmp_path_factory.mktemp("formats"))
    assert run.returncode == 0, run.stderr
    return run.stdout


@pytest.mark.parametrize("numba_cache_dir", [None, "under-a-file", "/dev/null/numba"])
def test_the_environment_defeats_numba_and_evclust_still_starts(readonly, numba_cache_dir, formats_table, tmp_path):
    env = blocked_env(readonly, numba_cache_dir)
    # Precondition: numba's own cache=True fails at import in this environment (numba 0.68).
    probe = "import evclust, plain_numba; print(evclust.__file__)"
    plain = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True)
    assert plain.returncode != 0
    assert "RuntimeError: cannot cache function 'f': no locator available" in plain.stderr
    # `evclust formats` imports the float and the fixed-point models (every decorator runs) and
    # compiles nothing: numba is never imported (evclust.jit makes dispatchers when first needed),
    # so nothing warns. A run that compiles warns once: the test below.
    run = evclust_cli(["formats"], tmp_path, env)
    assert run.returncode == 0, run.stderr
    assert run.stderr == ""
    assert run.stdout == formats_table
    assert_nothing_cached(readonly)


def test_simulate_and_track_without_a_cache_give_the_files_of_a_cached_run(readonly, tmp_path):
    blocked, normal = tmp_path / "blocked", tmp_path / "normal"
    blocked.mkdir()
    normal.mkdir()
    outputs = {}
    for folder, env in ((normal, None), (blocked, blocked_env(readonly))):
        sim = evclust_cli(["simulate", "crossing", "-o", "events.npz", "--truth", "truth.csv"], folder, env)
        track = evclust_cli(["track", "events.npz", "-o", "tracks.csv"], folder, env)
        outputs[folder] = [sim, track]
    for cached, uncached in zip(outputs[normal], outputs[blocked]):
        assert uncached.returncode == 0, uncached.stderr
        assert "Traceback" not in uncached.stderr
        assert uncached.stderr == cached.stderr + WARNING
        assert without_times(uncached.stdout) == without_times(cached.stdout)
    for name in ("events.npz", "truth.csv", "tracks.csv"):
        assert (blocked / name).read_bytes() == (normal / name).read_bytes(), name
    assert len((blocked / "tracks.csv").read_text().splitlines()) > 50  # crossing gives objects, one record each per frame
    assert_nothing_cached(readonly)


def test_a_writable_numba_cache_dir_brings_the_cache_back(readonly, tmp_path):
    """What the warning advises: the same read-only copy with NUMBA_CACHE_DIR writable caches there."""
    env = blocked_env(readonly, str(tmp_path / "numba-cache"))
    run = evclust_cli(["simulate", "slow", "-o", "events.npz"], tmp_path, env)
    assert run.returncode == 0, run.stderr
    assert run.stderr == ""
    assert list((tmp_path / "numba-cache").rglob("kernel.detect_interval-*.nbi"))
