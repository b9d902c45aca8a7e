"""The monolithic reference against closed forms and against the co-simulation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wire_fmu.core.units.block_train.reevings import single_fall
from wire_fmu.master.scene import SceneError, parse_scene
from wire_fmu.study.monolithic import run_monolithic

from .block_train_helpers import (
    FALL_EA,
    FALL_LENGTH,
    FALL_MASS,
    FALL_PRETENSION,
)
from .block_train_helpers import fall_scene as released_fall

G = 9.81
MASS, LENGTH, EA, PRETENSION = FALL_MASS, FALL_LENGTH, FALL_EA, FALL_PRETENSION


def fall_scene(**extra):
    """A mass released on a taut rope, recording its position, tension and ledger."""
    outputs = {"variables": ["rope.block_a.position", "rope.line_a.tension", "rope.energy_balance"]}
    return released_fall(**{"outputs": outputs, **extra})


def test_free_oscillation_matches_the_closed_form():
    """A mass released on a taut rope: y = y_eq (1 - cos w t), w^2 = EA / (l m)."""
    result = run_monolithic(fall_scene())
    unstretched = LENGTH * EA / (EA + PRETENSION)
    omega = math.sqrt(EA / (unstretched * MASS))
    y_eq = LENGTH - unstretched - MASS * G * unstretched / EA
    exact = y_eq * (1 - np.cos(omega * result.time))
    np.testing.assert_allclose(result.values["rope.block_a.position"], exact, atol=1e-10)
    assert np.max(np.abs(result.values["rope.energy_balance"])) < 1e-6


def stepped_positions(step: float) -> np.ndarray:
    """The core unit stepped like a master would: payout now, mean rate over the step."""
    from tests.block_train_helpers import make_unit

    unit = make_unit(
        single_fall(mass=MASS, length=LENGTH, axial_stiffness=EA),
        solver="rk4",
        solver_max_step=1e-4,
        initial_equilibrium=False,
        pretension=PRETENSION,
    )
    w, every = 2 * math.pi / 0.4, int(round(0.01 / step))
    positions = [unit.values["block_a.position"]]
    for i in range(int(round(1.0 / step))):
        t = i * step
        unit.values["line_a.payout"] = 0.02 * math.sin(w * t)
        unit.values["line_a.payout_rate"] = (
            0.02 * (math.sin(w * (t + step)) - math.sin(w * t)) / step
        )
        assert unit.advance(t, step).success
        if (i + 1) % every == 0:
            positions.append(unit.values["block_a.position"])
    return np.array(positions)


def test_driven_scene_is_the_limit_of_the_stepped_unit():
    """Payout driven by a sine, the rope going slack and snapping taut: the stepped unit
    converges to the reference at second order in the step."""
    driver = {
        "target": "rope.line_a.payout",
        "rate_target": "rope.line_a.payout_rate",
        "kind": "sine",
        "amplitude": 0.02,
        "period": 0.4,
    }
    result = run_monolithic(fall_scene(drivers=[driver]))
    assert result.events > 0  # slack and taut again
    reference = result.values["rope.block_a.position"]
    errors = [np.max(np.abs(stepped_positions(h) - reference)) for h in (0.01, 0.0025)]
    assert errors[1] < errors[0] / 8  # (0.01 / 0.0025)^2 = 16 in theory
    assert errors[1] < 1e-4


def test_foreign_fmus_cannot_be_monolithic(tmp_path):
    scene = parse_scene({"units": {"x": {"fmu": "some.fmu"}}}, base_dir=tmp_path)
    with pytest.raises(SceneError, match="not one of ours"):
        run_monolithic(scene)
