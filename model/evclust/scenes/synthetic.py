"""Synthetic scenes: a static background and rigid objects on constant-velocity legs, rendered
with exact area coverage at the edges (so sub-pixel motion changes pixel values smoothly), and
their exact ground truth."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import cv2
import numpy as np

from evclust.colour import rgb_to_ycbcr
from evclust.errors import EvclustError
from evclust.scenes.schema import BackgroundSpec, ObjectSpec, SceneSpec

TRUTH_COLUMNS = ("frame", "t_us", "id", "cx", "cy", "w", "h", "vx", "vy", "Y", "Cb", "Cr", "label", "fully_visible")
# Written by the simulator, optional when read (a hand-made CSV may leave it out: 1.0).
TRUTH_OPTIONAL = {"visible": 1.0}  # the fraction of the object's area in view and not hidden by an object in front


def make_background(spec: BackgroundSpec, width: int, height: int, seed: int, base_dir: Path) -> np.ndarray:
    """(H, W, 3) float32 RGB."""
    colour = np.asarray(spec.colour, dtype=np.float32)
    if spec.kind == "uniform":
        return np.broadcast_to(colour, (height, width, 3)).astype(np.float32)
    if spec.kind == "gradient":
        # Linear in the position along the direction, from `colour` at one corner to `colour_to`
        # at the opposite one.
        a = np.radians(spec.angle_deg)
        u = np.cos(a) * np.arange(width)[None, :] + np.sin(a) * np.arange(height)[:, None]
        u = (u - u.min()) / max(float(u.max() - u.min()), 1e-12)
        end = np.asarray(spec.colour_to, dtype=np.float32)
        return (colour + (end - colour) * u[..., None].astype(np.float32)).astype(np.float32)
    if spec.kind == "texture":
        noise = np.random.default_rng(seed).standard_normal((height, width)).astype(np.float32)
        smooth = cv2.GaussianBlur(noise, (0, 0), sigmaX=spec.scale, borderType=cv2.BORDER_REFLECT)
        smooth /= max(float(smooth.std()), 1e-12)
        return np.clip(colour + spec.contrast * smooth[..., None], 0, 255).astype(np.float32)
    path = (base_dir / spec.image).resolve()
    image = cv2.imread(str(path), cv2.IMREAD_COLOR)
    if image is None:
        raise EvclustError(f"{path}: background image cannot be read")
    image = cv2.resize(image, (width, height), interpolation=cv2.INTER_AREA)
    return cv2.cvtColor(image, cv2.COLOR_BGR2RGB).astype(np.float32)


def _coverage_1d(lo: float, hi: float, first: int, count: int) -> np.ndarray:
    """Overlap of pixels [i-0.5, i+0.5] with [lo, hi], for i = first .. first+count-1."""
    centres = np.arange(first, first + count, dtype=np.float64)
    return np.clip(np.minimum(centres + 0.5, hi) - np.maximum(centres - 0.5, lo), 0.0, 1.0)


def _part_coverage(shape: str, cx: float, cy: float, w: float, h: float, x0: int, y0: int, nx: int, ny: int):
    if shape == "rectangle":
        cov_x = _coverage_1d(cx - w / 2, cx + w / 2, x0, nx)
        cov_y = _coverage_1d(cy - h / 2, cy + h / 2, y0, ny)
        return np.outer(cov_y, cov_x)
    # Ellipse: signed distance to the boundary to first order, then a one-pixel ramp.
    a, b = w / 2, h / 2
    dx = np.arange(x0, x0 + nx, dtype=np.float64)[None, :] - cx
    dy = np.arange(y0, y0 + ny, dtype=np.float64)[:, None] - cy
    q = np.sqrt((dx / a) ** 2 + (dy / b) ** 2)
    grad = np.sqrt((dx / a**2) ** 2 + (dy / b**2) ** 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        dist = np.where(q > 0, (q - 1.0) * q / np.maximum(grad, 1e-12), -min(a, b))
    return np.clip(0.5 - dist, 0.0, 1.0)


@dataclasses.dataclass
class RigidObject:
    spec: ObjectSpec

    def __post_init__(self):
        s = self.spec
        self.parts = [(s.shape, (0.0, 0.0), s.size, np.asarray(s.colour))] + [
            (p.shape, p.offset, p.size, np.asarray(p.colour)) for p in s.patches
        ]
        lo = np.min([[ox - w / 2, oy - h / 2] for _, (ox, oy), (w, h), _ in self.parts], axis=0)
        hi = np.max([[ox + w / 2, oy + h / 2] for _, (ox, oy), (w, h), _ in self.parts], axis=0)
        self.box_offset = (hi + lo) / 2  # box centre relative to the path point
        self.box_size = hi - lo
        # Leg boundaries in frames, and the position at each boundary.
        starts = [float(s.start_frame)]
        points = [np.asarray(s.start, dtype=np.float64)]
        for leg in s.legs:
            points.append(points[-1] + leg.frames * np.asarray(leg.velocity))
            starts.append(starts[-1] + leg.frames)
        self.leg_starts = np.asarray(starts)
        self.leg_points = np.asarray(points)
        rgb_sum, self.area = self._whole()
        self.mean_ycbcr = rgb_to_ycbcr(rgb_sum / self.area)

    def state(self, frame: float):
        """(centre, velocity) at `frame`, or None when the object is not in the scene.
        The velocity is that of the leg that starts at or before `frame` (forward convention)."""
        if frame < self.leg_starts[0] or frame > self.leg_starts[-1]:
            return None
        j = min(int(np.searchsorted(self.leg_starts, frame, side="right")) - 1, len(self.spec.legs) - 1)
        velocity = np.asarray(self.spec.legs[j].velocity, dtype=np.float64)
        return self.leg_points[j] + (frame - self.leg_starts[j]) * velocity, velocity

    def layer(self, centre, width: int, height: int):
        """Premultiplied colour and alpha of the object over its bounding box clipped to the sensor."""
        cx, cy = centre
        bx, by = centre + self.box_offset
        bw, bh = self.box_size
        x0, x1 = max(int(np.floor(bx - bw / 2 + 0.5)), 0), min(int(np.ceil(bx + bw / 2 - 0.5)) + 1, width)
        y0, y1 = max(int(np.floor(by - bh / 2 + 0.5)), 0), min(int(np.ceil(by + bh / 2 - 0.5)) + 1, height)
        if x1 <= x0 or y1 <= y0:
            return None
        colour = np.zeros((y1 - y0, x1 - x0, 3))
        alpha = np.zeros((y1 - y0, x1 - x0))
        for shape, (ox, oy), (w, h), rgb in self.parts:
            m = _part_coverage(shape, cx + ox, cy + oy, w, h, x0, y0, x1 - x0, y1 - y0)
            colour = colour * (1 - m[..., None]) + rgb * m[..., None]
            alpha = alpha * (1 - m) + m
        return (slice(y0, y1), slice(x0, x1)), colour, alpha

    def _whole(self) -> tuple[np.ndarray, float]:
        """The summed RGB and the area (px) of the object rendered whole, at an integer offset on
        a canvas that holds it."""
        w, h = (int(np.ceil(v)) + 4 for v in self.box_size)
        centre = np.array([w / 2, h / 2]) - self.box_offset
        _, colour, alpha = self.layer(centre, w, h)
        return colour.reshape(-1, 3).sum(axis=0), float(alpha.sum())

    def fully_visible(self, centre, width: int, height: int) -> bool:
        lo = centre + self.box_offset - self.box_size / 2
        hi = centre + self.box_offset + self.box_size / 2
        return bool(lo[0] >= -0.5 and lo[1] >= -0.5 and hi[0] <= width - 0.5 and hi[1] <= height - 0.5)

    def partly_visible(self, centre, width: int, height: int) -> bool:
        lo = centre + self.box_offset - self.box_size / 2
        hi = centre + self.box_offset + self.box_size / 2
        return bool(hi[0] > -0.5 and hi[1] > -0.5 and lo[0] < width - 0.5 and lo[1] < height - 0.5)


class SyntheticSource:
    """Frames and ground truth of a synthetic scene."""

    def __init__(self, spec: SceneSpec, base_dir: Path, source: str):
        self.spec = spec
        self.source = source
        self.width, self.height = int(spec.width), int(spec.height)
        self.fps = float(spec.fps)
        self.n_frames = int(spec.frames)
        self.t_frame_us = 1e6 / self.fps
        self.substeps = int(spec.substeps)
        self.t_sample_us = self.t_frame_us / self.substeps
        self.n_samples = (self.n_frames - 1) * self.substeps + 1
        self.background = make_background(spec.background, self.width, self.height, spec.seed, base_dir)
        self.objects = [RigidObject(o) for o in spec.objects]

    def render(self, k: float) -> np.ndarray:
        """The view at frame k; k may be fractional (a sub-step between frames)."""
        frame = self.background.copy()
        for obj in self.objects:
            state = obj.state(k)
            if state is None:
                continue
            layer = obj.layer(state[0], self.width, self.height)
            if layer is None:
                continue
            window, colour, alpha = layer
            frame[window] = frame[window] * (1 - alpha[..., None]) + colour
        return frame

    def frames(self):
        """The views the sensor samples: every frame, and `substeps - 1` views between frames."""
        for j in range(self.n_samples):
            yield self.render(j / self.substeps)

    def _visible_fractions(self, k: int) -> dict[int, float]:
        """Per object present at frame k, the fraction of its area inside the view and not
        covered by the objects drawn after it (in front of it)."""
        covered = np.zeros((self.height, self.width))
        out = {}
        for obj in reversed(self.objects):
            state = obj.state(k)
            layer = obj.layer(state[0], self.width, self.height) if state is not None else None
            if layer is None:
                continue
            window, _, alpha = layer
            out[obj.spec.id] = float((alpha * (1.0 - covered[window])).sum()) / obj.area
            covered[window] += alpha * (1.0 - covered[window])
        return out

    def truth(self) -> list[dict]:
        rows = []
        for k in range(self.n_frames):
            visible = self._visible_fractions(k)
            for obj in self.objects:
                state = obj.state(k)
                if state is None or not obj.partly_visible(state[0], self.width, self.height):
                    continue
                centre, velocity = state
                box_centre = centre + obj.box_offset
                rows.append(
                    {
                        "frame": k,
                        "t_us": round(k * self.t_frame_us, 3),
                        "id": obj.spec.id,
                        "cx": round(float(box_centre[0]), 4),
                        "cy": round(float(box_centre[1]), 4),
                        "w": round(float(obj.box_size[0]), 4),
                        "h": round(float(obj.box_size[1]), 4),
                        "vx": round(float(velocity[0]), 4),
                        "vy": round(float(velocity[1]), 4),
                        "Y": round(float(obj.mean_ycbcr[0]), 3),
                        "Cb": round(float(obj.mean_ycbcr[1]), 3),
                        "Cr": round(float(obj.mean_ycbcr[2]), 3),
                        "label": obj.spec.label,
                        "fully_visible": int(obj.fully_visible(centre, self.width, self.height)),
                        "visible": round(min(visible.get(obj.spec.id, 0.0), 1.0), 4),
                    }
                )
        return rows
