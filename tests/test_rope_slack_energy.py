"""A slack rope spring's energy and loss: the damper drains, nothing injects.

Kelvin-Voigt spring, 10 m unstretched, EA = 1e7 N, c = 1e5 N s, stretched 1 mm.
Slack with the stretch falling (the damper unloads it at zero total force):
its strain energy drains at exactly the rate it falls. Slack with the stretch
growing is a state just past engaging (event location stops just past the
root): the loss is zero, never negative.
"""

from __future__ import annotations

import numpy as np
import pytest

from wire_fmu.core.components.rope import RopeProperties, rope_forces

ROPE = RopeProperties(axial_stiffness=1.0e7, damping=1.0e5)
LENGTH, STRETCH = 10.0, 1.0e-3  # m


def slack(length_rate: float):
    return rope_forces(
        ROPE,
        np.array([LENGTH + STRETCH]),
        np.array([LENGTH]),
        np.array([length_rate]),
        np.array([0.0]),
        np.array([False]),
    )


def test_relaxing_slack_spring_drains_its_strain_energy_through_the_damper():
    rate = -0.2  # m/s: shortening faster than the spring can follow (trial tension < 0)
    forces = slack(rate)
    elastic = ROPE.axial_stiffness * STRETCH / LENGTH
    assert forces.tension[0] == 0.0 and forces.trial_tension[0] < 0.0  # truly slack
    assert forces.energy[0] == pytest.approx(0.5 * elastic * STRETCH)
    assert forces.loss_power[0] == pytest.approx(-elastic * rate)  # d/dt of the energy


def test_slack_spring_being_stretched_never_has_a_negative_loss():
    """Mutation: the loss left at -strain_rate for a growing stretch; it was -1e3 W."""
    forces = slack(+1.0)
    assert forces.tension[0] == 0.0
    assert forces.loss_power[0] == 0.0
