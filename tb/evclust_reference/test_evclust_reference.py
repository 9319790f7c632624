"""evclust_reference, the activity against a reference time's per-event unit, against the fixed
model's own functions (`_reference_span`, `_reference_passed`, `_weight`, and the steps and
residual `_move_reference` decays by) under Icarus and Verilator.

Exhaustive over the span: every whole step count from the reference (m = 0, the weight exactly 1)
through the headroom's top (m = 64 * REFERENCE_HALVINGS, the weight 2^REFERENCE_HALVINGS) to a
step past it, where the event must move the reference first; each with the reference's residual
0, the largest and a random one, so the boundary is met from both sides. Random elsewhere: the
times over all 32 bits (the clock wraps between the reference and the event), the residual and
1/T_half over their widths within the model's domain, and spans near the boundary.
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

RANDOM_CASES = 4000
PRODUCT_LIMIT_BITS = 62  # arith.decay's domain: dt * inv_t_half_raw + residual < 2^62
TIME_MASK = (1 << 32) - 1


def reference_cases(widths: dict, seed: int):
    """(t, t_ref, residual, inv_t_half) inputs: the sweep over step counts, then random ones."""
    from evclust.clusterer.params import REFERENCE_HALVINGS
    from evclust.fixed.formats import DECAY_TABLE_BITS

    rng = random.Random(seed)
    drop = widths["INV_T_HALF_FRAC"] - DECAY_TABLE_BITS
    residual_max = (1 << widths["DECAY_RESIDUAL_W"]) - 1
    top = REFERENCE_HALVINGS << DECAY_TABLE_BITS
    one_step = 1 << drop  # inv_t_half = 2^DROP: each µs one step exactly
    for m in range(top + 2):
        t_ref = rng.randrange(1 << 32)
        for residual in (0, residual_max, rng.randrange(residual_max + 1)):
            yield (t_ref + m) & TIME_MASK, t_ref, residual, one_step
    # Within the model's domain, (2^32 - 1)·(1/T_half) + residual < 2^62 (arith.decay's).
    inv_max = (1 << min(widths["INV_T_HALF_W"], PRODUCT_LIMIT_BITS - 32 - 1)) - 1
    for _ in range(RANDOM_CASES):
        inv = rng.choice((widths["inv_t_half"], rng.randrange(1, inv_max + 1)))
        t_ref = rng.randrange(1 << 32)
        # Spans around the boundary of REFERENCE_HALVINGS half-lives, and over the whole clock.
        boundary_dt = (REFERENCE_HALVINGS << widths["INV_T_HALF_FRAC"]) // inv
        dt = rng.choice((rng.randrange(max(boundary_dt, 1) + 2), boundary_dt + rng.randrange(-2, 3), rng.randrange(1 << 32)))
        yield (t_ref + max(dt, 0)) & TIME_MASK, t_ref, rng.randrange(residual_max + 1), inv


def model_reference(model: dict, t: int, t_ref: int, residual: int, inv: int) -> tuple[int, int, int, int]:
    """(steps, residual out, passed, weight) as the fixed model computes them for an event at t
    (the weight only where the reference need not move first: 0 otherwise)."""
    from evclust.clusterer.layout import BG_RESIDUAL, BG_T
    from evclust.fixed.arith import decay_steps
    from evclust.fixed.fixed_model import N_GLOBALS, _reference_passed, _reference_span, _weight
    from evclust.fixed.formats import DECAY_TABLE_BITS

    k = model["k"].copy()
    k.inv_t_half = inv
    G = np.zeros(N_GLOBALS, np.int64)
    G[BG_T], G[BG_RESIDUAL] = t_ref, residual
    passed = bool(_reference_passed(G, t, k))
    steps, residual_out = decay_steps((t - t_ref) & TIME_MASK, residual, inv, int(k.inv_t_half_frac), DECAY_TABLE_BITS)  # _move_reference's
    assert steps == int(_reference_span(G, t, k)) >> (int(k.inv_t_half_frac) - DECAY_TABLE_BITS)
    weight = 0 if passed else int(_weight(G, t, k, model["table"]))
    return steps, residual_out, int(passed), weight


if cocotb is not None:

    @cocotb.test()
    async def reference_vectors(dut):
        """Every case through the combinational module; the first difference from the model fails."""
        await checked_vectors(dut, _reference_vectors)

    async def _reference_vectors(dut, config):
        model = reference_model(config["build"])
        error, checked = None, 0
        for t, t_ref, residual, inv in reference_cases(model["widths"], config["seed"]):
            dut.t.value, dut.t_ref.value, dut.residual.value, dut.inv_t_half.value = t, t_ref, residual, inv
            await Timer(1, unit="ns")
            want = model_reference(model, t, t_ref, residual, inv)
            passed = int(dut.passed.value)
            got = (int(dut.steps.value), int(dut.residual_out.value), passed, 0 if passed else int(dut.weight.value))
            checked += 1
            if got != want:
                error = (
                    f"t={t} t_ref={t_ref} residual={residual} inv_t_half={inv}: RTL (steps, residual, passed, weight) {got}, model {want}"
                )
                break
        return error, checked


# ------------------------------------------------------------------------------------------
# pytest: build, launch, check.

from cosim import LEAF_SIMULATORS, configuration_params, run, selected_simulators  # noqa: E402

# Two builds whose widths and 1/T_half differ: the defaults on the traffic sensor and the small one.
BUILDS = {"defaults": (480, 270, 50000.0), "small": (64, 48, 10000.0)}


def reference_build(name: str):
    """(header, parameters, table) of a build with the mode on."""
    from evclust.fixed.formats import build_formats
    from evclust.fixed.header import verilog_header

    width, height, t_frame = BUILDS[name]
    params = configuration_params(name, 16).model_copy(update={"activity_reference": True})
    table = build_formats(params, width, height, t_frame)
    return verilog_header(table), params.resolved(t_frame), table


def reference_model(name: str) -> dict:
    """The fixed model's constants and decay table for a build, and the widths the cases need."""
    from evclust.fixed.arith import decay_table
    from evclust.fixed.constants import constant_vector
    from evclust.fixed.formats import DECAY_FRAC_BITS, DECAY_TABLE_BITS

    _, params, table = reference_build(name)
    k = constant_vector(table, params, True)
    widths = {"INV_T_HALF_W": table.constants["inv_t_half"].fmt.word_bits, "INV_T_HALF_FRAC": int(k.inv_t_half_frac),
              "DECAY_RESIDUAL_W": table["decay_residual"].word_bits, "inv_t_half": int(k.inv_t_half)}  # fmt: skip
    return {"k": k, "table": decay_table(DECAY_TABLE_BITS, DECAY_FRAC_BITS), "widths": widths}


