"""The winch integrates its drum against the block train's interface model of the tension.

Closed forms: a free drum on the rope model's spring is a harmonic oscillator; with the
damper too, a damped one (eigenvalues from ``scipy.linalg``); a brake holding against a
tension that grows at the model's rate breaks away when the rope's torque reaches its
capacity. The ledger closes with the rope's work integrated along the model, both kernels
agree, and a rope model never pushes.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

from wire_fmu.core.framework.compiled import KERNEL_ENV
from wire_fmu.core.framework.interface_model import EffortModel, inputs_taken
from wire_fmu.core.units.winch.base import WinchInputs

from .winch_helpers import BRAKE, capacities, make_unit, one_mass, run

J = 800.0  # drum inertia, kg m^2
R_DRUM = 0.5  # winding radius, m
K = 4.0e5  # rope model's spring, N/m
E0 = 1.0e5  # tension at the step's start, N
X_REF = 0.02  # payout the model was taken at, m


def rope_inputs(stiffness=K, damping=0.0, rate=0.0, tension=E0, x_ref=X_REF, v_ref=0.0):
    """The winch's inputs of a rope model (and its tension E0)."""
    return {
        "rope.tension": tension,
        "rope.stiffness": stiffness,
        "rope.damping": damping,
        "rope.effort_rate": rate,
        "rope.reference_position": x_ref,
        "rope.reference_velocity": v_ref,
    }


def free_drum(**rope):
    """A rigid, undamped drum on the rope, at rest at payout 0, its motor holding E0."""
    return make_unit(
        "drum_inertia",
        drive_train=one_mass(J),
        drum_radius=R_DRUM,
        motor__command=-E0 * R_DRUM,
        solver="rk4",
        solver_max_step=1e-3,
        **{k.replace(".", "__"): v for k, v in rope_inputs(**rope).items()},
    )


def test_a_free_drum_on_the_rope_models_spring_oscillates_at_r_sqrt_k_over_j():
    """J phi'' = -E0 r + r (E0 - K (r phi - x_ref)): x = x_ref (1 - cos(w t)), w = r sqrt(K/J).

    The tension ``E0 + K x_ref cos(w t)`` stays positive: the rope never goes slack."""
    unit = free_drum()
    step = 0.25  # one communication step holds the whole model: the spring acts inside it
    got = run(unit, 0.25, step, record=("rope.payout", "rope.payout_rate"))
    omega = R_DRUM * math.sqrt(K / J)
    t = got["time"][-1]
    assert omega * t > 2.5  # most of half a period inside one step
    # RK4 at 1 ms: a global error of about (w h)^4 w t / 120 = 2e-10 relative to the swing
    swing = 2 * X_REF
    expected = X_REF * (1 - math.cos(omega * t))
    assert got["rope.payout"][-1] == pytest.approx(expected, abs=1e-8 * swing)
    rate = X_REF * omega * math.sin(omega * t)
    assert got["rope.payout_rate"][-1] == pytest.approx(rate, abs=1e-8 * swing * omega)


def test_the_rope_models_damper_gives_the_damped_oscillators_eigenvalues():
    """With D the drum's motion decays at the eigenvalues of [[0, 1], [-r^2 K/J, -r^2 D/J]]."""
    damping = 2.0e4
    unit = free_drum(damping=damping)
    got = run(unit, 0.4, 0.4, record=("rope.payout",))
    system = np.array([[0.0, 1.0], [-(R_DRUM**2) * K / J, -(R_DRUM**2) * damping / J]])
    lam = scipy.linalg.eigvals(system)
    # x(t) = x_ref + a e^{l1 t} + b e^{l2 t}, x(0) = 0, x'(0) = 0
    a, b = np.linalg.solve(np.array([[1.0, 1.0], lam]), np.array([-X_REF, 0.0]))
    t = 0.4
    expected = (X_REF + a * np.exp(lam[0] * t) + b * np.exp(lam[1] * t)).real
    assert got["rope.payout"][-1] == pytest.approx(expected, rel=1e-8)


def test_a_held_drum_breaks_away_when_the_growing_tension_reaches_the_brakes_capacity():
    """T(t) = E0 + R t: the brake slips at t* = (capacity / r - E0) / R, located in the step."""
    lever, rate, tension = 400.0, 2.0e5, 1.5e4
    unit = make_unit(
        "drum_inertia,band_brake",
        drive_train=one_mass(J),
        drum_radius=R_DRUM,
        solver="rk4",
        solver_max_step=1e-3,
        brake__lever_force=lever,
        **BRAKE,
        **{k.replace(".", "__"): v for k, v in rope_inputs(0.0, 0.0, rate, tension, 0.0).items()},
    )
    assert unit.values["brake.state"] == 2
    breakaway = (capacities(lever)[0] / R_DRUM - tension) / rate
    assert 0.0 < breakaway < 0.1
    run(unit, 0.1, 0.1)
    assert unit.values["brake.state"] == 1
    assert unit.values["mode_changes"] == 1
    assert unit.values["mode_change_time"] == pytest.approx(breakaway, abs=1e-8)


def test_the_ledger_closes_with_the_rope_models_work():
    """Stored energy change + dissipated = external work, the rope's along its model."""
    unit = make_unit(
        "drum_inertia,band_brake,motor_characteristic",
        drive_train=one_mass(J, damping=40.0),
        drum_radius=R_DRUM,
        solver="rk4",
        solver_max_step=1e-3,
        brake__lever_force=150.0,
        motor__command=-2.0e3,
        **BRAKE,
        **{
            k.replace(".", "__"): v
            for k, v in rope_inputs(K, 3.0e3, -1.0e5, 6.0e4, 0.0, 0.1).items()
        },
    )
    got = run(unit, 0.5, 0.05, record=("energy_balance", "external_work", "drum.speed"))
    assert np.ptp(got["drum.speed"]) > 0.1  # it moved
    assert abs(got["energy_balance"][-1]) < 1e-6 * np.abs(got["external_work"]).max()


