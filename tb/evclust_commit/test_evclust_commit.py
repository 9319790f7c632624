"""evclust_commit, step 3's write half, against the fixed model's `_commit` (an update's
increments added to the slot as it is now, each sum saturated to its format; the activity plus
one; the palette vote; the event count) under Icarus and Verilator.

Random slots and updates of two builds (the traffic preset and the defaults on a suite-sized
sensor): every field over its whole format, increments over their whole widths (so every sum
can leave its format at both ends: what a delayed commit saturates), activities, counters and
histogram entries at and near their tops (the saturations and the histogram's halving), votes
over their width. The activity the module takes is decayed to the update's time by the model's
`_decay_slot` (evclust_decay's own bench checks that unit). Each case checks every field the
commit writes and the three saturation counts the status counters add.
"""

from __future__ import annotations

import random
from pathlib import Path

import numpy as np
import pytest


try:
    import cocotb

    from cosim import checked_vectors, header_width, leaf_model
    from cocotb.triggers import Timer
except ImportError:  # collected by pytest without cocotb: the pytest half still reports why
    cocotb = None

CASES = 3000
# The fields the commit adds to: (state port, increment port, output port, layout column,
# delay-line column, increment width name in the header).
SUMS = (("px", "d_px", "px_out", "PX", "PD_PX", "CENTRE_W"), ("py", "d_py", "py_out", "PY", "PD_PY", "CENTRE_W"),
        ("rx", "d_rx", "rx_out", "RX", "PD_RX", None), ("ry", "d_ry", "ry_out", "RY", "PD_RY", None),
        ("vmx", "d_vmx", "vmx_out", "VMX", "PD_VMX", "V_MCM_W"), ("vmy", "d_vmy", "vmy_out", "VMY", "PD_VMY", "V_MCM_W"),
        ("norm", "d_norm", "norm_out", "MCM_NORM", "PD_NORM", "MCM_NORM_W"),
        ("col_y", "d_col_y", "col_y_out", "CY", "PD_CY", "COLOUR_W"), ("col_cb", "d_col_cb", "col_cb_out", "CCB", "PD_CCB", "COLOUR_W"),
        ("col_cr", "d_col_cr", "col_cr_out", "CCR", "PD_CCR", "COLOUR_W"))  # fmt: skip
SIGNED = {"vmx", "vmy", "vmx_out", "vmy_out"} | {increment for _, increment, *_ in SUMS}


def increment_bits(header: str, width: str | None) -> int:
    """An increment's width as evclust_increments.vh declares it: its field's and a sign (the
    size's: the wider of size_target and the half-size)."""
    if width is None:
        return max(header_width(header, "SIZE_TARGET_W"), header_width(header, "HALF_SIZE_W")) + 1
    return header_width(header, width) + 1


def cases(model, header: str, seed: int):
    """(S, H, row) cases: a slot as it is now and a live update of it."""
    from evclust.clusterer import layout

    rng = random.Random(seed)
    t, k = model.table, model.k

    def pick(lo: int, hi: int) -> int:
        return rng.choice((lo, hi, rng.randrange(lo, hi + 1), rng.randrange(lo, hi + 1)))

    tops = {"PX": t["centre"].raw_max, "PY": t["centre"].raw_max, "RX": int(k.r_max), "RY": int(k.r_max),
            "MCM_NORM": 1 << t["mcm_norm"].frac_bits, "CY": t["colour"].raw_max, "CCB": t["colour"].raw_max, "CCR": t["colour"].raw_max}  # fmt: skip
    hist_top = (1 << t["hist"].word_bits) - 1
    for _ in range(CASES):
        S = np.zeros((model.params.n_clusters, len(layout.SLOT_COLUMNS)), dtype=np.int64)
        H = np.zeros((model.params.n_clusters, len(model.params.palette)), dtype=np.int64)
        s = rng.randrange(S.shape[0])
        for column, top in tops.items():
            S[s, getattr(layout, column)] = pick(int(k.r_min) if column in ("RX", "RY") else 0, top)
        S[s, layout.VMX] = pick(t["v_mcm"].raw_min, t["v_mcm"].raw_max)
        S[s, layout.VMY] = pick(t["v_mcm"].raw_min, t["v_mcm"].raw_max)
        S[s, layout.ACT] = pick(0, t["activity"].raw_max)
        S[s, layout.EV_COUNT] = pick(0, t["events_in_interval"].raw_max)
        S[s, layout.T_LAST] = rng.randrange(1 << 32)
        S[s, layout.DECAY_RESIDUAL] = rng.randrange(1 << t["decay_residual"].word_bits)
        H[s] = [pick(0, hist_top) for _ in range(H.shape[1])]
        row = np.zeros(len(layout.PENDING_COLUMNS), dtype=np.int64)
        row[layout.PD_LIVE], row[layout.PD_SLOT] = 1, s
        # Mostly short times (little decay), some long.
        row[layout.PD_T] = (int(S[s, layout.T_LAST]) + rng.choice((0, rng.randrange(100), rng.randrange(1 << 32)))) & 0xFFFFFFFF
        for _, _, _, _, pd, width in SUMS:
            bits = increment_bits(header, width)
            row[getattr(layout, pd)] = pick(-(1 << (bits - 1)), (1 << (bits - 1)) - 1)
        row[layout.PD_CLASS] = rng.randrange(H.shape[1])
        row[layout.PD_VOTE] = pick(0, (1 << header_width(header, "VOTE_W")) - 1)
        yield S, H, row