def weight_bits(name: str) -> int:
    from evclust.clusterer.params import REFERENCE_HALVINGS

    return reference_build(name)[2]["activity"].word_bits + REFERENCE_HALVINGS


@pytest.mark.parametrize("build", sorted(BUILDS))
@pytest.mark.parametrize("sim", selected_simulators(LEAF_SIMULATORS))
def test_the_reference_unit_matches_the_models_functions_over_every_step_count_and_random_inputs(sim, build):
    from evclust.clusterer.params import REFERENCE_HALVINGS
    from evclust.fixed.formats import DECAY_TABLE_BITS

    header = reference_build(build)[0]
    result = run(sim, header, "reference_vectors", {"build": build, "seed": 11}, toplevel="evclust_reference",
                 parameters={"WEIGHT_BITS": weight_bits(build)})  # fmt: skip
    assert result["checked"] == 3 * ((REFERENCE_HALVINGS << DECAY_TABLE_BITS) + 2) + RANDOM_CASES


def test_the_sweep_meets_the_weights_known_values_and_the_boundary_from_both_sides():
    """The cases' own coverage, independent of the simulator: the weight is exactly 1.0 at the
    reference and 2^h after h whole half-lives; the sweep's last step counts pass the headroom
    and the one before does not; the random cases hold both sides of the boundary too."""
    from evclust.clusterer.params import REFERENCE_HALVINGS
    from evclust.fixed.formats import DECAY_TABLE_BITS

    model = reference_model("defaults")
    one = 1 << int(model["k"].activity_frac)
    inv = 1 << (model["widths"]["INV_T_HALF_FRAC"] - DECAY_TABLE_BITS)
    for h in range(REFERENCE_HALVINGS + 1):
        assert model_reference(model, (1000 + (h << DECAY_TABLE_BITS)) & TIME_MASK, 1000, 0, inv)[2:] == (0, one << h)
    top = REFERENCE_HALVINGS << DECAY_TABLE_BITS
    assert model_reference(model, 1000 + top, 1000, 0, inv)[2] == 0  # exactly at the top: no move
    assert model_reference(model, 1000 + top, 1000, 1, inv)[2] == 1  # the residual's one LSB past it: a move
    cases = list(reference_cases(model["widths"], 11))
    passed = [model_reference(model, *case)[2] for case in cases[3 * (top + 2) :]]
    assert 0.05 < sum(passed) / len(passed) < 0.95