@pytest.mark.parametrize(
    "effects", ["drum_inertia,band_brake,motor_characteristic", "band_brake,rope_layers"]
)
def test_both_kernels_agree_with_the_rope_model(monkeypatch, effects):
    """The compiled kernel and the readable reference: 1e-10 relative over stick and slip."""

    def go(kernel):
        monkeypatch.setenv(KERNEL_ENV, kernel)
        unit = make_unit(
            effects,
            drive_train=one_mass(J, damping=40.0),
            drum_radius=R_DRUM,
            drum__speed_command=2.0,
            brake__lever_force=300.0,
            motor__command=-1.0e3,
            **BRAKE,
            **{
                k.replace(".", "__"): v
                for k, v in rope_inputs(K, 3.0e3, 1.5e5, 5.0e4, 0.0, 0.0).items()
            },
        )
        assert getattr(unit.model, "compiled", False) == (
            kernel == "compiled" and "drum_inertia" in effects
        )
        return run(unit, 0.6, 0.02, record=("rope.payout", "brake.torque", "external_work"))

    compiled, python = go("compiled"), go("python")
    for key in compiled:
        np.testing.assert_allclose(compiled[key], python[key], rtol=1e-10, atol=1e-9, err_msg=key)


def test_a_rope_model_never_pushes():
    """Paid out beyond where the model's tension reaches zero, the rope is slack: 0 N."""
    model = EffortModel(K, 0.0, 0.0, X_REF, 0.0, 0.0)
    inputs = WinchInputs(tension=E0, rope_model=model)
    slack_from = X_REF + E0 / K
    assert inputs.tension_at(0.0, slack_from - 0.01, 0.0) == pytest.approx(0.01 * K)
    assert inputs.tension_at(0.0, slack_from + 0.01, 0.0) == 0.0
    assert WinchInputs(tension=-5.0).tension_at(0.0, 1.0, 0.0) == -5.0  # held: as given


def test_a_negative_spring_and_an_energy_form_solver_are_refused_by_name():
    unit = free_drum(stiffness=-1.0)
    problems = unit.input_problems()
    assert any("'rope.stiffness' must be >= 0" in p for p in problems), problems
    unit.values["rope.damping"] = math.nan
    problems = unit.input_problems()
    assert "input 'rope.damping' is not finite (nan)" in problems, problems
    assert any("'rope.stiffness' must be >= 0" in p for p in problems), problems  # all at once
    energy = make_unit(
        "drum_inertia",
        drive_train=one_mass(J),
        solver="energy",
        **{k.replace(".", "__"): v for k, v in rope_inputs().items()},
    )
    problems = energy.input_problems()
    assert any("solver 'energy'" in p and "rope.stiffness" in p for p in problems), problems


@pytest.mark.integration
def test_the_drawworks_winch_receives_the_fast_lines_stiffness(tmp_path):
    """With interface models the master wires the fast line's model to the winch.

    Held by the brake the sheave bearings stick, so the rope the drum sees is the fast
    line alone: the 45 m free span from the drum to the crown sheave and at most the
    rope wrapped on that stuck sheave (half a turn of 0.762 m radius), K = EA / L.
    """
    from dataclasses import replace

    from wire_fmu.master.run import find_scene, read_results_frame, run_scene
    from wire_fmu.master.scene import load_scene

    scene = load_scene(find_scene("drawworks"))
    (bond,) = scene.bonds
    assert bond.interface_lacking == ()
    run = replace(scene.run, interface_models=True, stop_time=1.5, output_interval=scene.run.step)
    on = replace(scene, run=run)
    links = on.bonds[0].interface
    on = replace(on, outputs=(*on.outputs, *(c.source for c in links), *(c.target for c in links)))
    outcome = run_scene(on, tmp_path / "drawworks", plots=False)
    assert outcome.result.status == "finished", outcome.result.message
    frame = read_results_frame(tmp_path / "drawworks")
    held = frame[(frame.index > 0.1) & (frame.index < 0.9)]
    stiffness = held["winch.rope.stiffness"].to_numpy()
    assert (stiffness <= 5.8e7 / 45.0).all()
    assert (stiffness >= 5.8e7 / (45.0 + math.pi * 0.762)).all()
    sent = frame["rope.line_a.stiffness"].to_numpy()[:-1]  # held over the next step
    assert (frame["winch.rope.stiffness"].to_numpy()[1:] == sent).all()
    moving = frame[frame.index > 1.2]
    assert (moving["winch.drum.speed"] > 1.0).all()  # lowering
    assert (frame["winch.rope.damping"] >= 0.0).all()


@pytest.mark.parametrize(
    ("values", "taken"),
    [
        ((1.0, 5.0, 2.0, 0.0), True),
        ((1.0, 0.0, 0.0, -3.0), True),  # a negative rate is an effort that falls
        ((1.0, -5.0, 2.0, 0.0), False),  # a spring that pushes the port along
        ((1.0, 5.0, -2.0, 0.0), False),
        ((math.nan, 5.0, 2.0, 0.0), False),
        ((1.0, 5.0, 2.0, math.inf), False),
    ],
)
def test_a_flow_side_takes_finite_inputs_with_no_negative_spring_or_damper(values, taken):
    assert inputs_taken(values, 1) is taken
    assert (not EffortModel(*values[1:]).problems("rope")) is (values[1] >= 0 and values[2] >= 0)
