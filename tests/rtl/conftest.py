import importlib
from pathlib import Path

import pytest


@pytest.fixture
def timing_script(monkeypatch):
    """synth/timing.py, a script that imports its neighbour synth.py as a script does: its folder
    on the path, for the test only (pytest takes it off again)."""
    monkeypatch.syspath_prepend(str(Path(__file__).resolve().parents[2] / "synth"))
    return importlib.import_module("timing")
