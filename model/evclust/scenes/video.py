"""Frames from anything OpenCV reads, or from a folder of images (sorted by name)."""

from __future__ import annotations

import collections
import contextlib
import os
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import cv2
import numpy as np

from evclust import limits
from evclust.errors import EvclustError
from evclust.events.format import MAX_SENSOR_SIDE
from evclust.threads import worker_threads

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".webp", ".ppm", ".pgm")


def _decoded_ahead(load, n: int, ahead: int = 4):
    """load(0), load(1), ... in order, up to `ahead` decoded at once on threads: images are
    independent files and OpenCV decodes without the GIL, so a folder reads at the speed of all
    cores (EVCLUST_THREADS of them). The window bounds the memory."""
    workers = min(ahead, worker_threads())
    if workers < 2:
        yield from (load(k) for k in range(n))
        return
    with ThreadPoolExecutor(workers) as pool:
        pending = collections.deque(pool.submit(load, k) for k in range(min(ahead, n)))
        for k in range(n):
            frame = pending.popleft().result()
            if k + ahead < n:
                pending.append(pool.submit(load, k + ahead))
            yield frame


@contextlib.contextmanager
def _native_stderr_silenced():
    """File descriptor 2 to /dev/null for a moment: OpenCV's AVI parser prints what it finds odd in a
    container straight to it, past any log level; evclust says in one line what went wrong."""
    sys.stderr.flush()
    saved = os.dup(2)
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


class VideoSource:
    def __init__(self, path: Path, fps: float | None = None, max_frames: int | None = None):
        self.path = Path(path)
        self.source = str(path)
        if not self.path.exists():
            raise EvclustError(f"{self.path}: no such video file or image folder")
        if self.path.is_dir():
            self.images = sorted(p for p in self.path.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES)
            if not self.images:
                raise EvclustError(f"{self.path}: the folder holds no images ({', '.join(IMAGE_SUFFIXES)})")
            if fps is None:
                raise EvclustError(f"{self.path}: a folder of images needs a frame rate (fps in the scene file, or --fps)")
            first = self._read_image(self.images[0])
            n_frames = len(self.images)
        else:
            self.images = None
            with _native_stderr_silenced():
                capture = cv2.VideoCapture(str(self.path))
                ok, first = capture.read() if capture.isOpened() else (False, None)
            if not ok:
                capture.release()
                raise EvclustError(f"{self.path}: OpenCV cannot read a frame from this file (unreadable or empty video)")
            fps = fps or capture.get(cv2.CAP_PROP_FPS) or None
            n_frames = int(capture.get(cv2.CAP_PROP_FRAME_COUNT)) or None
            capture.release()
            if not fps:
                raise EvclustError(f"{self.path}: the video does not declare a frame rate; give fps in a scene file or --fps")
            first = cv2.cvtColor(first, cv2.COLOR_BGR2RGB)
        self.height, self.width = first.shape[:2]
        if max(self.width, self.height) > MAX_SENSOR_SIDE:  # x and y are 16-bit: wider would wrap
            raise EvclustError(
                f"{self.path}: {self.width}x{self.height} frames; event coordinates hold at most {MAX_SENSOR_SIDE} px a side"
            )
        try:
            limits.check("SENSOR_PIXELS", self.width * self.height, f"{self.width}x{self.height} frames' pixels")
        except EvclustError as exc:
            raise EvclustError(f"{self.path}: {exc}") from None
        self.fps = float(fps)
        self.t_frame_us = 1e6 / self.fps
        self.n_frames = min(n_frames, max_frames) if (n_frames and max_frames) else (n_frames or max_frames)
        self.substeps = 1  # the sensor samples exactly the video's frames
        self.t_sample_us = self.t_frame_us
        self.n_samples = self.n_frames
        self.max_frames = max_frames

    def _read_image(self, path: Path) -> np.ndarray:
        image = cv2.imread(str(path), cv2.IMREAD_COLOR)
        if image is None:
            raise EvclustError(f"{path}: OpenCV cannot read this image")
        return cv2.cvtColor(image, cv2.COLOR_BGR2RGB)

    def _check_size(self, frame: np.ndarray, k: int) -> np.ndarray:
        """The frame as decoded, uint8 RGB: the simulator reads its colours from it directly, a
        quarter of the memory traffic of float32."""
        if frame.shape[:2] != (self.height, self.width):
            raise EvclustError(f"{self.path}: frame {k} is {frame.shape[1]}x{frame.shape[0]}, the first was {self.width}x{self.height}")
        return frame

    def frames(self):
        limit = self.max_frames or np.inf
        if self.images is not None:
            paths = self.images[: int(min(limit, len(self.images)))]
            yield from _decoded_ahead(lambda k: self._check_size(self._read_image(paths[k]), k), len(paths))
            return
        with _native_stderr_silenced():
            capture = cv2.VideoCapture(str(self.path))
        try:
            k = 0
            while k < limit:
                ok, bgr = capture.read()
                if not ok:
                    break
                yield self._check_size(cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB), k)
                k += 1
        finally:
            capture.release()
