"""Paper 002's multi-mass drives: impedances, reductions and the drive unit, against closed forms.

Independent checks: eigenvalues of the full state matrix by ``scipy.linalg.eig``
built here from the masses and shafts; the branched drive's equations written
out from the paper; the two-mass impedance formula; the steady state of a
rigid drive with motor characteristics.
"""

from __future__ import annotations

import importlib.util
import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

from wire_fmu.core.components.drive_data import (
    default_multimass_drive,
    parse_drive,
    two_motor_drive,
)
from wire_fmu.core.components.drive_train import DriveChain
from wire_fmu.core.components.drive_tree import DriveTree
from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.unit import Causality
from wire_fmu.core.units.multimass_drive.unit import DriveUnit
from wire_fmu.study.frequency_response import analytic_response, drive_unit, simulated_response

ROOT = Path(__file__).resolve().parents[1]


def chain() -> DriveTree:
    tree, problems = parse_drive(default_multimass_drive())
    assert problems == []
    return tree


def full_state_eigenvalues(masses, shafts) -> np.ndarray:
    """Oscillatory eigenvalues of [[0, I], [-M^-1 K, -M^-1 B]], built here from plain lists."""
    n = len(masses)
    m = np.diag([j for j, _ in masses])
    k = np.zeros((n, n))
    b = np.diag([beta for _, beta in masses]).astype(float)
    for i, j, c, beta in shafts:
        for mat, v in ((k, c), (b, beta)):
            mat[i, i] += v
            mat[j, j] += v
            mat[i, j] -= v
            mat[j, i] -= v
    a = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(m, k), -np.linalg.solve(m, b)]])
    lam = scipy.linalg.eig(a, right=False)
    lam = lam[lam.imag > 1e-2]  # oscillatory modes only (the rigid mode's 0 is noise-prone)
    return lam[np.argsort(lam.imag)]


def plain(data: dict) -> tuple[list, list]:
    names = [m["name"] for m in data["masses"]]
    masses = [(m["inertia"], m.get("damping", 0.0)) for m in data["masses"]]
    shafts = []
    for i, s in enumerate(data["shafts"]):
        a = names.index(s["from"]) if "from" in s else i
        b = names.index(s["to"]) if "to" in s else i + 1
        shafts.append((a, b, s["stiffness"], s.get("damping", 0.0)))
    return masses, shafts


# ================================================================= impedances
def test_two_mass_input_and_output_impedances_are_the_papers_formulas():
    tree = parse_drive(
        {
            "masses": [
                {"name": "a", "inertia": 2.0, "damping": 0.3},
                {"name": "b", "inertia": 5.0, "damping": 0.7},
            ],
            "shafts": [{"stiffness": 1e4, "damping": 4.0}],
        }
    )[0]
    for omega in (0.5, 30.0, 70.7, 400.0):
        p = 1j * omega
        z1, z2, z12 = 2.0 * p + 0.3, 5.0 * p + 0.7, 1e4 / p + 4.0
        numerator = z1 * z2 + z1 * z12 + z12 * z2
        assert tree.driving_point_impedance(0, omega) == pytest.approx(
            numerator / (z2 + z12), rel=1e-13
        )
        assert tree.driving_point_impedance(1, omega) == pytest.approx(
            numerator / (z1 + z12), rel=1e-13
        )


def test_tree_of_a_chain_agrees_with_drive_chain():
    tree = chain()
    as_chain = tree.to_chain()
    np.testing.assert_allclose(
        tree.natural_frequencies(), as_chain.natural_frequencies(), rtol=1e-10, atol=1e-4
    )
    for omega in (3.0, 80.0, 2000.0):
        assert tree.driving_point_impedance(0, omega) == pytest.approx(
            as_chain.input_impedance(omega), rel=1e-12
        )
        assert tree.driving_point_impedance(-1, omega) == pytest.approx(
            as_chain.output_impedance(omega), rel=1e-12
        )
    back = DriveTree.from_chain(as_chain)
    assert (back.inertias, back.dampings, back.motors, back.load_index) == (
        tree.inertias,
        tree.dampings,
        tree.motors,
        tree.load_index,
    )
    assert [(s.a, s.b, s.stiffness, s.damping) for s in back.shafts] == [
        (s.a, s.b, s.stiffness, s.damping) for s in tree.shafts
    ]


