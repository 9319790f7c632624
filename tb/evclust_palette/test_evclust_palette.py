"""evclust_palette, one event's palette class and vote, against the fixed model's functions
(`_nearest_palette`, `_mixing_palette`, `palette_vote`) under Icarus and Verilator.

The inputs are the run-time registers (palette colours, w_Y, the mixing tolerance, the background
entries, the switches), the background and the mixing table 1/|w|^2, which the core refreshes
with the model's `refresh_mixing` rule; each case draws them at random. Exhaustive where the
space is small: every value 0..255 of each colour channel of the event (the other two held),
under each of the four switch settings; random elsewhere: whole random events and registers,
and events placed on or near a background-to-entry segment, where the mixing rule decides.

Those cases rarely tell a mixing product that is one LSB off from a right one: the residual's
distance is floored by 2^-16 and compared with a tolerance in whole steps of 2^-F_w. So each
setting adds sensitive cases, an event and a tolerance each, searched for among thousands of
events (`sensitive_cases`): cases where one of the entries' products q (of dot and 1/|w|^2) and
q*w_Y, q*w_Cb, q*w_Cr, one LSB up or down, changes the class the mixing rule returns. The search
reimplements the rule in numpy only to find such cases; each case's expected class is still the
model's own, and the search's class must agree with it.

With STAGES = 2 (the core with update_delay = 2) each case goes through the pipeline register:
after an edge with `advance`, the event and the background move to another's, and the class and
vote read must still be the captured case's (stage 2 reads only its register and the run-time
registers); an edge without `advance` must keep them.

The cocotb test runs inside the simulator (configured by EVCLUST_TB); the pytest function builds
and launches it through `cocotb_tools.runner`, as tb/evclust_core/test_evclust_core.py.
"""

from __future__ import annotations

import json
import os
import random
from pathlib import Path

import pytest


try:
    import cocotb
    from cocotb.triggers import Timer

    from cosim import pipeline_edge
except ImportError:  # collected by pytest without cocotb: the pytest half still reports why
    cocotb = None

