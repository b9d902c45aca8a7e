"""The accuracy study: its metric, its order fits, its reference, and real studies.

The order tests run two smooth two-unit scenes whose internal solver (RK4)
has an error far below the coupling's: ``docs/scenes/winch_hoist.toml``, a
winch and a block train coupled by a power bond (the tension is held: order
1 held constant, order 2 held at the step average of a linear or quadratic
extrapolant), and ``docs/scenes/coupled_falls.toml``, two block trains that
each hold the other's block displacement as a plain signal (the same orders).
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from wire_fmu.master.scene import SceneError, VarRef, load_scene, parse_scene
from wire_fmu.study.accuracy import reference_run, run_accuracy_study
from wire_fmu.study.accuracy_report import accuracy_markdown
from wire_fmu.study.measures import RunRow, output_error
from wire_fmu.study.orders import equal_error, observed_orders, theoretical_order
from wire_fmu.study.plan import (
    COUPLINGS,
    StudyError,
    build_grid,
    configured_scene,
    coupling_choices,
    parse_couplings,
    study_scene,
    study_settings,
    with_stop_time,
)
from wire_fmu.study.solvers import SolverChoice, scene_solver

from .block_train_helpers import (
    FALL_EA,
    FALL_LENGTH,
    FALL_MASS,
    FALL_PRETENSION,
    long_form_rope_data,
)
from .block_train_helpers import fall_scene as released_fall

ROOT = Path(__file__).resolve().parents[1]
COUPLED_FALLS = ROOT / "docs" / "scenes" / "coupled_falls.toml"
WINCH_HOIST = ROOT / "docs" / "scenes" / "winch_hoist.toml"
RK4 = SolverChoice("rk4 h=4e-3", {"solver": "rk4", "solver_max_step": 4e-3})
G = 9.81
MASS, LENGTH, EA, PRETENSION = FALL_MASS, FALL_LENGTH, FALL_EA, FALL_PRETENSION


def fall_scene(**extra):
    """A mass released on a taut rope, studied over two steps (see block_train_helpers)."""
    study = {
        "key_outputs": ["rope.block_a.position"],
        "steps": [0.02, 0.01],
        "output_interval": 0.02,
    }
    return released_fall(**{"study": study, **extra})


def row(
    family: str,
    extrapolation: str,
    step: float,
    error: float,
    cost: float,
    solver: str = "s",
    algorithm: str = "jacobi",
) -> RunRow:
    return RunRow(
        family,
        algorithm,
        extrapolation,
        solver,
        step,
        "finished",
        error,
        "y",
        cost,
        1.0,
        cost,
        1,
        0,
        10,
        2,
        0.9,
        0.05,
        0.05,
    )


# ------------------------------------------------------------------- no FMUs
def test_study_reference_matches_the_closed_form():
    """The study's reference on its own grid: y = y_eq (1 - cos w t), w^2 = EA / (l m)."""
    scene = fall_scene()
    settings = study_settings(scene)
    reference = reference_run(study_scene(scene, settings), settings)
    unstretched = LENGTH * EA / (EA + PRETENSION)
    omega = math.sqrt(EA / (unstretched * MASS))
    y_eq = LENGTH - unstretched - MASS * G * unstretched / EA
    exact = y_eq * (1 - np.cos(omega * reference.time))
    assert reference.time[1] == pytest.approx(0.02)
    np.testing.assert_allclose(reference.values["rope.block_a.position"], exact, atol=1e-10)
    error, worst = output_error(
        {"rope.block_a.position": exact}, reference.values, settings.key_outputs
    )
    assert error < 1e-8 and worst == "rope.block_a.position"


def test_error_metric_is_max_deviation_over_range_of_the_worst_output():
    reference = {"a": np.array([0.0, 1.0, 2.0]), "b": np.array([10.0, 10.0, 10.0])}
    got = {"a": np.array([0.0, 1.1, 2.0]), "b": np.array([10.0, 10.0, 10.001])}
    error, worst = output_error(got, reference, ["a", "b"])
    assert worst == "b"  # constant output: scaled by 1e-6 of its size, so 0.001 / 1e-5
    assert error == pytest.approx(0.001 / 1e-5)
    assert output_error(got, reference, ["a"]) == (pytest.approx(0.05), "a")
    short = {"a": np.array([0.0, 1.0])}
    assert math.isnan(output_error(short, reference, ["a"])[0])