def test_branched_drive_follows_the_papers_four_equations():
    """M1 - Z13(w1-w3) = Z1 w1; M2 - Z23(w2-w3) = Z2 w2;
    Z13(w1-w3) + Z23(w2-w3) - Z34(w3-w4) = Z3 w3; Z34(w3-w4) - Mc = Z4 w4."""
    tree, problems = parse_drive(two_motor_drive())
    assert problems == [] and not tree.is_chain()
    data = two_motor_drive()
    j = [m["inertia"] for m in data["masses"]]
    beta = [m["damping"] for m in data["masses"]]
    (c13, b13), (c23, b23), (c34, b34) = [(s["stiffness"], s["damping"]) for s in data["shafts"]]
    for omega in (1.0, 60.0, 250.0):
        p = 1j * omega
        z = [j[k] * p + beta[k] for k in range(4)]
        z13, z23, z34 = c13 / p + b13, c23 / p + b23, c34 / p + b34
        system = np.array(
            [
                [z[0] + z13, 0, -z13, 0],
                [0, z[1] + z23, -z23, 0],
                [-z13, -z23, z13 + z23 + z34 + z[2], -z34],
                [0, 0, -z34, z34 + z[3]],
            ]
        )
        speeds = np.linalg.solve(system, np.array([1.0, 0.0, 0.0, 0.0]))  # M1 = 1, M2 = Mc = 0
        np.testing.assert_allclose(tree.speeds_per_torque(omega, 0), speeds, rtol=1e-12)
        assert tree.driving_point_impedance(0, omega) == pytest.approx(1 / speeds[0], rel=1e-12)


# ================================================================= reduction
@pytest.mark.parametrize("kept, frequency_tol, damping_tol", [(3, 2e-4, 2e-3), (2, 0.03, 0.1)])
def test_reduced_drive_keeps_the_full_chains_lowest_mode(kept, frequency_tol, damping_tol):
    """Delta-star reduction against the full chain's eigenvalues (scipy.linalg.eig)."""
    masses, shafts = plain(default_multimass_drive())
    full = full_state_eigenvalues(masses, shafts)
    reduced_chain = chain().to_chain().reduced(kept)
    assert reduced_chain.n == kept
    reduced = DriveTree.from_chain(reduced_chain)
    freqs, zetas = reduced.damped_modes()
    assert freqs.size == kept - 1
    assert freqs[0] == pytest.approx(full[0].imag, rel=frequency_tol)
    assert zetas[0] == pytest.approx(-full[0].real / abs(full[0]), rel=damping_tol)
    if kept == 3:  # the coupling's mass was tiny: the second mode is kept too, to 2 %
        assert freqs[1] == pytest.approx(full[1].imag, rel=0.02)


def test_reduction_is_exact_in_the_quasi_static_limit():
    """A vanishing interior mass: two shafts in series, frequencies exact."""
    masses = [(1.0, 0.0), (1e-9, 0.0), (3.0, 0.0)]
    shafts = [(0, 1, 2e4, 0.0), (1, 2, 5e4, 0.0)]
    full = full_state_eigenvalues(masses, shafts)
    reduced = DriveChain(
        (1.0, 1e-9, 3.0), (0.0,) * 3, (2e4, 5e4), (0.0, 0.0), ("a", "b", "c")
    ).reduced(2)
    series = 1.0 / (1 / 2e4 + 1 / 5e4)
    assert reduced.stiffnesses[0] == pytest.approx(series, rel=1e-12)
    assert reduced.natural_frequencies()[1] == pytest.approx(full[0].imag, rel=1e-8)


# ================================================================= frequency response
@pytest.mark.parametrize(
    "params, effects",
    [
        ({}, ()),
        ({"masses_kept": 2, "solver_max_step": 5e-3}, ()),
        ({"drive": two_motor_drive(), "motor_slope": 25.6}, ("motor_characteristic",)),
    ],
    ids=["full chain", "reduced to 2", "two motors with characteristics"],
)
def test_simulated_frequency_response_matches_one_over_z_in(params, effects):
    """Periodic steady state of the stepped unit against 1/Z_in(j w) and the load transfer."""
    unit = drive_unit(params, effects)
    for frequency in (13.0, 60.0):
        sim, formula = simulated_response(unit, frequency), analytic_response(unit, frequency)
        assert abs(sim.motor / formula.motor - 1.0) < 1e-3
        assert abs(sim.load / formula.load - 1.0) < 1e-5