def model_commit(model, S, H, row) -> tuple[dict, int]:
    """(the module's outputs as `_commit` computes them, the activity decayed to the update's time)."""
    from evclust.clusterer import layout
    from evclust.fixed import fixed_model

    s = int(row[layout.PD_SLOT])
    decayed = S.copy()
    fixed_model._decay_slot(decayed, s, int(row[layout.PD_T]), model.k, model.decay)
    after, hist = S.copy(), H.copy()
    log = np.zeros(len(fixed_model.SIGNALS), dtype=np.int64)
    fixed_model._commit(after, hist, model.globals.copy(), row.copy(), model.k, model.decay, log, None)
    out = {port: int(after[s, getattr(layout, column)]) for _, _, port, column, _, _ in SUMS}
    out |= {"act_out": int(after[s, layout.ACT]), "ev_count_out": int(after[s, layout.EV_COUNT]),
            "hist_out": sum(int(v) << (j * model.table["hist"].word_bits) for j, v in enumerate(hist[s])),
            "act_saturations": int(log[fixed_model.S_ACT]), "vm_saturations": int(log[fixed_model.S_VM]),
            "ev_count_saturations": int(log[fixed_model.S_EVCOUNT])}  # fmt: skip
    return out, int(decayed[s, layout.ACT])


if cocotb is not None:

    @cocotb.test()
    async def commit_vectors(dut):
        await checked_vectors(dut, _commit_vectors)

    async def _commit_vectors(dut, config):
        from evclust.clusterer import layout

        model = leaf_model(config["build"])
        header = Path(config["header"]).read_text()
        hist_bits = model.table["hist"].word_bits
        dut.r_min.value = int(model.k.r_min)
        dut.r_max.value = int(model.k.r_max)
        checked = 0
        for S, H, row in cases(model, header, config["seed"]):
            s = int(row[layout.PD_SLOT])
            want, decayed = model_commit(model, S, H, row)
            dut.act_decayed.value = decayed
            for port, increment, _, column, pd, _ in SUMS:
                getattr(dut, port).value = int(S[s, getattr(layout, column)]) & ((1 << len(getattr(dut, port))) - 1)
                getattr(dut, increment).value = int(row[getattr(layout, pd)]) & ((1 << len(getattr(dut, increment))) - 1)
            dut.hist.value = sum(int(v) << (j * hist_bits) for j, v in enumerate(H[s]))
            dut.ev_count.value = int(S[s, layout.EV_COUNT])
            dut.class_index.value = int(row[layout.PD_CLASS])
            dut.vote.value = int(row[layout.PD_VOTE])
            await Timer(1, unit="ns")
            got = {name: getattr(dut, name).value.to_signed() if name in SIGNED else int(getattr(dut, name).value) for name in want}
            checked += 1
            if got != want:
                diff = {name: (got[name], want[name]) for name in want if got[name] != want[name]}
                return f"slot {S[s].tolist()}, histogram {H[s].tolist()}, update {row.tolist()}: (RTL, model) {diff}", checked
        return None, checked


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import LEAF_BUILDS, LEAF_SIMULATORS, header_width, leaf_model, run, selected_simulators  # noqa: E402


@pytest.mark.parametrize("build", sorted(LEAF_BUILDS))
@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_the_commit_lands_an_update_as_the_model_does(sim, build):
    from evclust.fixed.header import verilog_header

    header = verilog_header(leaf_model(build).table)
    result = run(sim, header, "commit_vectors", {"build": build, "seed": 13}, toplevel="evclust_commit")
    assert result["checked"] == CASES


def test_the_cases_reach_every_saturation_and_the_halving():
    """Each sum leaves its format at the bottom and at the top in some case, the activity and the
    event count saturate, and the histogram halves."""
    from evclust.clusterer import layout
    from evclust.fixed.header import verilog_header

    model = leaf_model("traffic")
    header = verilog_header(model.table)
    outs, low, high, halved = [], set(), set(), 0
    hist_top = (1 << model.table["hist"].word_bits) - 1
    for S, H, row in cases(model, header, 13):
        want, _ = model_commit(model, S, H, row)
        outs.append(want)
        s = int(row[layout.PD_SLOT])
        for _, _, port, column, pd, _ in SUMS:
            total = int(S[s, getattr(layout, column)]) + int(row[getattr(layout, pd)])
            if want[port] > total:
                low.add(port)
            elif want[port] < total:
                high.add(port)
        halved += int(H[s, int(row[layout.PD_CLASS])] + row[layout.PD_VOTE] >= hist_top)
    ports = {port for _, _, port, *_ in SUMS}
    assert low == ports and high == ports
    assert any(o["act_saturations"] for o in outs) and any(o["ev_count_saturations"] for o in outs)
    assert sum(o["vm_saturations"] for o in outs) > CASES // 50
    assert CASES // 20 < halved < CASES - CASES // 20