def test_settings_from_the_study_table_and_defaults():
    scene = fall_scene()
    settings = study_settings(scene)
    assert settings.key_outputs == (VarRef("rope", "block_a.position"),)
    assert settings.steps == (0.02, 0.01)
    assert settings.stop_time == pytest.approx(1.0)
    default = study_settings(
        fall_scene(study={}, plots=[{"title": "y", "variables": ["rope.block_a.position"]}])
    )
    assert default.steps == pytest.approx((0.04, 0.02, 0.01, 0.005, 0.0025))
    assert default.output_interval == pytest.approx(0.04)
    quick = study_settings(
        fall_scene(study={}, plots=[{"title": "y", "variables": ["rope.block_a.position"]}]),
        quick=True,
    )
    assert quick.quick and len(quick.steps) == 3 and quick.solvers == ()  # the scene's own
    assert quick.extrapolations == ("constant", "linear")


@pytest.mark.parametrize(
    "study, message",
    [
        ({"key_outputs": ["x"]}, "not 'unit.variable'"),
        ({"key_outputs": ["rope.block_a.position"], "steps": [0.03, 0.02]}, "not a multiple"),
        ({"key_outputs": ["rope.block_a.position"], "colour": "red"}, "unknown keys"),
    ],
)
def test_study_table_problems_are_reported(study, message):
    with pytest.raises(SceneError, match=message):
        study_settings(fall_scene(study=study))


def test_scene_study_table_must_be_a_table():
    with pytest.raises(SceneError, match=r"\[study\] must be a table"):
        fall_scene(study=3)


def test_a_failing_reference_is_a_study_error(monkeypatch):
    from wire_fmu.core.framework.hybrid import IntegrationError
    from wire_fmu.study import accuracy

    def chattering(*args, **kwargs):
        raise IntegrationError("more than 10000 events in one step")

    monkeypatch.setattr(accuracy, "run_monolithic", chattering)
    scene = fall_scene()
    settings = study_settings(scene)
    with pytest.raises(StudyError, match="reference .* failed: IntegrationError: more than"):
        reference_run(study_scene(scene, settings), settings)


def test_stop_time_override_is_a_multiple_of_the_output_interval():
    settings = study_settings(fall_scene())
    assert with_stop_time(settings, 0.55).stop_time == pytest.approx(0.54)
    assert with_stop_time(settings, None) is settings
    with pytest.raises(ValueError, match="stop_time"):
        with_stop_time(settings, -1.0)


def test_theory_of_held_efforts_signals_and_bonded_flows():
    scene = load_scene(COUPLED_FALLS)
    assert [theoretical_order(scene, e) for e in ("constant", "linear", "quadratic")] == [1, 2, 2]
    assert theoretical_order(fall_scene(), "constant") is None  # nothing held
    bonded = parse_scene(long_form_rope_data(), base_dir=Path("."))
    assert theoretical_order(bonded, "constant") == 1  # the held tension
    # the same bond with its effort not held (marked as exact like a position): only the flow
    only_flow = replace(
        bonded,
        bonds=(replace(bonded.bonds[0], effort=replace(bonded.bonds[0].effort, role="position")),),
    )
    assert theoretical_order(only_flow, "constant") == 2  # a flow into an exact position