def test_frequency_response_deviation_is_the_holds_aliasing():
    """The held torque's steps alias into the motor speed's samples: error ~ 1/steps^2."""
    unit = drive_unit({}, ())
    errors = []
    for steps in (100, 200):
        sim = simulated_response(unit, 8.0, steps=steps)
        errors.append(abs(sim.motor / analytic_response(unit, 8.0).motor - 1.0))
    assert 3.0 < errors[0] / errors[1] < 5.0


# ================================================================= the unit
def make_drive(params: dict | None = None, effects: str = "", **inputs) -> DriveUnit:
    unit = DriveUnit("drive")
    for key, value in (params or {}).items():
        unit.values[key] = json.dumps(value) if isinstance(value, dict) else value
    unit.values["effects"] = effects
    unit.configure()
    unit.values.update(inputs)
    unit.initialize(0.0)
    return unit


def run(unit: DriveUnit, duration: float, step: float) -> None:
    for i in range(int(round(duration / step))):
        result = unit.advance(i * step, step)
        assert result.success, result.message


@pytest.mark.parametrize(
    "drive", [default_multimass_drive(), two_motor_drive()], ids=["chain", "two motors"]
)
def test_steady_speed_with_motor_characteristics(drive):
    """Every motor a - b w, ground dampers: w = sum(a) / (sum(b) + sum(beta)) once settled."""
    motors = len(drive.get("motors", [0]))
    inputs = {
        "motor.torque": 4000.0,
        "motor2.torque": 4000.0 if motors == 2 else 0.0,
        "load.torque": 150.0,
    }
    unit = make_drive({"drive": drive, "motor_slope": 25.6}, "motor_characteristic", **inputs)
    run(unit, 3.0, 0.01)
    beta = sum(m["damping"] for m in drive["masses"])
    expected = (4000.0 * motors - 150.0) / (25.6 * motors + beta)
    for k in range(len(drive["masses"])):
        assert unit.values[f"mass_{k + 1}.speed"] == pytest.approx(expected, rel=1e-6)
    assert abs(unit.values["energy_balance"]) < 1e-6 * unit.values["external_work"]
    if motors == 2:  # equal motors at equal speeds share the load equally
        assert unit.values["motor.drive_torque"] == pytest.approx(
            unit.values["motor2.drive_torque"], rel=1e-6
        )


def test_start_in_quasi_static_twist_has_no_ringing():
    """Shafts pre-twisted for the rigid acceleration: without ground dampers the chain
    accelerates as one body, every mass at M / sum(J), with no shaft vibration at all."""
    drive = default_multimass_drive()
    for mass in drive["masses"]:
        mass["damping"] = 0.0
    unit = make_drive({"drive": drive}, **{"motor.torque": 100.0, "load.torque": 30.0})
    j_total = sum(m["inertia"] for m in drive["masses"])
    speeds = []
    for i in range(50):
        unit.advance(i * 1e-3, 1e-3)
        speeds.append([unit.values[f"mass_{k}.speed"] for k in range(1, 5)])
    t = 1e-3 * np.arange(1, 51)
    np.testing.assert_allclose(
        np.array(speeds), np.outer(70.0 / j_total * t, np.ones(4)), rtol=1e-9
    )
    assert unit.values["shaft_3.torque"] == pytest.approx(30.0 + 2.0 * 70.0 / j_total, rel=1e-9)


def test_reduced_unit_is_cheaper_and_agrees_at_low_frequency():
    full = make_drive({"solver_max_step": 5e-4}, **{"motor.torque": 50.0})
    reduced = make_drive({"masses_kept": 2, "solver_max_step": 5e-3}, **{"motor.torque": 50.0})
    for unit in (full, reduced):
        unit.values["load.torque"] = 20.0
        run(unit, 1.0, 0.01)
    assert reduced.values["load.speed"] == pytest.approx(full.values["load.speed"], rel=1e-3)
    assert reduced.model.solver.rhs_calls * 5 < full.model.solver.rhs_calls


def test_configuration_problems_are_all_reported():
    with pytest.raises(ConfigurationError) as info:
        make_drive({"drive": two_motor_drive(), "masses_kept": 2, "solver": "warp"}, "turbo")
    text = str(info.value)
    for word in ("turbo", "warp", "branched"):
        assert word in text
    with pytest.raises(ConfigurationError, match="unstable"):
        make_drive({"solver_max_step": 0.01})
    with pytest.raises(ConfigurationError, match="loop"):
        make_drive(
            {
                "drive": {
                    "masses": [{"name": n, "inertia": 1.0} for n in "abc"],
                    "shafts": [
                        {"from": "a", "to": "b", "stiffness": 1.0},
                        {"from": "b", "to": "a", "stiffness": 1.0},
                    ],
                }
            }
        )


