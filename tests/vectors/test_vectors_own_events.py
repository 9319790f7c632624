"""`evclust vectors --events FILE`: golden vectors from a team's own event file, replayed on the RTL."""

from __future__ import annotations

import json

import numpy as np
import pytest

from evclust.cli import main
from evclust.clusterer import load_params
from evclust.run import track_events
from evclust.events import read_events
from evclust.vectors import event_fields
from evclust.vectors.pack import unpack
from evclust.vectors.read import load_case

from cosim import TIMING_SIMULATORS, selected_simulators
from testkit import assert_one_line_error, run_cli

N = 6000


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    folder = tmp_path_factory.mktemp("own")
    assert main(["simulate", "crossing", "-o", str(folder / "walk.h5"), "-q"]) == 0
    assert main(["simulate", "crossing", "-o", str(folder / "walk_dvs.aedat4"), "-q"]) == 0
    return folder


@pytest.mark.parametrize("sim", selected_simulators(TIMING_SIMULATORS))  # Icarus: make test-full
def test_own_events_become_a_case_the_rtl_replays_bit_exact(recording, capsys, sim):
    out = recording / f"vec_{sim}"
    code, stdout, err = run_cli(
        capsys, "vectors", "--events", str(recording / "walk.h5"), "--max-events", str(N), "-o", str(out), "--replay", sim
    )
    assert code == 0, err
    case = load_case(out / "walk")
    assert len(case.events) == N
    # The case's expected records are the fixed model's on the same first N events, run apart.
    events, meta = read_events(recording / "walk.h5")
    params, _ = load_params(None, meta.source)
    fixed = track_events(events[:N], meta, params, model="fixed")
    manifest = json.loads((out / "walk" / "manifest.json").read_text())
    assert fixed.tracks.size > 0 and manifest["counts"]["records"] == fixed.tracks.size
    t_words = [unpack(word, event_fields(case.table))[0] for word in case.events]
    assert np.array_equal(np.array(t_words, np.uint64), events["t"][:N] & np.uint64(0xFFFFFFFF))
    assert f"RTL ({sim}) matches the fixed model bit for bit: {fixed.tracks.size} records" in stdout


@pytest.mark.parametrize(
    "args, fragments",
    [
        (["--events", "walk_dvs.aedat4"], ("walk_dvs.aedat4", "DVS-only events")),
        (["--events", "walk.h5", "--max-events", "0"], ("--max-events 0",)),
        (["--events", "walk.h5", "--check"], ("--check",)),
        (["--max-events", "10"], ("go with --events FILE",)),
        (["--events", "absent.h5"], ("absent.h5", "no such event file")),
    ],
)
def test_bad_requests_fail_with_one_line_and_write_nothing(recording, capsys, args, fragments):
    out = recording / "never"
    args = [str(recording / a) if a.endswith((".h5", ".aedat4")) else a for a in args]
    code, _, err = run_cli(capsys, "vectors", *args, "-o", str(out))
    assert_one_line_error(code, err, *fragments)
    assert not out.exists() or not any(out.iterdir())
