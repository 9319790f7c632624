"""Running a clusterer model (float, fixed or RTL, by name) over events: evclust.run.track."""

from evclust.run.track import MODELS, TrackRun, prepare_run, rerun_objects, track_events, track_stream

__all__ = ["MODELS", "TrackRun", "prepare_run", "rerun_objects", "track_events", "track_stream"]
