"""evclust reference VIDEO -o truth.csv: a frame-based reference for a real video"""

from __future__ import annotations

from evclust.cli.common import preset_list


def add_parser(sub) -> None:
    p = sub.add_parser(
        "reference",
        help="build a frame-based reference (objects, velocity, colour) for a real video",
        description=(
            "Real videos have no ground truth. This builds a reference from the frames with OpenCV: objects are "
            "the foreground blobs of a background subtractor (MOG2, shadows removed, cleaned by morphology), their "
            "velocity the median dense optical flow (DIS) inside each blob, their colour the mean YCbCr of its "
            "pixels, their identity followed from frame to frame. The CSV has the ground truth's columns, so "
            "'evclust score --truth' takes it. Its known weaknesses are in docs/METRICS.md."
        ),
    )
    p.add_argument("video", metavar="VIDEO", help="video file OpenCV reads (or a folder of images with --fps)")
    p.add_argument("-o", "--output", required=True, metavar="TRUTH.csv", help="reference CSV to write")
    p.add_argument("--frames", type=int, metavar="N", help="use only the first N frames")
    p.add_argument("--fps", type=float, metavar="F", help="frame rate of an image folder (default: the video's)")
    p.add_argument(
        "--warmup", type=int, default=30, metavar="N", help="frames the background model learns from before objects count (default: 30)"
    )
    p.add_argument("--min-area", type=int, default=400, metavar="PX", help="smallest blob that is an object, px (default: 400)")
    p.add_argument(
        "--params", metavar="P", help=f"parameter file or preset whose palette names the colours ({preset_list()}; default: the defaults')"
    )
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p.set_defaults(run=run)


def run(args) -> int:
    from pathlib import Path

    from evclust.clusterer import load_params
    from evclust.errors import EvclustError
    from evclust.metrics.match import nearest_palette_class
    from evclust.scenes import write_truth
    from evclust.scenes.frame_reference import ReferenceOptions, build_reference
    from evclust.scenes.video import VideoSource
    from evclust.tracks import TrackMeta

    if args.min_area < 1:
        raise EvclustError(f"--min-area {args.min_area}: at least one pixel")
    if args.warmup < 0:
        raise EvclustError(f"--warmup {args.warmup}: must not be negative")
    if args.frames is not None and args.frames < 2:
        raise EvclustError(f"--frames {args.frames}: at least 2 frames are needed for a velocity")
    params, _ = load_params(args.params)
    source = VideoSource(Path(args.video), fps=args.fps, max_frames=args.frames)
    palette = TrackMeta(
        width=source.width, height=source.height, t_frame_us=source.t_frame_us, palette=params.palette_names,
        palette_ycbcr=tuple(tuple(float(c) for c in e) for e in params.palette_ycbcr()),
        palette_background=tuple(params.palette_background), luma_weight=params.luma_weight,
    )  # fmt: skip

    def label(ycbcr) -> str:
        index = int(nearest_palette_class(ycbcr, palette)[0])
        return palette.palette[index] if index >= 0 else ""

    options = ReferenceOptions(warmup_frames=args.warmup, min_area=args.min_area)
    result = build_reference(source, options, progress=not args.quiet, palette_label=label)
    write_truth(args.output, result.rows)
    print(f"{args.output}: {args.video}: {result.summary()}")
    return 0
