"""The Python passes ruff's lint and format check and import-linter's contracts (the layers, no
import circles) under the rules of pyproject.toml, as `make lint` runs them, so that CI (which
runs `make test`) keeps it so; and a file that breaks a rule is caught."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


def tool(name: str, *args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess:
    if not (BIN / name).exists():
        pytest.fail(f"{BIN / name}: not in this environment; pip install -e '.[test]'")
    return subprocess.run([str(BIN / name), *args], cwd=cwd, capture_output=True, text=True, timeout=300)


def ruff(*args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess:
    return tool("ruff", *args, cwd=cwd)


def test_the_repository_passes_ruff_check():
    done = ruff("check", ".")
    assert done.returncode == 0, done.stdout + done.stderr


def test_the_repository_is_formatted():
    done = ruff("format", "--check", ".")
    assert done.returncode == 0, done.stdout + done.stderr


def test_the_rules_catch_an_unused_import_and_a_loop_closure(tmp_path):
    (tmp_path / "pyproject.toml").write_text((ROOT / "pyproject.toml").read_text())
    (tmp_path / "broken.py").write_text("import os\n\nfns = []\nfor i in range(3):\n    fns.append(lambda: i)\n")
    done = ruff("check", "--no-cache", "broken.py", cwd=tmp_path)
    assert done.returncode == 1
    assert "F401" in done.stdout and "B023" in done.stdout, done.stdout


def test_the_imports_keep_the_layers_and_make_no_circle():
    done = tool("lint-imports", "--no-cache")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Contracts: 2 kept, 0 broken." in done.stdout


def test_the_tests_mirror_the_packages():
    # tests/<package>/ for each package's tests; only repository-wide tests stay at the top.
    packages = {p.name for p in (ROOT / "model" / "evclust").iterdir() if (p / "__init__.py").exists()}
    folders = {p.name for p in (ROOT / "tests").iterdir() if p.is_dir() and not p.name.startswith((".", "__"))}
    assert folders <= packages, f"test folders that name no package: {sorted(folders - packages)}"
    top = sorted(p.name for p in (ROOT / "tests").glob("test_*.py"))
    assert top == ["test_documents.py", "test_readonly_install.py", "test_style.py"], top


def test_no_script_or_test_edits_the_import_path():
    # The package is installed (editable or as a wheel) and a script's own folder is on its path,
    # so nothing needs sys.path edited; an edit would hide an import the installed package lacks.
    edits = [f"{p.relative_to(ROOT)}:{n}" for folder in ("model", "tb", "synth", "bench", "tests", "formal")
             for p in sorted((ROOT / folder).rglob("*.py")) for n, line in enumerate(p.read_text().splitlines(), 1)
             if "sys.path." + "insert" in line or "sys.path." + "append" in line]  # fmt: skip
    assert edits == []
