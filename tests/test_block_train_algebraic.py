"""A block train without coordinates takes one internal step a communication step.

The riser tensioner's rope (every body driven, sheaves massless) is algebraic in its
held inputs; its only states are the energy ledgers, and their powers are quadratic
in time over a step (the ring moving at a constant rate, the rope's damper force
constant), so Simpson's rule -- one RK4 step -- closes the ledger to round-off however
long the step.
"""

from __future__ import annotations

import pytest

from wire_fmu.core.units.block_train.reevings import drilling_block_train, riser_tensioner

from .block_train_helpers import make_unit


def riser_rope(max_step: float):
    unit = make_unit(
        riser_tensioner(),
        "rope_damping",
        initial_equilibrium=False,
        pretension=356.0e3,
        solver="rk4",
        solver_max_step=max_step,
    )
    unit.values["mover_b.velocity"] = 0.5  # m/s, the ring moving
    return unit


def test_no_coordinates_one_internal_step_whatever_the_max_step():
    unit = riser_rope(1e-4)
    assert unit.model.n_coords == 0
    assert unit.model.solver.internal_count(0.0, 0.01) == 1
    with_block = make_unit(drilling_block_train(4), "", solver="rk4", solver_max_step=1e-4)
    assert with_block.model.solver.internal_count(0.0, 0.01) == 100  # dynamic: as asked


@pytest.mark.parametrize("step", [1e-3, 0.02])
def test_its_ledger_closes_over_long_steps(step):
    """Stored energy, dissipation in the rope's damper and the ring's work balance,
    with one internal step of 1 ms or of 20 ms."""
    unit = riser_rope(1e-3)
    t = 0.0
    for _ in range(10):
        assert unit.advance(t, step).success
        t += step
    values = unit.values
    assert values["dissipated_energy"] > 0.0 and abs(values["external_work"]) > 100.0
    assert abs(values["energy_balance"]) < 1e-9 * abs(values["external_work"])
