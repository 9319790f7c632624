"""The scene file (TOML), checked field by field: unknown keys and out-of-range values are refused.

Coordinates are pixel indices: pixel x covers [x - 0.5, x + 0.5], so an object centred on pixel
x has cx = x. Velocities are in px/frame. Colours are RGB 0..255, converted to YCbCr with BT.601.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from evclust import limits
from evclust.errors import EvclustError

Colour = tuple[
    Annotated[float, Field(ge=0, le=255)],
    Annotated[float, Field(ge=0, le=255)],
    Annotated[float, Field(ge=0, le=255)],
]
Vec2 = tuple[float, float]
Size2 = tuple[Annotated[float, Field(gt=0)], Annotated[float, Field(gt=0)]]


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)  # NaN and inf: refused at the source


class SensorSpec(Strict):
    """The change detector: what it sees and when it fires."""

    detector: Literal["log", "linear"] = "log"
    log_eps: Annotated[float, Field(gt=0)] = 1.0  # L = ln(Y + log_eps), Y in 0..255
    # In L units (ln for log, grey levels for linear). Below 10^-3 every flicker of noise fires,
    # and a scene's events grow without bound, so smaller thresholds are refused.
    threshold_on: Annotated[float, Field(ge=1e-3)] = 0.2
    threshold_off: Annotated[float, Field(ge=1e-3)] = 0.2


class BackgroundSpec(Strict):
    kind: Literal["uniform", "texture", "gradient", "image"] = "uniform"
    colour: Colour = (128.0, 128.0, 128.0)
    colour_to: Colour = (128.0, 128.0, 128.0)  # gradient: from colour to colour_to across the view
    angle_deg: float = 0.0  # gradient: its direction, degrees from +x towards +y
    contrast: Annotated[float, Field(ge=0, le=128)] = 10.0  # texture: standard deviation, grey levels
    scale: Annotated[float, Field(gt=0, le=1000)] = 4.0  # texture: correlation length, px
    image: str | None = None

    @model_validator(mode="after")
    def _image_needs_path(self):
        if self.kind == "image" and not self.image:
            raise ValueError("background kind 'image' needs image = \"path\"")
        return self


class PatchSpec(Strict):
    """A coloured part of an object, drawn over the parts before it."""

    shape: Literal["rectangle", "ellipse"] = "rectangle"
    offset: Vec2 = (0.0, 0.0)  # from the object's centre, px
    size: Size2  # full width and height, px
    colour: Colour


class LegSpec(Strict):
    """A stretch of constant velocity."""

    frames: Annotated[int, Field(gt=0)]
    velocity: Vec2  # px/frame


# The longest object label: the ground-truth files hold it in a 32-character column (truth.py).
LABEL_CHARS = 32


class ObjectSpec(Strict):
    id: Annotated[int, Field(ge=0)]
    label: Annotated[str, Field(max_length=LABEL_CHARS)]
    shape: Literal["rectangle", "ellipse"] = "rectangle"
    size: Size2
    colour: Colour
    patches: list[PatchSpec] = []
    start: Vec2  # centre at start_frame
    start_frame: Annotated[int, Field(ge=0)] = 0
    legs: Annotated[list[LegSpec], Field(min_length=1)]


class SceneSpec(Strict):
    """A synthetic scene or a video. Effects are validated by the simulator, which owns them."""

    name: str = ""
    description: str = ""
    seed: Annotated[int, Field(ge=0)] = 0
    # synthetic scenes
    width: Annotated[int, Field(gt=0, le=65535)] | None = None
    height: Annotated[int, Field(gt=0, le=65535)] | None = None
    fps: Annotated[float, Field(gt=0, le=1e6)] | None = None
    frames: Annotated[int, Field(gt=1)] | None = None
    # Synthetic scenes can be sampled between frames: the sensor then sees `substeps` renders per
    # frame, so an edge faster than 1 px/frame crosses each pixel at the right time.
    substeps: Annotated[int, Field(ge=1, le=64)] = 1
    background: BackgroundSpec = BackgroundSpec()
    objects: list[ObjectSpec] = []
    # video scenes: anything OpenCV reads, or a folder of images
    video: str | None = None
    truth: str | None = None  # ground-truth CSV of a video
    sensor: SensorSpec = SensorSpec()
    effects: dict[str, dict] = {}

    @model_validator(mode="after")
    def _synthetic_or_video(self):
        if self.video is None:
            missing = [k for k in ("width", "height", "fps", "frames") if getattr(self, k) is None]
            if missing:
                raise ValueError(f'a synthetic scene needs {", ".join(missing)} (or video = "path")')
            ids = [o.id for o in self.objects]
            if len(ids) != len(set(ids)):
                raise ValueError("object ids must be unique")
            # Bounds on the work a scene asks for, checked before anything is drawn (limits.py).
            try:
                limits.check("SENSOR_PIXELS", self.width * self.height, f"a {self.width}x{self.height} sensor's pixels")
                limits.check("FRAMES", self.frames, "frames")
                for o in self.objects:
                    limits.check("OBJECT_AREA", o.size[0] * o.size[1], f"object {o.id}'s area in px²")
            except EvclustError as exc:
                raise ValueError(str(exc)) from None
        elif self.objects:
            raise ValueError("a video scene cannot also have objects")
        elif self.substeps != 1:
            raise ValueError("substeps applies to synthetic scenes only: a video has only its frames")
        return self
