"""Task metrics (SPEC §8; paper §6.3, §7.3): match track records to ground truth, score them.

`match` pairs each filter step's track records with the ground-truth objects of that moment;
`score` turns the pairs into the figures of the paper's Tables 5 and 7 plus tracking figures;
`format_tables` prints them. Definitions: docs/METRICS.md.
"""

from evclust.metrics.match import DEFAULT_GATE_PX, MATCH_DTYPE, MatchCounts, match, match_with_counts, nearest_palette_class
from evclust.metrics.scores import ColourError, Scores, VelocityScores, score, scores_from_matches
from evclust.metrics.tables import format_tables

__all__ = [
    "DEFAULT_GATE_PX",
    "MATCH_DTYPE",
    "MatchCounts",
    "match",
    "match_with_counts",
    "nearest_palette_class",
    "Scores",
    "VelocityScores",
    "ColourError",
    "score",
    "scores_from_matches",
    "format_tables",
]
