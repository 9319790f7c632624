"""Reports: task results per scene (docs/RESULTS.md); the fixed-point error budget comes later."""

from evclust.report.results import PAPER, TARGETS, prepare_scene, scene_results, write_results

__all__ = ["PAPER", "TARGETS", "prepare_scene", "scene_results", "write_results"]
