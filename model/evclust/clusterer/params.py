"""The clusterer's parameters: one `[clusterer]` TOML table, the same names in float, fixed and RTL.

Units: px for positions and sizes, µs for times, px/frame for velocities, 0..255 for colours.
Every α is the mean-shift memory of eq. (1); the hardware form uses β = 1 - α.
"""

from __future__ import annotations

import math
import tomllib
from importlib import resources
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from evclust.colour import NAMED_COLOURS, rgb_to_ycbcr
from evclust.errors import EvclustError, read_text, validation_message

Alpha = Annotated[float, Field(ge=0.0, lt=1.0)]
Positive = Annotated[float, Field(gt=0.0)]
NonNegative = Annotated[float, Field(ge=0.0)]
Byte = Annotated[float, Field(ge=0.0, le=255.0)]


class PaletteEntry(BaseModel):
    """A colour class: a name (matched against ground-truth labels) and its RGB colour."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)  # NaN and inf: refused at the source
    name: Annotated[str, Field(min_length=1)]
    rgb: tuple[Byte, Byte, Byte]


# γ's modes, in the order of their codes in both models and the RTL (GAMMA_MODE_* in the header).
GAMMA_MODES = ("global", "activity", "count")

# The activity against a reference time (activity_reference) holds Ã = A·2^((t - t_ref)/T_half),
# which grows by up to 2^REFERENCE_HALVINGS before the reference moves (at a filter step, or first
# at an event this many half-lives after it): the fixed model gives Ã that many integer bits more
# than the activity, and the RTL's header carries the count (REFERENCE_HALVINGS) for its rows.
REFERENCE_HALVINGS = 4

MAX_WARMUP = 64  # the interval filter's running mean covers at most this many measurements

DEFAULT_PALETTE = tuple(PaletteEntry(name=c.name, rgb=c.rgb) for c in NAMED_COLOURS)


class ClustererParams(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)  # NaN and inf: refused at the source

    # The cluster table and the seek region (§5.2).
    n_clusters: Annotated[int, Field(ge=1, le=1024)] = 16  # N slots
    # Beyond the paper: pipeline semantics. A core that takes one event per clock at a high clock
    # rate writes a slot back some events after it read it. With update_delay = D, event n reads
    # the table with the updates of events up to n - D - 1 committed (creations at once), and
    # each update is committed as increments added to the slot as it then is (docs/DESIGN.md,
    # "Pipeline semantics"). 0: the paper's sequential update.
    update_delay: Annotated[int, Field(ge=0, le=64)] = 0
    # Beyond the paper: the activity against a reference time (docs/DESIGN.md, "Activity against a
    # reference time"). Between filter steps each slot keeps Ã = A·2^((t - t_ref)/T_half), t_ref the
    # last step's time, so an event adds its weight 2^((t - t_ref)/T_half), one value per event and
    # the same for every slot: the per-event update of the activity is an addition, with no decay
    # in its recurrence. The step decays every slot by the same 2^-((t - t_ref)/T_half). False: the
    # paper's decay-then-add at every event.
    activity_reference: bool = False
    # Beyond the paper: the filter step's sweep beside the events (docs/DESIGN.md, "The sweep
    # beside the events"). 0: the step is one sweep of every slot between two events, with
    # everything in flight committed first (the paper's; a core stalls the stream for it). R >= 1:
    # the sweep runs on while events flow, R slots before each event after the step's; each event
    # and each swept slot see the table as it then is. With activity_reference the reference then
    # moves only when Ã runs out of headroom, and the step scales the activity by its decay.
    sweep_slots_per_event: Annotated[int, Field(ge=0, le=1024)] = 0
    # The defaults hold across the generalization suite: they were tuned on its tuning split
    # (evclust tune --suite tuning, docs/TUNING.md), never on its test split.
    seek_margin: NonNegative = 2.7  # S, px: a cluster catches events within its box grown by S (+ seek_scale·max R)
    r_init: Positive = 18.4  # half-size of a new cluster, px
    r_min: Positive = 1.0  # half-size clamp, px
    r_max: Positive = 80.0
    size_gain: Positive = 1.94  # g_R: R tracks g_R · |e - P|
    alpha_pos: Alpha = 0.9843  # centre
    alpha_size: Alpha = 0.9847  # half-size
    # Activity: an event count decaying with half-life T_half. Times are given in µs, or in frame
    # periods of the event stream when the µs value is not set (the defaults).
    t_half_us: Positive | None = None
    t_half_frames: Positive = 1.4
    a_min: NonNegative = 0.31  # below: the slot is freed at a filter step
    a_valid: NonNegative = 2.25  # at or above (and not noise): the cluster is reported
    filter_every: Annotated[int, Field(ge=1, le=1 << 20)] = 64  # N_f events between filter steps
    # Velocity (§6.2): mean centre motion, every event, and regular interval, every τ.
    alpha_vel_mcm: Alpha = 0.9922  # close to 1, as in the paper: one event says little about motion
    gamma: Positive = 37.0  # events per frame, the paper's global scale factor of eq. (5)
    # global: the paper's γ. activity: γ_i = A_i·ln2·T_frame/T_half, refreshed at filter steps.
    # count (beyond the paper): γ_i = the cluster's events in the last τ · T_frame/τ, which does not
    # follow the bursts inside a frame (activity with a short T_half does, and biases V_MCM).
    gamma_mode: Literal[GAMMA_MODES] = "count"
    alpha_vel_int: Alpha = 0.583
    tau_us: Positive | None = None  # τ in µs; when not set, tau_frames frame periods (rounded to whole µs)
    tau_frames: Positive = 4.25
    # Beyond the paper: both filters otherwise start at V = 0 and need ~1/β samples to forget it,
    # often longer than an object stays in view.
    velocity_warm_start: bool = True  # interval: skip the partial first τ, seed V_RI with the first full one
    mcm_bias_correction: bool = True  # MCM: report V / (1 - α^n), n = events since creation
    t_frame_us: Positive | None = None  # frame period; default: the event file's
    # Colour (§7.2).
    alpha_lum: Alpha = 0.9931
    alpha_chro: Alpha = 0.9851
    alpha_bg: Alpha = 0.999
    p_correction: Annotated[float, Field(gt=0.0, le=1.0)] = 0.59  # p of eq. (11)
    background: tuple[Byte, Byte, Byte] | None = None  # fixed background YCbCr; default: estimated
    palette: Annotated[tuple[PaletteEntry, ...], Field(min_length=1, max_length=64)] = DEFAULT_PALETTE
    palette_background: tuple[str, ...] = ()  # palette names that are background, never a class
    luma_weight: NonNegative = 1.0  # palette distance: w_Y·|ΔY| + |ΔCb| + |ΔCr|
    hist_bits: Annotated[int, Field(ge=2, le=24)] = 16  # saturating histogram counters
    # count: each event adds 1 (§7.2.2). contrast (beyond the paper): each event adds its L1 distance
    # from the background colour, so edge events that are mostly background weigh little.
    palette_vote: Literal["count", "contrast"] = "count"
    # nearest: the event's class is the nearest entry (§7.2.2). mixing (beyond the paper): an edge
    # event is a mixture q·object + (1-q)·background (§7.2.1); its class is the nearest entry among
    # those whose background-to-entry segment passes within mixing_tolerance of it.
    palette_assign: Literal["nearest", "mixing"] = "mixing"
    mixing_tolerance: NonNegative = 12.0  # L1 (luma weighted) distance to a mixing segment
    # Beyond the paper: one cluster per object (docs/TUNING.md, "One cluster per object").
    # Scales are in steps of 1/64 in the fixed model and the RTL.
    # The seek margin grows by seek_scale·max(Rx, Ry), so a large object's far edge is in reach. Off
    # by default: with the object layer on it costs a multiply per slot and buys no HOTA (docs/TUNING.md).
    seek_scale: NonNegative = 0.0
    merge: bool = True  # filter step: merge two clusters whose grown boxes overlap and whose velocities agree
    merge_scale: NonNegative = 0.390625  # for merging, each box grows by merge_scale·max(Rx, Ry)
    merge_v_tol: NonNegative = 0.32  # px/frame: the L1 velocity difference two merging clusters may have,
    merge_v_rel: NonNegative = 0.15625  # plus this fraction of the faster one's L1 speed
    noise_gate: NonNegative = 9.2  # report a cluster only if its activity is noise_gate times what the background's events give its box
    # A new cluster needs support: another event in its 3x3 neighbourhood of cells (2^support_cell_bits
    # px square) within the support window; isolated noise events then create nothing.
    create_support: bool = True
    support_cell_bits: Annotated[int, Field(ge=0, le=4)] = 0
    support_window_us: Positive | None = None  # the window in µs; when not set, support_window_frames frame periods
    support_window_frames: Positive = 0.127
    # Decisions from velocity (§6.3).
    v_min: NonNegative = 0.0114  # px/frame: a cluster whose MCM and interval speeds are both below is noise
    exit_margin: NonNegative = 10.9  # M, px: the border band where exit prediction acts
    v_exit: NonNegative = 1.0  # px/frame: minimum speed to predict an exit
    theta_exit_deg: Annotated[float, Field(gt=0.0, le=90.0)] = 45.0  # max angle to the border normal
    # The object layer (beyond the paper; clusterer/objects.py): once per filter step, the reported
    # clusters are grouped into objects by common fate, each kept under one id by prediction and
    # gated association. Times in frames of the event stream.
    objects: bool = True
    n_objects: Annotated[int, Field(ge=1, le=256)] = 16  # object slots
    object_gate: NonNegative = 2.55  # px: the margin of the overlap tests (cluster with cluster, group with object)
    object_link_along: NonNegative = 4.375  # along their motion, clusters link this many of their half-sizes across it apart
    object_v_tol: NonNegative = 1.98  # px/frame: common fate, velocities within this (L1)
    object_v_rel: NonNegative = 0.875  # plus this fraction of the faster L1 speed
    object_track_frames: Positive = 1.42  # the centre's α-β filter: time constant, frames
    object_rate_frames: Positive = 2.09  # ... and of the velocity's pull by the centre's residual
    object_velocity_frames: Positive = 17.2  # the velocity's pull towards its clusters' velocities
    object_size_frames: Positive = 0.145
    object_colour_frames: Positive = 1.78
    object_birth_frames: NonNegative = 4.36  # members for this long before an object is reported
    object_coast_frames: NonNegative = 9.2  # an object without members is predicted and reported this long,
    object_keep_frames: NonNegative = 82.0  # and kept, unreported, this long for its clusters to return

    @model_validator(mode="after")
    def _consistent(self):
        if self.a_min > self.a_valid:
            raise ValueError(
                f"need a_min <= a_valid, got {self.a_min} > {self.a_valid}: every cluster would be freed before it is reported"
            )
        if not self.r_min <= self.r_init <= self.r_max:
            raise ValueError(f"need r_min <= r_init <= r_max, got {self.r_min}, {self.r_init}, {self.r_max}")
        names = [e.name for e in self.palette]
        if len(set(names)) != len(names):
            raise ValueError("palette names must be unique")
        unknown = [n for n in self.palette_background if n not in names]
        if unknown:
            raise ValueError(f"palette_background names {', '.join(unknown)} are not in the palette")
        if len(self.palette_background) == len(names):
            raise ValueError("every palette entry is background: no class is left")
        return self

    def resolved(self, t_frame_us: float) -> ClustererParams:
        """The parameters in µs on a stream of frame period `t_frame_us`: a time not given in µs
        is its value in frames times the frame period (τ and the support window in whole µs,
        as the hardware counts them)."""
        update = {}
        if self.t_half_us is None:
            update["t_half_us"] = self.t_half_frames * t_frame_us
        if self.tau_us is None:
            update["tau_us"] = float(max(1, round(self.tau_frames * t_frame_us)))
        if self.support_window_us is None:
            update["support_window_us"] = float(max(1, round(self.support_window_frames * t_frame_us)))
        return self.model_copy(update=update) if update else self

    def interval_warmup(self) -> int:
        """With velocity_warm_start, the interval filter gains 1/n on its n-th measurement (a
        running mean) until 1/n <= β_vi: the first such n, at most MAX_WARMUP."""
        beta = 1.0 - self.alpha_vel_int
        return int(min(max(math.ceil(1.0 / beta - 1e-9), 1), MAX_WARMUP))

    def times(self, t_frame_us: float) -> str:
        """What the time constants come to on a stream of this frame period, for a summary line."""
        r = self.resolved(t_frame_us)

        def show(name, us, frames_value):
            given = getattr(self, name + "_us")
            source = "µs, given" if given is not None else f"= {frames_value:g} frames"
            return f"{name} {us:,.0f} µs ({source})"

        return ", ".join((show("t_half", r.t_half_us, self.t_half_frames), show("tau", r.tau_us, self.tau_frames)))

    @property
    def palette_names(self) -> tuple[str, ...]:
        return tuple(e.name for e in self.palette)

    def palette_ycbcr(self) -> np.ndarray:
        """(K, 3) float64 YCbCr of the palette entries (BT.601 full range)."""
        return rgb_to_ycbcr(np.array([e.rgb for e in self.palette], dtype=np.float64))

    def background_mask(self) -> np.ndarray:
        return np.array([e.name in self.palette_background for e in self.palette], dtype=np.bool_)


def parse_params(text: str, name: str) -> ClustererParams:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise EvclustError(f"{name}: malformed TOML: {exc}") from None
    unknown = sorted(set(data) - {"clusterer"})
    if unknown:
        raise EvclustError(f"{name}: unknown table or key '{unknown[0]}' (parameters go in a [clusterer] table)")
    try:
        return ClustererParams.model_validate(data.get("clusterer", {}))
    except ValidationError as exc:
        raise EvclustError(f"{name}: {validation_message(exc, 'clusterer')}") from None


def preset_names() -> list[str]:
    folder = resources.files("evclust.clusterer") / "presets"
    return sorted(p.name[: -len(".toml")] for p in folder.iterdir() if p.name.endswith(".toml"))


def load_params(ref: str | Path | None, source: str = "") -> tuple[ClustererParams, str]:
    """A TOML file, a preset name, or None: the preset of the events' source scene if there is
    one, else the defaults. Returns the parameters and where they came from."""
    if ref is None:
        if source in preset_names():
            ref = source
        else:
            return ClustererParams(), "defaults"
    path = Path(str(ref))
    if path.suffix.lower() == ".toml":
        if not path.is_file():
            raise EvclustError(f"{path}: no such parameter file")
        return parse_params(read_text(path), str(path)), str(path)
    if str(ref) in preset_names():
        text = (resources.files("evclust.clusterer") / "presets" / f"{ref}.toml").read_text()
        return parse_params(text, f"preset '{ref}'"), f"preset '{ref}'"
    raise EvclustError(f"unknown parameter set '{ref}': give a .toml file or a preset ({', '.join(preset_names())})")
