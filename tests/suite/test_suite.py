"""The generalization suite end to end on a few small scenes: the CLI verbs, the Dask runner,
the report, and the optuna study on SQLite (the quick share of `make generalize` in `make test`)."""

from __future__ import annotations

import re


from evclust.cli import main
from evclust.clusterer import ClustererParams
from evclust.choices import SPLITS

SMALL_TEST_SEEDS = (1016, 1023)  # the test split's smallest scenes: one through the codec, one clean, both noisy
SMALL_TUNING_SEED = 11  # a small clean tuning scene


def test_generalize_writes_the_page_for_a_few_scenes(tmp_path, capsys):
    out = tmp_path / "G.md"
    code = main(["generalize", "--split", "test", "--seeds", *map(str, SMALL_TEST_SEEDS), "--suite-dir", str(tmp_path / "suite"),
                 "--workers", "2", "-o", str(out), "-q"])  # fmt: skip
    assert code == 0
    text = out.read_text()
    assert text.startswith("<!-- inputs: formats=")  # its input stamp (evclust.stamps)

    # Three configurations, float and fixed of the defaults beside the paper's: what each reports
    # (the defaults' objects, the paper's clusters), then every one's cluster records.
    def overall(title):
        table = text.split(f"## Overall: {title}")[1].split("\n## ")[0]
        rows = [
            line for line in table.splitlines() if re.match(r"\| (default|default, frame period withheld|paper) \| (float|fixed) \|", line)
        ]
        return [[cell.strip() for cell in r.split("|")[1:4]] for r in rows]

    assert overall("what each configuration reports") == [
        ["default", "float", "objects"],
        ["default", "fixed", "objects"],
        ["default, frame period withheld", "float", "objects"],
        ["paper", "float", "clusters"],
    ]
    assert overall("cluster records") == [
        ["default", "float", "clusters"],
        ["default", "fixed", "clusters"],
        ["default, frame period withheld", "float", "clusters"],
        ["paper", "float", "clusters"],
    ]
    for section in ("## Targets", "## By category: default, float model, objects", "## By category: default, float model, its cluster records",
                    "## Per scene", "## Typical failures", "## Commands", "## Fixed against float", "## Frame period withheld"):  # fmt: skip
        assert section in text
    assert all(f"gen_{s}" in text for s in SMALL_TEST_SEEDS)
    assert (tmp_path / "img" / "g_failures.png").stat().st_size > 10_000
    # The scenes were kept: a second run simulates nothing again.
    keys = sorted(p.read_text() for p in (tmp_path / "suite").glob("*.key"))
    assert len(keys) == len(SMALL_TEST_SEEDS)


def test_generalize_refuses_seeds_outside_the_split(tmp_path, capsys):
    assert main(["generalize", "--split", "test", "--seeds", "3", "-o", str(tmp_path / "G.md")]) == 2
    assert "--seeds 3: not in the test split" in capsys.readouterr().err


def test_scenes_generate_writes_a_scene_its_truth_and_its_facts(tmp_path, capsys):
    assert main(["scenes", "--generate", "11", "-o", str(tmp_path)]) == 0
    assert {p.name for p in tmp_path.iterdir()} == {"gen_0011.toml", "gen_0011.json"}
    assert main(["simulate", str(tmp_path / "gen_0011.toml"), "-o", str(tmp_path / "e.npz"), "--truth", str(tmp_path / "t.csv"), "-q"]) == 0
    assert (tmp_path / "t.csv").read_text().splitlines()[0].endswith(",visible")


def test_scenes_options_need_an_output_folder(tmp_path, capsys):
    assert main(["scenes", "--split", "test"]) == 2
    assert "need -o DIR" in capsys.readouterr().err
    assert main(["scenes", "-o", str(tmp_path)]) == 2


def test_track_prints_the_time_constants_it_chose(tmp_path, capsys):
    assert main(["scenes", "--generate", "11", "-o", str(tmp_path)]) == 0
    assert main(["simulate", str(tmp_path / "gen_0011.toml"), "-o", str(tmp_path / "e.npz"), "-q"]) == 0
    capsys.readouterr()
    assert main(["track", str(tmp_path / "e.npz"), "-o", str(tmp_path / "t.csv"), "-q"]) == 0
    line = capsys.readouterr().out
    # 15 fps: the defaults' T_half and τ in frames times 66,667 µs (τ rounded to whole µs).
    defaults = ClustererParams()
    t_half, tau = defaults.t_half_frames * 1e6 / 15, round(defaults.tau_frames * 1e6 / 15)
    assert (
        f"parameters from defaults (t_half {t_half:,.0f} µs (= {defaults.t_half_frames:g} frames), "
        f"tau {tau:,.0f} µs (= {defaults.tau_frames:g} frames))"
    ) in line


def test_suite_tuning_keeps_its_trials_in_sqlite_and_resumes(tmp_path):
    import optuna

    from evclust.suite import dask_client, prepare_scene
    from evclust.tune.suite import tune_suite

    storage = f"sqlite:///{tmp_path / 'study.db'}"
    folder = tmp_path / "suite"
    with dask_client(workers=1) as client:
        client.submit(prepare_scene, SMALL_TUNING_SEED, str(folder)).result()
        first = tune_suite(client, folder, (SMALL_TUNING_SEED,), ClustererParams(), 2, storage, "t", progress=False)
        second = tune_suite(client, folder, (SMALL_TUNING_SEED,), ClustererParams(), 2, storage, "t", progress=False)
    assert (first.trials, second.trials) == (2, 4)  # the first trial is the base set (enqueued), then resumed
    study = optuna.load_study(study_name="t", storage=storage)
    assert len(study.trials) == 4 and study.best_value == second.value
    assert second.value <= study.trials[0].value  # never worse than the starting point


def test_the_split_seeds_are_disjoint_and_the_test_split_is_big_enough():
    assert not set(SPLITS["tuning"]) & set(SPLITS["test"]) and len(SPLITS["test"]) >= 30


def test_a_search_of_the_object_layer_alone_leaves_every_other_parameter_as_it_starts(capsys):
    from evclust.tune.suite import searched, suggest

    space, categorical = searched("object_")
    assert space and not categorical and all(name.startswith("object_") for name, *_ in space)

    class Trial:  # each suggestion at its range's top
        def suggest_float(self, name, low, high, log=False, step=None):
            return high

    base = ClustererParams()
    tried = suggest(Trial(), base, "object_")
    changed = {k for k, v in tried.model_dump().items() if v != base.model_dump()[k]}
    assert changed and all(k.startswith("object_") for k in changed)
    assert main(["tune", "traffic", "--only", "object_", "-o", "x.toml"]) == 2
    assert "--only works with --suite" in capsys.readouterr().err
