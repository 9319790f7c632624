"""A frame-based reference for real videos, which have no ground truth (docs/METRICS.md).

Objects are the foreground blobs of a background subtractor (OpenCV's MOG2, shadows removed),
cleaned by morphology; each blob's velocity is the median of dense optical flow (OpenCV's DIS)
inside it, from frame k to k+1 like the simulator's ground truth; its colour is the mean YCbCr of
the frame's pixels inside it. Identities follow blobs from frame to frame: Hungarian assignment on
the distance between each object's flow-predicted centre and the blobs' centres. The rows are
the ground-truth CSV's, so `evclust score --truth` takes them.

It is a reference, not the truth: shadows that survive, people who merge into one blob when they
walk together, and people who stand still long enough to become background all show in it.
"""

from __future__ import annotations

import dataclasses
import time

import cv2
import numpy as np
from scipy.optimize import linear_sum_assignment
from tqdm import tqdm

from evclust.colour import RGB_TO_YCBCR
from evclust.scenes.video import VideoSource

SHADOW = 127  # MOG2 marks shadow pixels with this value, foreground with 255


@dataclasses.dataclass(frozen=True)
class ReferenceOptions:
    warmup_frames: int = 30  # frames the background model learns from before objects are reported
    history: int = 300  # MOG2's memory, frames
    var_threshold: float = 25.0  # MOG2's squared Mahalanobis distance for foreground
    min_area: int = 400  # px: smaller blobs are noise
    open_px: int = 3  # morphological opening (removes speckle), then closing (fills bodies)
    close_px: int = 15
    gate_px: float = 60.0  # an object and a blob farther apart than this are never the same


@dataclasses.dataclass
class ReferenceRun:
    rows: list[dict]
    frames: int
    ids: int
    wall_s: float

    def summary(self) -> str:
        per_frame = len(self.rows) / max(self.frames, 1)
        return f"{self.frames} frames, {len(self.rows)} object rows ({per_frame:.2f} per frame), {self.ids} identities, wall time {self.wall_s:.2f} s"


def _kernel(px: int) -> np.ndarray:
    return cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (px, px))


def _blobs(mask: np.ndarray, min_area: int) -> list[np.ndarray]:
    """Boolean masks of the connected foreground regions of at least `min_area` px."""
    n, labels, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
    return [labels == i for i in range(1, n) if stats[i, cv2.CC_STAT_AREA] >= min_area]


class _Identities:
    """Frame-to-frame association: each known object's centre moved by its flow, matched to the
    nearest blob centre by Hungarian assignment within the gate; the rest get new ids."""

    def __init__(self, gate_px: float):
        self.gate = gate_px
        self.known: dict[int, tuple[float, float]] = {}  # id -> predicted centre
        self.next_id = 0

    def assign(self, centres: np.ndarray, predicted: np.ndarray) -> list[int]:
        ids = [-1] * len(centres)
        old = list(self.known.items())
        if old and len(centres):
            cost = np.linalg.norm(np.array([c for _, c in old])[:, None, :] - centres[None, :, :], axis=2)
            rows, cols = linear_sum_assignment(np.where(cost <= self.gate, cost, 1e9))
            for r, c in zip(rows, cols):
                if cost[r, c] <= self.gate:
                    ids[c] = old[r][0]
        for i, ident in enumerate(ids):
            if ident < 0:
                ids[i], self.next_id = self.next_id, self.next_id + 1
        self.known = {ident: tuple(p) for ident, p in zip(ids, predicted)}
        return ids


