"""evclust_merge_search, the filter step's merge search, against the fixed model's `_mergeable`
(the lowest live slot j > k that slot k absorbs, as the model's sweep tries them), under Icarus
and Verilator.

Random tables of the defaults' formats (merging on): boxes overlapping, touching, grown into
reach and apart; interval velocities agreeing and not, measured (two measurements or more) and
not; free slots; every k. The products each slot brings, merge_scale * max(Rx, Ry) and
merge_v_rel * (|Vx| + |Vy|), are made from the model's constants as the core makes them when it
writes a slot.
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

TABLES = 600
WIDTH, HEIGHT, T_FRAME = 160, 120, 16666.0


def make_model(n: int):
    from evclust.clusterer import ClustererParams
    from evclust.fixed.model import FixedClusterer

    return FixedClusterer(ClustererParams(n_clusters=n), WIDTH, HEIGHT, T_FRAME)


def tables(model, seed: int):
    """(k, S) pairs: clusters in a few groups, so that boxes overlap, touch or lie apart."""
    from evclust.clusterer.layout import PX, PY, RX, RY, SLOT_COLUMNS, VALID, VI_COUNT, VIX, VIY

    rng = random.Random(seed)
    t = model.table
    fp, fr, fi = t["centre"].frac_bits, t["half_size"].frac_bits, t["v_int"].frac_bits
    v_max = (1 << (t["v_int"].word_bits - 1)) - 1
    n = model.params.n_clusters
    for _ in range(TABLES):
        S = np.zeros((n, len(SLOT_COLUMNS)), dtype=np.int64)
        groups = [(rng.randrange(WIDTH) << fp, rng.randrange(HEIGHT) << fp, rng.randrange(-3 << fi, 3 << fi), rng.randrange(-3 << fi, 3 << fi))
                  for _ in range(rng.randrange(1, 4))]  # fmt: skip
        for s in range(n):
            gx, gy, gvx, gvy = rng.choice(groups)
            S[s, VALID] = rng.random() < 0.85
            S[s, PX] = min(max(0, gx + rng.randrange(-25 << fp, 25 << fp)), (WIDTH - 1) << fp)
            S[s, PY] = min(max(0, gy + rng.randrange(-25 << fp, 25 << fp)), (HEIGHT - 1) << fp)
            S[s, RX] = rng.randrange(1 << fr, 20 << fr)
            S[s, RY] = rng.randrange(1 << fr, 20 << fr)
            wild = rng.random() < 0.1
            S[s, VIX] = rng.randrange(-v_max, v_max) if wild else gvx + rng.randrange(-1 << fi, 1 << fi)
            S[s, VIY] = rng.randrange(-v_max, v_max) if wild else gvy + rng.randrange(-1 << fi, 1 << fi)
            S[s, VI_COUNT] = rng.randrange(4)
        yield rng.randrange(n), S


def model_search(model, k: int, S) -> int:
    """The lowest j > k that the model's sweep would have slot k absorb, or -1."""
    from evclust.clusterer.layout import VALID
    from evclust.fixed import fixed_model

    for j in range(k + 1, S.shape[0]):
        if S[j, VALID] != 0 and fixed_model._mergeable(S, k, j, model.k):
            return j
    return -1


def products(model, S) -> tuple[list[int], list[int]]:
    """merge_scale * max(Rx, Ry) and merge_v_rel * (|Vx| + |Vy|) per slot, as the core writes them."""
    from evclust.clusterer.layout import RX, RY, VIX, VIY

    scale, rel = model.table.constants["merge_scale"].raw, model.table.constants["merge_v_rel"].raw
    return ([scale * int(max(S[s, RX], S[s, RY])) for s in range(S.shape[0])],
            [rel * int(abs(S[s, VIX]) + abs(S[s, VIY])) for s in range(S.shape[0])])  # fmt: skip


if cocotb is not None:

    @cocotb.test()
    async def merge_search_vectors(dut):
        await checked_vectors(dut, _merge_search_vectors)

    async def _merge_search_vectors(dut, config):
        from evclust.clusterer.layout import PX, PY, RX, RY, VALID, VI_COUNT, VIX, VIY

        model = make_model(config["n"])
        w = config["widths"]
        checked = 0

        def bus(values, bits):
            return sum((int(v) & ((1 << bits) - 1)) << (i * bits) for i, v in enumerate(values))

        dut.v_tol.value = model.table.constants["merge_v_tol"].raw
        for k, S in tables(model, config["seed"]):
            grow, vrel = products(model, S)
            dut.k.value = k
            dut.valid.value = bus(S[:, VALID], 1)
            dut.centre_x.value, dut.centre_y.value = bus(S[:, PX], w["centre"]), bus(S[:, PY], w["centre"])
            dut.half_x.value, dut.half_y.value = bus(S[:, RX], w["half"]), bus(S[:, RY], w["half"])
            dut.v_x.value, dut.v_y.value = bus(S[:, VIX], w["v"]), bus(S[:, VIY], w["v"])
            dut.measured.value = bus(S[:, VI_COUNT], w["count"])
            dut.grow.value, dut.vrel.value = bus(grow, w["grow"]), bus(vrel, w["vrel"])
            await Timer(1, unit="ns")
            got = int(dut.j.value) if int(dut.found.value) else -1
            want = model_search(model, k, S)
            checked += 1
            if got != want:
                return f"k = {k}: RTL j = {got}, model j = {want}; table {S.tolist()}", checked
        return None, checked


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import LEAF_SIMULATORS, run, selected_simulators  # noqa: E402


def widths(model) -> dict:
    """The core's widths: GROW_W and VREL_W as evclust_core computes them."""
    t, c = model.table, model.table.constants
    return {"centre": t["centre"].word_bits, "half": t["half_size"].word_bits, "v": t["v_int"].word_bits,
            "count": t["interval_updates"].word_bits, "v_tol": c["merge_v_tol"].fmt.word_bits,
            "grow": c["merge_scale"].fmt.word_bits + t["half_size"].word_bits,
            "vrel": c["merge_v_rel"].fmt.word_bits + t["v_int"].word_bits + 1}  # fmt: skip


@pytest.mark.parametrize("n", [4, 16])
@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_the_search_finds_the_lowest_slot_the_model_merges(sim, n):
    from evclust.rtl.sources import params_header
    from evclust.clusterer import ClustererParams

    model = make_model(n)
    w = widths(model)
    header = params_header(ClustererParams(n_clusters=n), WIDTH, HEIGHT, T_FRAME)
    parameters = {"N": n, "SLOT_BITS": max(1, (n - 1).bit_length()), "CENTRE_BITS": w["centre"], "HALF_BITS": w["half"], "V_BITS": w["v"],
                  "COUNT_BITS": w["count"], "V_TOL_BITS": w["v_tol"], "GROW_BITS": w["grow"], "VREL_BITS": w["vrel"]}  # fmt: skip
    result = run(
        sim, header, "merge_search_vectors", {"n": n, "seed": n, "widths": w}, toplevel="evclust_merge_search", parameters=parameters
    )
    assert result["checked"] == TABLES


def test_the_tables_merge_and_do_not():
    """The generated tables give merges by overlap, by grown reach with agreeing velocities, and none."""
    model = make_model(16)
    found = [model_search(model, k, S) for k, S in tables(model, 16)]
    assert sum(j >= 0 for j in found) > TABLES // 5 and sum(j < 0 for j in found) > TABLES // 5