def test_orders_are_fitted_where_coupling_error_dominates():
    steps = [0.2, 0.04, 0.02, 0.01, 0.005]
    rows = [row("c", "constant", h, 3.0 * h, 1 / h) for h in steps]  # 0.6 at 0.2: too big
    rows += [row("l", "linear", h, 50.0 * h**2, 1 / h) for h in steps[1:]]
    rows.append(
        RunRow(
            "monolithic / s",
            "monolithic",
            "-",
            "s",
            math.nan,
            "finished",
            5e-4,
            "y",
            1.0,
            1.0,
            1.0,
            1,
            0,
            0,
            0,
            1.0,
            0.0,
            0.0,
        )
    )
    orders = {o.family: o for o in observed_orders(rows, load_scene(COUPLED_FALLS))}
    assert orders["c"].observed == pytest.approx(1.0) and orders["c"].points == 4
    assert orders["l"].observed == pytest.approx(2.0)
    assert orders["l"].points == 3  # 1.25e-3 is within 4 x the solver's own error 5e-4
    assert orders["l"].theory == 2 and orders["c"].theory == 1


def test_equal_error_interpolates_cost_and_names_the_cheapest():
    rows = [row("a", "constant", h, h, 1 / h) for h in (0.1, 0.01)]
    rows += [row("b", "linear", h, h**2, 10 / h) for h in (0.1, 0.01)]
    (at_1e3,) = equal_error(rows, [1e-3])
    assert at_1e3.costs["a"] == math.inf  # never reached on the grid
    # b goes from error 1e-2 at cost 100 to 1e-4 at cost 1000: half way in log
    assert at_1e3.costs["b"] == pytest.approx(math.sqrt(100 * 1000))
    assert at_1e3.cheapest == "b"
    (at_1e1,) = equal_error(rows, [1e-1])
    assert at_1e1.costs["a"] == pytest.approx(10) and at_1e1.cheapest == "a"


# --------------------------------------------------------------- with FMUs
@pytest.mark.integration
def test_observed_orders_match_theory_across_a_power_bond(tmp_path):
    """Winch and block train, tension one way, payout and its rate back: the held tension
    makes constant extrapolation first order, linear and quadratic second order."""
    scene = load_scene(WINCH_HOIST)
    settings = replace(
        study_settings(scene),
        steps=(0.04, 0.02, 0.01, 0.005),
        stop_time=1.2,
        solvers=(),
        couplings=(),
        monolithic_rtols=(),
    )
    study = run_accuracy_study(scene, tmp_path, settings=settings, progress=False)
    assert len(study.orders) == 6
    for order in study.orders:
        assert order.points >= 3, order
        assert abs(order.observed - order.theory) < 0.3, order
    cosim = [r for r in study.rows if r.algorithm != "monolithic"]
    assert all(r.status == "finished" and r.error < 0.3 for r in cosim)
    assert all(r.do_step_calls == 2 * round(1.2 / r.step) for r in cosim)
    assert all(0.0 < r.physics_share < 1.0 and r.fmu_calls > r.do_step_calls for r in cosim)
    for name in (
        "accuracy.csv",
        "accuracy.md",
        "accuracy.json",
        "work_precision.png",
        "convergence.png",
    ):
        assert (tmp_path / name).stat().st_size > 0
    assert "Observed convergence orders" in (tmp_path / "accuracy.md").read_text()
    assert study.comparison and study.comparison[0].cheapest


def test_the_grid_adds_couplings_a_scene_can_use():
    """Event synchronisation for any scene; interface models only across a bond that offers
    them (a bond written out long-hand offers none)."""
    bonded = parse_scene(
        long_form_rope_data(study={"key_outputs": ["r.line_a.tension"]}), base_dir=Path(".")
    )
    settings = replace(
        study_settings(bonded), steps=(0.02, 0.01), solvers=(), extrapolations=("linear",)
    )
    assert coupling_choices(bonded, settings) == ["held", "synchronised"]
    grid = build_grid(bonded, settings)
    assert {c.family for c in grid} == {
        f"{a} / linear / {scene_solver(bonded).label}{tail}"
        for a in ("jacobi", "gauss_seidel")
        for tail in ("", " / synchronised")
    }
    synchronised = next(c for c in grid if c.coupling == "synchronised")
    configured = configured_scene(bonded, synchronised)
    assert configured.run.synchronise_events and not configured.run.interface_models
    assert coupling_choices(bonded, replace(settings, couplings=())) == ["held"]