def build_reference(source: VideoSource, options: ReferenceOptions = ReferenceOptions(), progress: bool = False,
                    palette_label=None) -> ReferenceRun:  # fmt: skip
    """Truth rows (TRUTH_COLUMNS) for every frame after the warm-up but the last, which has no
    next frame to give a velocity. `palette_label(ycbcr) -> str` names the colour."""
    start = time.perf_counter()
    subtractor = cv2.createBackgroundSubtractorMOG2(history=options.history, varThreshold=options.var_threshold, detectShadows=True)
    flow_engine = cv2.DISOpticalFlow_create(cv2.DISOPTICAL_FLOW_PRESET_MEDIUM)
    flow_engine.setFinestScale(0)  # full resolution: coarser scales underestimate a smooth object's motion
    opening, closing = _kernel(options.open_px), _kernel(options.close_px)
    identities = _Identities(options.gate_px)
    rows: list[dict] = []
    previous = None  # (frame index, RGB, grey, blob masks) waiting for the next frame's flow
    k = -1
    frames = tqdm(source.frames(), total=source.n_frames, unit="frame", desc="reference", disable=None if progress else True)
    for k, rgb in enumerate(frames):
        rgb8 = np.clip(rgb, 0, 255).astype(np.uint8)
        grey = cv2.cvtColor(rgb8, cv2.COLOR_RGB2GRAY)
        # OpenCV's automatic rate is 1/(frames seen): fast enough to absorb the part of a slow
        # object that overlaps its last positions. After the warm-up the rate is 1/history.
        rate = -1.0 if k < options.warmup_frames else 1.0 / options.history
        mask = subtractor.apply(cv2.cvtColor(rgb8, cv2.COLOR_RGB2BGR), learningRate=rate)
        if previous is not None:
            k0, rgb0, grey0, blobs0 = previous
            if blobs0:
                flow = flow_engine.calc(grey0, grey, None)
                rows += _rows(k0, source.t_frame_us, rgb0, blobs0, flow, identities, source, palette_label)
            else:
                identities.known = {}
        foreground = np.where(mask == 255, 255, 0).astype(np.uint8)  # shadows (127) are not objects
        foreground = cv2.morphologyEx(cv2.morphologyEx(foreground, cv2.MORPH_OPEN, opening), cv2.MORPH_CLOSE, closing)
        blobs = _blobs(foreground, options.min_area) if k >= options.warmup_frames else []
        previous = (k, rgb, grey, blobs)
    return ReferenceRun(rows, k + 1, identities.next_id, time.perf_counter() - start)


def _rows(k, t_frame_us, rgb, blobs, flow, identities, source, palette_label) -> list[dict]:
    centres, predicted, found = [], [], []
    for blob in blobs:
        ys, xs = np.nonzero(blob)
        x0, x1, y0, y1 = xs.min(), xs.max(), ys.min(), ys.max()
        cx, cy = (x0 + x1) / 2.0, (y0 + y1) / 2.0
        vx, vy = np.median(flow[..., 0][blob]), np.median(flow[..., 1][blob])
        ycc = rgb[blob].astype(np.float64).mean(axis=0) @ RGB_TO_YCBCR[:, :3].T + RGB_TO_YCBCR[:, 3]
        centres.append((cx, cy))
        predicted.append((cx + vx, cy + vy))
        found.append(
            (cx, cy, x1 - x0 + 1, y1 - y0 + 1, vx, vy, ycc, x0 > 0 and y0 > 0 and x1 < source.width - 1 and y1 < source.height - 1)
        )
    ids = identities.assign(np.array(centres, dtype=np.float64).reshape(-1, 2), np.array(predicted).reshape(-1, 2))
    out = []
    for ident, (cx, cy, w, h, vx, vy, ycc, inside) in zip(ids, found):
        out.append({
            "frame": k, "t_us": round(k * t_frame_us, 3), "id": ident, "cx": float(cx), "cy": float(cy), "w": float(w), "h": float(h),
            "vx": float(vx), "vy": float(vy), "Y": float(ycc[0]), "Cb": float(ycc[1]), "Cr": float(ycc[2]),
            "label": palette_label(ycc) if palette_label else "", "fully_visible": int(bool(inside)),
        })  # fmt: skip
    return out
