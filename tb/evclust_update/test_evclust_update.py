"""evclust_update, step 3's read half, against the fixed model's `_increments` (each alpha
filter's increment from the slot the event reads) under Icarus and Verilator.

Random slots and events of two builds (the traffic preset and the defaults on a suite-sized
sensor): centres anywhere on the sensor and at its corners, sizes over [R_min, R_max], velocities
and weights over their whole formats, gamma up to its format's top (so gamma * step saturates to
V's format), colours over theirs. Half the cases use the build's constants, half random ones over
each register's width (the module's constants are run-time registers). Each case checks every
increment, every new value (the state read plus its increment, the size clamped) and the two
saturation counts the status counters add.

With STAGES = 2 (the core with update_delay = 2) the same cases go through the pipeline register:
each case's step saturations are read in its own cycle (stage 1); after an edge with `advance`,
the inputs move to another case's and the increments and MCM saturations read must still be the
captured case's (stage 2 reads only its register); an edge without `advance` must keep them.
"""

from __future__ import annotations

import random
from pathlib import Path

import numpy as np
import pytest


try:
    import cocotb

    from cosim import checked_vectors, header_width, leaf_model, pipeline_edge
    from cocotb.triggers import Timer
except ImportError:  # collected by pytest without cocotb: the pytest half still reports why
    cocotb = None

CASES = 3000
# The module's constant ports, named as the model's constants (k.<port>): (port, register width in the header).
CONSTANTS = (("beta_pos", "CFG_BETA_POS_W"), ("size_gain", "CFG_SIZE_GAIN_W"), ("beta_size", "CFG_BETA_SIZE_W"),
             ("r_min", "CFG_R_MIN_W"), ("r_max", "CFG_R_MAX_W"), ("beta_vel_mcm", "CFG_BETA_VEL_MCM_W"),
             ("beta_lum", "CFG_BETA_LUM_W"), ("beta_chro", "CFG_BETA_CHRO_W"))  # fmt: skip
# The slot fields the module reads: (port, layout column).
FIELDS = (("px", "PX"), ("py", "PY"), ("rx", "RX"), ("ry", "RY"), ("gamma", "GAMMA"), ("vmx", "VMX"), ("vmy", "VMY"),
          ("norm", "MCM_NORM"), ("col_y", "CY"), ("col_cb", "CCB"), ("col_cr", "CCR"))  # fmt: skip
# Its outputs: (increment port, new-value port, delay-line column, layout column).
OUTPUTS = (("d_px", "px_new", "PD_PX", "PX"), ("d_py", "py_new", "PD_PY", "PY"), ("d_rx", "rx_new", "PD_RX", "RX"),
           ("d_ry", "ry_new", "PD_RY", "RY"), ("d_vmx", "vmx_new", "PD_VMX", "VMX"), ("d_vmy", "vmy_new", "PD_VMY", "VMY"),
           ("d_norm", "norm_new", "PD_NORM", "MCM_NORM"), ("d_col_y", "col_y_new", "PD_CY", "CY"),
           ("d_col_cb", "col_cb_new", "PD_CCB", "CCB"), ("d_col_cr", "col_cr_new", "PD_CCR", "CCR"))  # fmt: skip


def cases(model, header: str, seed: int):
    """(k, S, slot, event) cases: the model's constant vector (the build's, or random registers),
    a random table and an event."""
    from evclust.clusterer import layout

    rng = random.Random(seed)
    t = model.table
    fp, fw = t["centre"].frac_bits, t["mcm_norm"].frac_bits
    width, height = t.width, t.height

    def pick(lo: int, hi: int) -> int:
        return rng.choice((lo, hi, rng.randrange(lo, hi + 1), rng.randrange(lo, hi + 1)))

    for n in range(CASES):
        k = model.k.copy()
        if n % 2:
            for name, register in CONSTANTS:
                k[name] = pick(0, (1 << header_width(header, register)) - 1)
            k.r_min, k.r_max = sorted((k.r_min, k.r_max))
        S = np.zeros((model.params.n_clusters, len(layout.SLOT_COLUMNS)), dtype=np.int64)
        s = rng.randrange(S.shape[0])
        S[s, layout.PX] = pick(0, (width - 1) << fp)
        S[s, layout.PY] = pick(0, (height - 1) << fp)
        S[s, layout.RX] = pick(int(k.r_min), int(k.r_max))
        S[s, layout.RY] = pick(int(k.r_min), int(k.r_max))
        S[s, layout.GAMMA] = pick(0, t["gamma"].raw_max)
        S[s, layout.VMX] = pick(t["v_mcm"].raw_min, t["v_mcm"].raw_max)
        S[s, layout.VMY] = pick(t["v_mcm"].raw_min, t["v_mcm"].raw_max)
        S[s, layout.MCM_NORM] = pick(0, 1 << fw)
        for column in (layout.CY, layout.CCB, layout.CCR):
            S[s, column] = pick(0, t["colour"].raw_max)
        event = (rng.randrange(width), rng.randrange(height), pick(0, 255), pick(0, 255), pick(0, 255))
        yield k, S, s, event