@pytest.mark.parametrize(
    ("drive", "kept"),
    [(default_multimass_drive(), "2..4"), (two_motor_drive(), "4 (a branched")],
    ids=["chain", "two motors"],
)
def test_more_masses_kept_than_the_drive_has_is_refused_with_the_range(drive, kept):
    with pytest.raises(ConfigurationError) as info:
        make_drive({"drive": drive, "masses_kept": 99})
    text = str(info.value)
    assert "MultiMassDrive 'drive'" in text and "parameter 'masses_kept'" in text
    assert f"keep {kept}" in text and "got 99" in text
    assert make_drive({"masses_kept": 4}).model.n == 4  # every mass kept: the full drive


@pytest.mark.parametrize(
    ("values", "named"),
    [
        ({"initial_speed": 1e300}, ["parameter 'initial_speed' = 1e+300 rad/s"]),
        ({"motor.torque": 1e308}, ["input 'motor.torque' = 1e+308 N.m"]),
        (
            {"initial_speed": 1e200, "motor.torque": 1e308},
            ["parameter 'initial_speed' = 1e+200 rad/s", "input 'motor.torque' = 1e+308 N.m"],
        ),
    ],
)
def test_a_start_too_large_for_the_drive_is_named_without_numpy_warnings(values, named):
    unit = DriveUnit("drive")
    unit.values["effects"] = ""
    unit.configure()
    unit.values.update(values)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a numpy RuntimeWarning would fail here
        with pytest.raises(ConfigurationError) as info:
            unit.initialize(0.0)
    text = str(info.value)
    assert "MultiMassDrive 'drive'" in text and "start state" in text
    assert all(name in text for name in named)


def test_a_torque_too_large_mid_run_refuses_the_step_without_numpy_warnings():
    """A finite input the drive cannot integrate (1e308 N m) makes the state overflow: the
    step is refused, naming the unit and the non-finite state, and numpy's own warnings
    stay out of the host's terminal."""
    unit = make_drive({}, "", **{"motor.torque": 100.0})
    run(unit, 0.02, 0.01)
    unit.values["motor.torque"] = 1e308
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a numpy RuntimeWarning would fail here
        result = unit.advance(0.02, 0.01)
    assert not result.success
    assert "MultiMassDrive 'drive'" in result.message and "non-finite" in result.message
    assert unit.time == pytest.approx(0.02)  # the refused step left the state where it was


def test_declarations_and_feedthrough():
    assert DriveUnit.check_declarations() == []
    unit = make_drive({"motor_slope": 25.6}, "motor_characteristic", **{"motor.torque": 10.0})
    run(unit, 0.1, 0.01)
    outputs = [v for v in DriveUnit.VARIABLES if v.causality is Causality.output]
    for name in ("motor.torque", "motor2.torque", "load.torque"):
        before = dict(unit.values)
        unit.values[name] += 5.0
        unit.evaluate_outputs()
        after = dict(unit.values)
        unit.values[name] -= 5.0
        unit.evaluate_outputs()
        for var in outputs:
            if name not in var.depends_on:
                assert after[var.name] == before[var.name], (name, var.name)
    assert unit.values["mass_5.speed"] == 0.0 and unit.values["shaft_4.torque"] == 0.0


def test_facade_steps_like_the_core():
    spec = importlib.util.spec_from_file_location("drive_facade", ROOT / "models" / "drive.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    facade = module.MultiMassDrive(instance_name="drive", resources=None)
    refs = {v.name: v.value_reference for v in facade.vars.values()}
    assert list(refs) == [v.name for v in DriveUnit.VARIABLES] + ["physics_seconds"]
    facade.setup_experiment(0.0, None, None)
    facade.enter_initialization_mode()
    facade.exit_initialization_mode()
    unit = make_drive()
    for i in range(20):
        facade.set_real([refs["motor.torque"]], [math.sin(i)])
        facade.do_step(i * 0.01, 0.01)
        unit.values["motor.torque"] = math.sin(i)
        unit.advance(i * 0.01, 0.01)
    names = ["motor.speed", "load.speed", "shaft_2.torque", "energy_balance"]
    assert facade.get_real([refs[n] for n in names]) == [unit.values[n] for n in names]
