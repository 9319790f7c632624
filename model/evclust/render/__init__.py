"""Pictures of event streams (and, later, of tracks)."""

from evclust.render.events import draw_events

__all__ = ["draw_events"]
