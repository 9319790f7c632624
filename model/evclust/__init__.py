"""evclust: colour event simulator, event-by-event clusterer, fixed-point model and RTL.

Data flows one way: scene -> simulator -> events -> clusterer -> tracks -> metrics -> report.
"""

import os
import time

__version__ = "0.1.0"
STARTED = time.perf_counter()  # when the package was imported: `track` counts its start-up from here

# OpenCV's and FFmpeg's own messages (a damaged block of a video, a missing moov atom) would reach
# stderr beside evclust's one-line error; a user who wants them sets these before the run. They
# are read when OpenCV loads, so they are set here, before any module imports cv2.
os.environ.setdefault("OPENCV_LOG_LEVEL", "OFF")
os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")  # AV_LOG_QUIET
