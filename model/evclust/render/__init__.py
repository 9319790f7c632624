"""Pictures of event streams and of tracks: event pictures, track frames and videos, track plots."""

from evclust.render.events import draw_events
from evclust.render.plots import plot_colour, plot_scatter, plot_velocity
from evclust.render.tracks import FrameDrawer, draw_tracks, render_png, render_video

__all__ = [
    "draw_events",
    "FrameDrawer",
    "draw_tracks",
    "render_png",
    "render_video",
    "plot_velocity",
    "plot_colour",
    "plot_scatter",
]