def model_update(model, k, S, s: int, event) -> dict:
    """The module's outputs as the model computes them: the increments `_increments` writes into
    the delay line, the new values they give, and the step and MCM saturations it counts."""
    from evclust.clusterer import layout
    from evclust.fixed import fixed_model

    x, y, lum, cb, cr = event
    row = np.zeros(len(layout.PENDING_COLUMNS), dtype=np.int64)
    log = np.zeros(len(fixed_model.SIGNALS), dtype=np.int64)
    G = model.globals.copy()
    fixed_model._increments(S, G, s, 0, x, y, lum, cb, cr, k, model.palette, model.inv_ww, model.background_mask, log, None, row)
    out = {"step_saturations": int(log[fixed_model.S_STEP]), "mcm_saturations": int(log[fixed_model.S_MCM_IN])}
    for increment, new, pd, column in OUTPUTS:
        d = int(row[getattr(layout, pd)])
        out[increment] = d
        out[new] = int(S[s, getattr(layout, column)]) + d
    for new in ("rx_new", "ry_new"):  # the size as written: clamped (the delayed commit clamps the sum)
        out[new] = min(max(out[new], int(k.r_min)), int(k.r_max))
    return out


if cocotb is not None:

    @cocotb.test()
    async def update_vectors(dut):
        await checked_vectors(dut, _update_vectors)

    async def _update_vectors(dut, config):
        from evclust.clusterer import layout

        model = leaf_model(config["build"])
        header = Path(config["header"]).read_text()
        signed = {"vmx", "vmy", "vmx_new", "vmy_new"} | {increment for increment, *_ in OUTPUTS}
        rng = random.Random(config["seed"])
        all_cases = list(cases(model, header, config["seed"]))
        pipelined = config["stages"] == 2
        stage2 = {"mcm_saturations"} | {increment for increment, *_ in OUTPUTS}

        def apply(k, S, s, event, constants=True):
            if constants:
                for port, _ in CONSTANTS:
                    getattr(dut, port).value = int(k[port])
            for port, column in FIELDS:
                getattr(dut, port).value = int(S[s, getattr(layout, column)]) & ((1 << len(getattr(dut, port))) - 1)
            for port, value in zip(("ev_x", "ev_y", "lum", "cb", "cr"), event):
                getattr(dut, port).value = value

        def read(names):
            return {name: getattr(dut, name).value.to_signed() if name in signed else int(getattr(dut, name).value) for name in names}

        def mismatch(S, s, event, got, want):
            diff = {name: (got[name], want[name]) for name in want if got[name] != want[name]}
            return f"slot {S[s].tolist()}, event {event}: (RTL, model) {diff}" if diff else None

        dut.clk.value, dut.advance.value = 0, 0
        checked = 0
        for k, S, s, event in all_cases:
            want = model_update(model, k, S, s, event)
            apply(k, S, s, event)
            await Timer(1, unit="ns")
            if not pipelined:
                error = mismatch(S, s, event, read(want), want)
            else:
                error = mismatch(S, s, event, read({"step_saturations"}), {"step_saturations": want["step_saturations"]})
                if error is None:
                    await pipeline_edge(dut, 1)
                    apply(*rng.choice(all_cases), constants=False)  # stage 1 moves on; stage 2 must not
                    await Timer(1, unit="ns")
                    error = mismatch(S, s, event, read(stage2), {name: want[name] for name in stage2})
                if error is None and rng.random() < 0.2:
                    await pipeline_edge(dut, 0)  # no advance: the register keeps its case
                    error = mismatch(S, s, event, read(stage2), {name: want[name] for name in stage2})
            checked += 1
            if error:
                return error, checked
        return None, checked


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import LEAF_SIMULATORS, cosim_share, header_width, leaf_model, run, selected_simulators  # noqa: E402

# One build a simulator in `make test`, drawn from the commit hash (all three in `make test-full`).
LEAF_CASES = [("traffic", 1), ("defaults", 1), ("defaults", 2)]


@pytest.mark.rotating
@pytest.mark.parametrize(
    "sim, build, stages",
    [(sim, *case) for sim in selected_simulators(LEAF_SIMULATORS) for case in cosim_share(LEAF_CASES, 1, "update", sim)],
)
def test_the_update_gives_the_models_increments_and_new_values(sim, build, stages):
    from evclust.fixed.header import verilog_header

    header = verilog_header(leaf_model(build).table)
    result = run(sim, header, "update_vectors", {"build": build, "seed": 11, "stages": stages}, toplevel="evclust_update",
                 parameters={"STAGES": stages})  # fmt: skip
    assert result["checked"] == CASES


def test_the_cases_saturate_and_clamp():
    """The cases reach what the module must get right at the edges: gamma * step saturated to V's
    format, the size clamped at R_min and at R_max, and increments of both signs."""
    from evclust.fixed.header import verilog_header

    model = leaf_model("traffic")
    header = verilog_header(model.table)
    outs = []
    for k, S, s, event in cases(model, header, 11):
        outs.append((model_update(model, k, S, s, event), int(k.r_min), int(k.r_max)))
    assert sum(o["mcm_saturations"] > 0 for o, _, _ in outs) > CASES // 50
    assert any(o["rx_new"] == lo and o["d_rx"] < 0 for o, lo, _ in outs)
    assert any(o["rx_new"] == hi and o["d_rx"] > 0 for o, _, hi in outs)
    assert any(o["d_px"] < 0 for o, _, _ in outs) and any(o["d_px"] > 0 for o, _, _ in outs)
