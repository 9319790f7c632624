"""The generalization suite (docs/GENERALIZATION.md): seeded scenes in a fixed tuning/test split,
simulated once, then tracked and scored in batches on Dask."""

from evclust.suite.evaluate import SceneResult, evaluate_scene
from evclust.suite.prepare import SceneFiles, prepare_scene, split_seeds
from evclust.suite.run import dask_client, map_scenes, prepare_split, run_split

__all__ = [
    "SceneFiles", "SceneResult", "dask_client", "evaluate_scene", "map_scenes", "prepare_scene", "prepare_split",
    "run_split", "split_seeds",
]  # fmt: skip
