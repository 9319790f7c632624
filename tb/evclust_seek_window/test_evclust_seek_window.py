"""evclust_seek_window, one axis of a slot's seek window, under Icarus and Verilator against its
definition (tb/seek_builds.py: `window`), and the definition itself against what the seek needs
at every pixel: lo <= x <= hi exactly when |x * 2^F_P - P| <= R (the model's `_seek` hit), and
the key's distance, {x - up, nf} or {floor(P / 2^F_P) - x, P mod 2^F_P}, equal to |x * 2^F_P - P|.

Random centres and reaches over their whole words and small reaches near the centre, and the
edges: a centre at 0 and at its largest word, a zero reach, a reach past either end of the
sensor, P - R and P + R exactly on a pixel and one LSB either side of it, a centre on a pixel
(nf = 0). The seek's two builds (the scaled seek's reach is the widest).
"""

from __future__ import annotations

import random

import numpy as np
import pytest

try:
    import cocotb

    from cosim import checked_vectors
    from cocotb.triggers import Timer
except ImportError:  # collected by pytest without cocotb: the pytest half still reports why
    cocotb = None

from seek_builds import BUILDS, widths, window

CASES = 3000


def cases(xy_w: int, centre_w: int, reach_w: int, fp: int, seed: int):
    """(centre, reach) pairs: random over the words, near the sensor, and on the edges."""
    rng = random.Random(seed)
    top_centre, top_reach = (1 << centre_w) - 1, (1 << reach_w) - 1
    pixel = 1 << fp
    for i in range(CASES):
        kind = i % 5
        if kind == 0:  # anywhere in either word
            centre, reach = rng.randrange(top_centre + 1), rng.randrange(top_reach + 1)
        elif kind == 1:  # a small reach, as slots have
            centre, reach = rng.randrange(top_centre + 1), rng.randrange(40 * pixel)
        elif kind == 2:  # the word's ends
            centre = rng.choice((0, top_centre, rng.randrange(4) * pixel, top_centre - rng.randrange(4)))
            reach = rng.choice((0, top_reach, rng.randrange(8 * pixel), 1))
        else:  # P - R (kind 3) or P + R (kind 4) on a pixel, or one LSB either side
            centre = rng.randrange(top_centre + 1)
            if rng.random() < 0.3:
                centre &= ~(pixel - 1)  # on a pixel: nf = 0
            edge = rng.randrange(1 << xy_w) * pixel + rng.choice((-1, 0, 1))
            reach = max(0, min(top_reach, centre - edge if kind == 3 else edge - centre))
        yield centre, reach


if cocotb is not None:

    @cocotb.test()
    async def seek_window_vectors(dut):
        await checked_vectors(dut, _seek_window_vectors)

    async def _seek_window_vectors(dut, config):
        xy_w, centre_w, reach_w, fp = config["xy_w"], config["centre_w"], config["reach_w"], config["fp"]
        checked = 0
        for centre, reach in cases(xy_w, centre_w, reach_w, fp, config["seed"]):
            dut.centre.value, dut.reach.value = centre, reach
            await Timer(1, unit="ns")
            got, want = int(dut.window.value), window(centre, reach, xy_w, centre_w, fp)
            checked += 1
            if got != want:
                return f"centre {centre:#x}, reach {reach:#x}: RTL window {got:#x}, definition {want:#x}", checked
        return None, checked


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import LEAF_SIMULATORS, run, selected_simulators  # noqa: E402


def _fp(build: str) -> int:
    from seek_builds import model_for

    return model_for(build)[0].table["centre"].frac_bits


@pytest.mark.parametrize("build", sorted(BUILDS))
@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_the_window_is_its_definition(sim, build):
    w = widths(build)
    parameters = {"XY_BITS": w["xy_w"], "CENTRE_BITS": w["centre_w"], "REACH_BITS": w["reach_w"], "WINDOW_BITS": w["window_w"]}
    header = w.pop("header")
    result = run(sim, header, "seek_window_vectors", {"build": build, "seed": 11, "fp": _fp(build)} | w,
                 toplevel="evclust_seek_window", parameters=parameters)  # fmt: skip
    assert result["checked"] == CASES


@pytest.mark.parametrize("build", sorted(BUILDS))
def test_the_definition_gives_the_hit_and_the_distance_at_every_pixel(build):
    """The window's fields unpacked and tested at every coordinate x of the event word: the hit
    and the distance the key computes from them equal |x * 2^F_P - P| <= R and |x * 2^F_P - P|."""
    w = widths(build)
    xy_w, centre_w, fp = w["xy_w"], w["centre_w"], _fp(build)
    lo_w = centre_w - fp + 1
    x = np.arange(1 << xy_w, dtype=np.int64)
    hits = 0
    for centre, reach in cases(xy_w, centre_w, w["reach_w"], fp, 11):
        packed = window(centre, reach, xy_w, centre_w, fp)
        nf = packed & ((1 << fp) - 1)
        up = (packed >> fp) & ((1 << lo_w) - 1)
        hi = (packed >> (fp + lo_w)) & ((1 << xy_w) - 1)
        lo = packed >> (fp + lo_w + xy_w)
        assert lo < 1 << lo_w
        gap = np.abs((x << fp) - centre)
        np.testing.assert_array_equal((lo <= x) & (x <= hi), gap <= reach, err_msg=f"hit, P {centre:#x}, R {reach:#x}")
        distance = np.where(x >= up, ((x - up) << fp) + nf, (((centre >> fp) - x) << fp) + (centre & ((1 << fp) - 1)))
        np.testing.assert_array_equal(distance, gap, err_msg=f"distance, P {centre:#x}")
        hits += int((gap <= reach).sum())
    assert 0 < hits < CASES << xy_w
