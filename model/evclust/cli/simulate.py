"""evclust simulate SCENE -o events.npz [--truth gt.csv]"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

from evclust.errors import EvclustError, atomic_output


def add_parser(sub) -> None:
    p = sub.add_parser(
        "simulate",
        help="turn a scene or a video into colour events",
        description=(
            "Simulate a colour event camera (DVS change detector + TFS colour measurement) on a scene. "
            "SCENE is a built-in scene name (see 'evclust scenes'), a TOML scene file, a video file "
            "OpenCV can read, or a folder of images. Sensor effects are switched on in the scene file."
        ),
    )
    p.add_argument("scene", metavar="SCENE", help="built-in name, scene.toml, video file or image folder")
    p.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="EVENTS",
        help="event file to write (.npz, .h5 or .hdf5; .aedat4 or .raw EVT3 keep DVS events only, without colour)",
    )
    p.add_argument(
        "--truth", metavar="GT.csv", help="also write the ground truth per frame (synthetic scenes, or a video with a CSV beside it)"
    )
    p.add_argument("--seed", type=int, metavar="N", help="seed of the sensor effects (default: the scene's)")
    p.add_argument("--frames", type=int, metavar="N", help="simulate only the first N frames")
    p.add_argument("--fps", type=float, metavar="F", help="frame rate of a video or image folder (default: the video's)")
    p.add_argument("--evt", choices=("evt3", "evt2"), default="evt3", help="EVT version of a .raw output (default: evt3)")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.set_defaults(run=run)


# Frame rates a simulation accepts: slower than one frame in 1000 s puts event times past what
# the µs clock holds over a long video; faster than 10^6 frames/s leaves under 1 µs per frame.
MIN_FPS, MAX_FPS = 1e-3, 1e6


def run(args) -> int:
    if args.frames is not None and args.frames < 2:
        raise EvclustError(f"--frames {args.frames}: at least 2 frames are needed to see a change")
    if args.fps is not None and not MIN_FPS <= args.fps <= MAX_FPS:  # NaN fails both
        raise EvclustError(f"--fps {args.fps}: the frame rate must be between {MIN_FPS:g} and {MAX_FPS:g} frames/s")
    if args.seed is not None and args.seed < 0:
        raise EvclustError(f"--seed {args.seed}: a seed is a whole number >= 0")
    from evclust.events import event_writer
    from evclust.scenes import load_scene, write_truth
    from evclust.scenes.truth import read_truth
    from evclust.simulator import Simulation, stream_scene

    scene = load_scene(args.scene, fps=args.fps, max_frames=args.frames)
    if args.truth and not scene.has_truth:
        raise EvclustError(f"{args.scene}: no ground truth for this scene (a video needs a CSV of the same name beside it)")
    stream = stream_scene(scene, seed=args.seed, progress=not args.quiet)
    # Written as made, so memory does not grow with the video; a failure leaves no file. The
    # truth is written before the events are committed, and removed if they are not: both
    # outputs or neither.
    truth_written = False
    try:
        with event_writer(args.output, stream.meta, evt_version=args.evt) as writer:
            for chunk in stream:
                writer.write(chunk)
            result = Simulation(None, stream.meta, stream.samples, stream.sample_period_us, stream.wall_s, count=writer.count)
            if result.frames < 2:
                raise EvclustError(f"{args.scene}: only {result.frames} frame(s) could be read; at least 2 are needed")
            if args.truth:
                if scene.truth_path is not None:
                    read_truth(scene.truth_path)  # checked as `score` will read it, not copied blind
                    with atomic_output(args.truth) as tmp:
                        shutil.copyfile(scene.truth_path, tmp)
                else:
                    rows = scene.source.truth()
                    write_truth(args.truth, [r for r in rows if r["frame"] < result.frames])
                truth_written = True
    except BaseException:
        if truth_written:
            Path(args.truth).unlink(missing_ok=True)
        raise
    print(result.summary())
    sys.stdout.flush()
    return 0