SETTINGS = 24  # random register settings; each runs the channel sweeps and the random events
# Icarus, about ten times slower on these sweeps, runs the first third of the same settings
# (the same seed), and Verilator all of them.
SETTINGS_ON = {"verilator": SETTINGS, "icarus": SETTINGS // 3}
RANDOM_EVENTS = 64
SWITCHES = ((0, 0), (0, 1), (1, 0), (1, 1))  # (mixing, vote_contrast)
CANDIDATES = 8000  # events searched a setting for sensitive cases
TERMS = ("q", "qw_y", "qw_cb", "qw_cr")  # the products a sensitive case is sensitive to


class Palette:
    """One random register setting and the model's view of it (k, G, palette, inv_ww, mask)."""

    def __init__(self, config: dict, rng: random.Random):
        import numpy as np

        from evclust.clusterer.layout import BG_CB, BG_CR, BG_Y
        from evclust.fixed import fixed_model as fm
        from evclust.fixed.constants import DTYPE
        from evclust.jit import named_record

        w = config["widths"]
        self.size = w["P"]
        self.k = named_record(DTYPE, config["k"])
        self.k.luma_weight = rng.randrange(1 << w["LUMA_BITS"])
        self.k.mixing_tolerance = rng.choice((0, rng.randrange(1 << w["TOL_BITS"]), (1 << w["TOL_BITS"]) - 1))
        self.palette = np.array([[rng.randrange(256) for _ in range(3)] for _ in range(self.size)], np.int64)
        if rng.random() < 0.3:  # equal entries: ties go to the lower index
            self.palette[rng.randrange(self.size)] = self.palette[rng.randrange(self.size)]
        self.mask = np.array([rng.random() < 0.25 for _ in range(self.size)], np.bool_)
        self.G = np.zeros(fm.N_GLOBALS, np.int64)
        bg_max = (255 << self.k.background_frac) | ((1 << self.k.background_frac) - 1)
        for column in (BG_Y, BG_CB, BG_CR):
            self.G[column] = rng.randrange(bg_max + 1)
        if rng.random() < 0.2:  # the background on an entry: |w|^2 = 0, whose 1/|w|^2 is 0
            j = rng.randrange(self.size)
            for column, channel in ((BG_Y, 0), (BG_CB, 1), (BG_CR, 2)):
                self.G[column] = int(self.palette[j, channel]) << self.k.background_frac
        self.inv_ww = np.zeros(self.size, np.int64)
        fm.refresh_mixing(self.G, self.palette, self.inv_ww, self.k)
        self.bg = tuple(int(self.G[c]) for c in (BG_Y, BG_CB, BG_CR))

    def expect(self, lum: int, cb: int, cr: int, mixing: int, vote_contrast: int) -> tuple[int, int]:
        from evclust.fixed import fixed_model as fm

        fb = int(self.k.background_frac)
        if mixing:
            bg = tuple(v >> fb for v in self.bg)
            c = fm._mixing_palette(lum, cb, cr, bg, self.palette, self.inv_ww, self.mask, self.k)
        else:
            c = fm._nearest_palette(lum, cb, cr, self.palette, self.k)
        self.k.vote_contrast = vote_contrast
        return int(c), int(fm.palette_vote(lum, cb, cr, self.G, self.k))

    def expect_at(self, lum: int, cb: int, cr: int, tolerance: int, vote_contrast: int) -> tuple[int, int]:
        """The model's (class, vote) under the mixing rule at another tolerance."""
        kept, self.k.mixing_tolerance = self.k.mixing_tolerance, tolerance
        try:
            return self.expect(lum, cb, cr, 1, vote_contrast)
        finally:
            self.k.mixing_tolerance = kept

    def classes(self, events, tolerance, nudge=None):
        """The mixing rule's class for each event (rows of `events`) at each tolerance, with one
        product of one entry moved by an LSB: nudge = (entry, term, +1 or -1). numpy, vectorised
        over the events, for the search only (`expect` is the model's)."""
        import numpy as np

        k = self.k
        fw, fq, lw = int(k.luma_weight_frac), int(k.mixing_q_frac), int(k.luma_weight)
        bg = np.array([v >> int(k.background_frac) for v in self.bg], np.int64)
        u = events - bg  # (M, 3)
        w = self.palette - bg  # (P, 3)
        d_end = lw * np.abs(events[:, None, 0] - self.palette[None, :, 0]) + (
            (np.abs(events[:, None, 1] - self.palette[None, :, 1]) + np.abs(events[:, None, 2] - self.palette[None, :, 2])) << fw
        )
        dot = u @ w.T  # (M, P)
        q = np.where(dot <= 0, 0, np.minimum((dot * self.inv_ww[None, :]) >> fq, 1 << fq))
        if nudge is not None and nudge[1] == "q":
            q[:, nudge[0]] += nudge[2]
        qw = q[:, :, None] * w[None, :, :]  # (M, P, 3)
        if nudge is not None and nudge[1] != "q":
            qw[:, nudge[0], TERMS.index(nudge[1]) - 1] += nudge[2]
        r = np.abs((u[:, None, :] << fq) - qw)
        d_line = np.where(self.mask[None, :], d_end, (lw * r[:, :, 0] + ((r[:, :, 1] + r[:, :, 2]) << fw)) >> fq)
        inside = d_line <= (np.asarray(tolerance, np.int64) << fw)[:, None]
        best = np.argmin(np.where(inside, d_end, np.int64(1) << 62), axis=1)  # the first of equals: the lower index
        return np.where(inside.any(axis=1), best, np.argmin(d_end, axis=1)), d_line

    def sensitive_cases(self, rng: random.Random, tol_bits: int):
        """(event, tolerance, nudge): for each entry the rule mixes (no background mask) and each
        term and sign, the first searched event with a tolerance at which that one-LSB change
        moves the class. The tolerance sits where the entry's distance and the nudged one fall
        on either side of it (d <= m * 2^F_w < d' or the other way)."""
        import numpy as np

        gen = np.random.default_rng(rng.randrange(1 << 32))
        events = gen.integers(0, 256, size=(CANDIDATES, 3), dtype=np.int64)
        fw = int(self.k.luma_weight_frac)
        top = (1 << tol_bits) - 1
        _, d = self.classes(events, np.zeros(CANDIDATES, np.int64))
        for j in range(self.size):
            if self.mask[j]:
                continue
            for term in TERMS:
                for sign in (1, -1):
                    _, d_nudged = self.classes(events, np.zeros(CANDIDATES, np.int64), (j, term, sign))
                    low, high = np.minimum(d[:, j], d_nudged[:, j]), np.maximum(d[:, j], d_nudged[:, j])
                    m = np.minimum(-((-low) >> fw), top)  # the least tolerance holding the lower one
                    straddled = (m << fw) < high
                    if not straddled.any():
                        continue
                    rows = np.flatnonzero(straddled)
                    plain, _ = self.classes(events[rows], m[rows])
                    moved, _ = self.classes(events[rows], m[rows], (j, term, sign))
                    for row in rows[plain != moved][:1]:
                        yield tuple(int(v) for v in events[row]), int(m[row]), (j, term, sign)

    def events(self, rng: random.Random):
        """Each channel swept over 0..255 with the others held, random events, events on segments."""
        held = [rng.randrange(256) for _ in range(3)]
        for channel in range(3):
            for value in range(256):
                colour = list(held)
                colour[channel] = value
                yield tuple(colour)
        for _ in range(RANDOM_EVENTS):
            yield tuple(rng.randrange(256) for _ in range(3))

        bg = [v >> int(self.k.background_frac) for v in self.bg]
        for _ in range(RANDOM_EVENTS):  # on a segment background -> entry, nudged
            j, q = rng.randrange(self.size), rng.random()
            yield tuple(min(255, max(0, round(b + q * (int(p) - b)) + rng.randint(-2, 2))) for b, p in zip(bg, self.palette[j]))


if cocotb is not None:

    @cocotb.test()
    async def palette_vectors(dut):
        """Every case through the combinational module; the first difference from the model fails."""
        config = json.loads(os.environ["EVCLUST_TB"])
        try:
            result = await _palette_vectors(dut, config)
        except Exception as exc:
            result = {"checked": 0, "classes": [], "error": f"{type(exc).__name__}: {exc}"}
        Path(config["out"]).write_text(json.dumps(result))
        assert result["error"] is None, result["error"]

    async def _palette_case(dut, rng, pal, lum, cb, cr, mixing, vote_contrast, pipelined, bg_max):
        """(class, vote) read for one event and switch setting; with STAGES = 2 read through the
        register while stage 1 has moved on (and sometimes an edge without advance)."""
        dut.lum.value, dut.cb.value, dut.cr.value = lum, cb, cr
        dut.mixing.value, dut.vote_contrast.value = mixing, vote_contrast
        await Timer(1, unit="ns")
        if pipelined:
            await pipeline_edge(dut, 1)  # stage 1 moves on to another event and background; stage 2 must not
            dut.lum.value, dut.cb.value, dut.cr.value = (rng.randrange(256) for _ in range(3))
            dut.bg_y.value, dut.bg_cb.value, dut.bg_cr.value = (rng.randrange(bg_max + 1) for _ in range(3))
            await Timer(1, unit="ns")
            if rng.random() < 0.1:
                await pipeline_edge(dut, 0)  # no advance: the register keeps its case
        got = (int(dut.class_index.value), int(dut.vote.value))
        if pipelined:
            dut.bg_y.value, dut.bg_cb.value, dut.bg_cr.value = pal.bg
        return got

    def _describe(pal, lum, cb, cr, mixing, vote_contrast, tolerance):
        return (f"event ({lum}, {cb}, {cr}), mixing={mixing}, vote_contrast={vote_contrast}, palette {pal.palette.tolist()}, "
                f"background {pal.bg}, mask {pal.mask.tolist()}, w_Y {pal.k.luma_weight}, tolerance {tolerance}")  # fmt: skip

    async def _palette_vectors(dut, config):
        import numpy as np

        rng = random.Random(config["seed"])
        error, checked, classes, sensitive = None, 0, set(), set()
        inv_bits, tol_bits = config["widths"]["INV_BITS"], config["widths"]["TOL_BITS"]
        pipelined = config["stages"] == 2
        bg_max = (1 << config["widths"]["BG_BITS"]) - 1

        dut.clk.value, dut.rst.value, dut.advance.value = 0, 0, 0
        for _ in range(config["settings"]):
            pal = Palette(config, rng)
            for port, channel in (("palette_y", 0), ("palette_cb", 1), ("palette_cr", 2)):
                getattr(dut, port).value = sum(int(pal.palette[j, channel]) << (8 * j) for j in range(pal.size))
            dut.inv_ww.value = sum(int(pal.inv_ww[j]) << (inv_bits * j) for j in range(pal.size))
            dut.background_mask.value = sum(int(pal.mask[j]) << j for j in range(pal.size))
            dut.bg_y.value, dut.bg_cb.value, dut.bg_cr.value = pal.bg

            dut.luma_weight.value = int(pal.k.luma_weight)
            dut.mixing_tolerance.value = int(pal.k.mixing_tolerance)
            for lum, cb, cr in pal.events(rng):
                for mixing, vote_contrast in SWITCHES:
                    got = await _palette_case(dut, rng, pal, lum, cb, cr, mixing, vote_contrast, pipelined, bg_max)
                    want = pal.expect(lum, cb, cr, mixing, vote_contrast)
                    checked += 1
                    classes.add((mixing, got[0]))
                    if got != want:
                        error = f"{_describe(pal, lum, cb, cr, mixing, vote_contrast, pal.k.mixing_tolerance)}: RTL (class, vote) {got}, model {want}"
                        break
                if error:
                    break
            if error:
                break
            # The cases one LSB of a mixing product decides, each at its own tolerance.
            for (lum, cb, cr), tolerance, (j, term, sign) in pal.sensitive_cases(rng, tol_bits):
                vote_contrast = rng.randrange(2)
                want = pal.expect_at(lum, cb, cr, tolerance, vote_contrast)
                searched = int(pal.classes(np.array([[lum, cb, cr]], np.int64), [tolerance])[0][0])
                if searched != want[0]:
                    error = (
                        f"{_describe(pal, lum, cb, cr, 1, vote_contrast, tolerance)}: the search's class {searched}, the model's {want[0]}"
                    )
                    break
                dut.mixing_tolerance.value = tolerance
                got = await _palette_case(dut, rng, pal, lum, cb, cr, 1, vote_contrast, pipelined, bg_max)
                sensitive.add((j, term, sign))
                if got != want:
                    error = (f"{_describe(pal, lum, cb, cr, 1, vote_contrast, tolerance)} (a case where {term} of entry {j} one LSB "
                             f"{'up' if sign > 0 else 'down'} moves the class): RTL (class, vote) {got}, model {want}")  # fmt: skip
                    break
            if error:
                break
        return {"checked": checked, "classes": sorted(classes), "sensitive": sorted(sensitive), "error": error}


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import PALETTE_SIMULATORS, configuration_params, cosim_share, run, selected_simulators  # noqa: E402

# Builds whose palette widths differ: the traffic preset (8 entries), and the defaults (every
# addition on, the mixing rule's formats) on a suite-sized sensor.
BUILDS = {"traffic": (480, 270, 50000.0), "defaults": (160, 120, 16666.0)}


def _width(constants: dict, name: str) -> int:
    """A constant's register width; 1 for one the parameter set leaves out (the header's rule)."""
    return constants[name].fmt.word_bits if name in constants else 1


def palette_build(name: str) -> tuple[str, dict, dict]:
    """(header, module parameters, cocotb configuration) of a build."""
    from evclust.fixed.constants import DTYPE
    from evclust.fixed.header import verilog_header
    from evclust.fixed.model import FixedClusterer

    width, height, t_frame = BUILDS[name]
    model = FixedClusterer(configuration_params(name, 16), width, height, t_frame)
    table = model.table
    size = table.palette_size
    c = table.constants
    widths = {"P": size, "CLASS_W": max(1, (size - 1).bit_length()), "BG_BITS": table["background"].word_bits,
              "INV_BITS": table["inv_ww"].word_bits, "VOTE_BITS": table["vote"].word_bits,
              "LUMA_BITS": _width(c, "luma_weight"), "TOL_BITS": _width(c, "mixing_tolerance")}  # fmt: skip
    return verilog_header(table), widths, {"widths": widths, "k": {name: int(model.k[name]) for name in DTYPE.names}}


# (build, STAGES, DSP_ENTRIES): the mixing products as shifted additions (0), in multiplier
# blocks for every entry (traffic: 8 of 8), and split (defaults: 3 of 7 in blocks, the rest
# added; the core takes 6 of 7). One case a simulator in `make test`, drawn from the commit hash
# for each (all of them under both in `make test-full`).
LEAF_CASES = [("traffic", 1, 0), ("defaults", 1, 0), ("defaults", 2, 0), ("traffic", 2, 8), ("defaults", 1, 3)]


@pytest.mark.rotating
@pytest.mark.parametrize(
    "sim, build, stages, dsp_entries",
    [(sim, *case) for sim in selected_simulators(PALETTE_SIMULATORS) for case in cosim_share(LEAF_CASES, 1, "palette", sim)],
)
def test_the_palette_class_and_vote_match_the_models_functions(sim, build, stages, dsp_entries):
    header, parameters, config = palette_build(build)
    settings = SETTINGS_ON[sim]
    result = run(sim, header, "palette_vectors", config | {"seed": 11, "stages": stages, "settings": settings},
                 toplevel="evclust_palette", parameters=parameters | {"STAGES": stages, "DSP_ENTRIES": dsp_entries})  # fmt: skip
    assert result["checked"] == settings * (3 * 256 + 2 * RANDOM_EVENTS) * len(SWITCHES)
    size = parameters["P"]
    # An LSB of every product moved a class somewhere, in both signs, for entries in multiplier
    # blocks and entries by addition alike (so a product one LSB off in either form fails).
    for term in TERMS:
        for sign in (1, -1):
            entries = {j for j, t, s in result["sensitive"] if t == term and s == sign}
            assert dsp_entries == 0 or any(j < dsp_entries for j in entries), (term, sign, sorted(entries))
            assert dsp_entries >= size or any(j >= dsp_entries for j in entries), (term, sign, sorted(entries))
    # Both rules chose every entry somewhere, so no class index went untested.
    assert {c for m, c in result["classes"] if m == 0} == set(range(size))
    assert {c for m, c in result["classes"] if m == 1} == set(range(size))