def test_couplings_named_on_the_command_line():
    assert parse_couplings("ramped, held,ramped") == ("ramped", "held")
    assert parse_couplings("all") == tuple(COUPLINGS)
    with pytest.raises(ValueError) as caught:
        parse_couplings("held,ramp,interface+sync")
    text = str(caught.value)
    assert "'ramp'" in text and "'interface+sync'" in text and "interface+ramped" in text
    with pytest.raises(ValueError, match="none given"):
        parse_couplings(" , ")


def test_the_cli_refuses_an_unknown_coupling_as_a_usage_error(capsys):
    from wire_fmu.cli import main

    with pytest.raises(SystemExit) as caught:
        main(["study", "accuracy", "drawworks", "--couplings", "held,bogus"])
    assert caught.value.code == 2
    assert "--couplings" in capsys.readouterr().err


@pytest.mark.integration
def test_the_study_compares_the_couplings_it_is_given(tmp_path):
    """``couplings`` replaces the plan's: the scene's own coupling and those named, no more."""
    scene = load_scene(WINCH_HOIST)
    settings = replace(
        study_settings(scene, quick=True),
        steps=(0.02, 0.01),
        stop_time=0.4,
        algorithms=("gauss_seidel",),
        extrapolations=("linear",),
    )
    study = run_accuracy_study(
        scene, tmp_path, settings=settings, couplings=["synchronised"], progress=False
    )
    assert study.settings.couplings == ("synchronised",)
    cosim = {r.family for r in study.rows if r.algorithm != "monolithic"}
    assert len(cosim) == 2 and sum(f.endswith(" / synchronised") for f in cosim) == 1


@pytest.mark.integration
def test_observed_orders_of_held_position_signals(tmp_path):
    """Two block trains each holding the other's block displacement: orders 1 and 2."""
    scene = load_scene(COUPLED_FALLS)
    settings = replace(study_settings(scene, quick=True), steps=(0.04, 0.02, 0.01), stop_time=0.8)
    study = run_accuracy_study(scene, tmp_path, settings=settings, progress=False)
    assert {(o.algorithm, o.extrapolation) for o in study.orders} == {
        (a, e) for a in ("jacobi", "gauss_seidel") for e in ("constant", "linear")
    }
    for order in study.orders:
        assert order.points == 3, order
        assert abs(order.observed - order.theory) < 0.3, order


@pytest.mark.integration
def test_refused_and_blown_up_configurations_are_recorded(tmp_path):
    """A unit refusing its solver stops a run; quadratic extrapolation at w H ~ 5 blows up."""
    scene = load_scene(COUPLED_FALLS)
    bogus = SolverChoice("no such solver", {"solver": "no_such_solver"})
    settings = replace(
        study_settings(scene),
        steps=(0.64, 0.32),
        output_interval=0.64,
        stop_time=1.28,
        algorithms=("jacobi",),
        extrapolations=("quadratic",),
        solvers=(bogus, RK4),
        couplings=(),
        monolithic_rtols=(),
    )
    study = run_accuracy_study(scene, tmp_path, settings=settings, progress=False)
    own = scene_solver(scene).label
    assert own == "rk4 h=0.004 (scene)"
    assert {r.family for r in study.rows} == {  # RK4 is the scene's own: studied once
        f"jacobi / quadratic / {own}",
        "gauss_seidel / linear / no such solver",
        f"monolithic / {own}",
    }
    refused = [r for r in study.rows if r.solver == bogus.label]
    assert len(refused) == 2
    assert all(r.status == "failed" and "no_such_solver" in r.message for r in refused)
    blown = [r for r in study.rows if r.solver == own and r.algorithm != "monolithic"]
    assert [r.status for r in blown] == ["diverged", "diverged"]
    assert all(r.error > 1.0 for r in blown)
    assert all(math.isnan(o.observed) for o in study.orders)
    text = accuracy_markdown(study)
    assert "did not finish or blew up" in text and "no_such_solver" in text
    assert (tmp_path / "work_precision.png").exists()
