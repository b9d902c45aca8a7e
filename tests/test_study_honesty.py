"""A study that cannot say anything refuses or warns, and never prints a meaningless number.

Key outputs that are not physical quantities (counts, flags, states) are
refused; key outputs that do not move in the studied window are left out
with a warning, or the study refuses when none moves; orders are fitted
only on at least three runs in the asymptotic range; an effect's change is
never relative to a still or non-finite baseline; quick studies cover the
window where a scene's action happens. Synthetic arrays and declarations
only: no FMU is built and no study is run.
"""

from __future__ import annotations

import logging
import math
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import wire_fmu
from wire_fmu.core.framework.variables import output
from wire_fmu.master.scene import SceneError, VarRef
from wire_fmu.master.validate import Structure
from wire_fmu.registry import BY_NAME
from wire_fmu.study.accuracy import _compared, summary_text
from wire_fmu.study.accuracy_report import AccuracyStudy, accuracy_markdown
from wire_fmu.study.effects import EffectCase, _baseline_comparison, _effect_row
from wire_fmu.study.effects_report import change_text
from wire_fmu.study.key_outputs import (
    check_physical,
    moving_key_outputs,
    physical_problem,
    still_outputs,
    still_tolerance,
)
from wire_fmu.study.measures import Comparison, RunRow, output_error
from wire_fmu.study.monolithic import MonolithicResult
from wire_fmu.study.orders import asymptotic_runs, observed_orders
from wire_fmu.study.plan import StudyError, StudyOptions, study_settings, with_stop_time
from wire_fmu.study.timing import TimedRun, Timing
from wire_fmu.study.window import first_sample, window_problems

from .block_train_helpers import fall_scene

SCENES = sorted((Path(wire_fmu.__file__).parent / "scenes").glob("*.toml"))
TOL = still_tolerance(1e-10)


def real(name: str, unit: str, description: str, kind: str = "Real") -> SimpleNamespace:
    """A model variable as fmpy reads it from a model description."""
    return SimpleNamespace(
        name=name, type=kind, unit=unit, declaredType=None, description=description
    )


def run_row(family: str, step: float, error: float, status: str = "finished") -> RunRow:
    return RunRow(
        family, "jacobi", "linear", "s", step, status, error, "y", 1.0, 1.0, 1.0 / step,
        1, 0, 10, 2, 0.9, 0.05, 0.05,
    )  # fmt: skip


def floor_row(error: float) -> RunRow:
    """The monolithic model with the families' solver: that solver's own error."""
    row = run_row("monolithic / s", math.nan, error)
    return replace(row, algorithm="monolithic", extrapolation="-")


def study_scene_settings(**study):
    scene = fall_scene(study={"key_outputs": ["rope.block_a.position"], **study})
    return scene, study_settings(scene)


# ------------------------------------------------------------- physical quantities
@pytest.mark.parametrize(
    "var",
    [
        real(
            "solver.evaluations", "", "Torque evaluations of the internal solver so far", "Integer"
        ),
        real("broken", "", "Whether any rope span has broken", "Boolean"),
        real("mode", "", "Operating mode", "Enumeration"),
        real("solver.steps", "1", "Internal steps so far"),
        real("brake.state", "", "Band brake: 0 released, 1 slipping, 2 holding"),
        real("physics_seconds", "s", "wall-clock time spent in the unit's physics"),
        output("cycle.count", "", "Revolutions completed", type=int),
    ],
)
def test_counts_flags_states_and_timing_are_not_physical_quantities(var):
    assert physical_problem(var)


@pytest.mark.parametrize(
    "var",
    [
        real("cycle.delta", "1", "Coefficient of non-uniformity of the last revolution"),
        real("stroke_used", "1", "Rod extension as a fraction of the stroke"),
        real("line_a.tension", "N", "Number of newtons in the fast line"),  # N: physical
        output("shaft.speed", "rad/s", "Main shaft speed"),
    ],
)
def test_physical_quantities_pass(var):
    assert physical_problem(var) is None


def test_our_units_declare_every_count_flag_and_state_as_non_real():
    """Among our units' outputs, exactly the non-Real ones are not physical quantities."""
    for unit in BY_NAME.values():
        for var in unit.core_class().VARIABLES:
            if var.causality == "output":
                assert bool(physical_problem(var)) == (var.type is not float), (unit.name, var)


def test_a_counter_as_key_output_is_refused_by_name():
    description = SimpleNamespace(
        modelVariables=[
            real("shaft.speed", "rad/s", "Main shaft speed"),
            real("solver.evaluations", "", "Torque evaluations so far", "Integer"),
        ]
    )
    structure = Structure({}, {"paper": description})
    keys = (VarRef("paper", "shaft.speed"), VarRef("paper", "solver.evaluations"))
    with pytest.raises(StudyError, match=r"'machine_unit'.*paper\.solver\.evaluations.*Integer"):
        check_physical("machine_unit", keys, structure.variable)
    check_physical("machine_unit", keys[:1], structure.variable)  # a speed is fine


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_shipped_scenes_study_physical_key_outputs(path):
    """Every key output of a shipped scene is a declared physical quantity of its unit."""
    scene = StudyOptions().prepare(path)[0]
    declared = {
        name: {v.name: v for v in BY_NAME[spec.fmu].core_class().VARIABLES}
        for name, spec in scene.units.items()
    }
    keys = study_settings(scene).key_outputs
    assert all(k.variable in declared[k.unit] for k in keys), keys
    check_physical(scene.name, keys, lambda ref: declared[ref.unit][ref.variable])


# ------------------------------------------------------------------ still outputs
def test_still_outputs_zero_roundoff_and_nonfinite_swings():
    values = {
        "zero": np.zeros(5),
        "roundoff": 15.0 + np.array([0.0, 3.6e-15, 0.0, 1e-14, 0.0]),
        "held": 1.177e5 + np.array([0.0, 8e-9, 0.0, 0.0, 0.0]),
        "nan": np.array([1.0, np.nan, 2.0, 3.0, 4.0]),
        "moves": np.array([13.5, 13.4, 13.45, 13.5, 13.48]),
    }
    still = {s.key for s in still_outputs(values, list(values), 0, TOL)}
    assert still == {"zero", "roundoff", "held", "nan"}


def test_the_window_decides_what_moves():
    y = np.array([0.0, 1.0, 2.0, 2.0, 2.0, 2.0])  # moves, then rests from sample 2 on
    assert not still_outputs({"y": y}, ["y"], 0, TOL)
    assert [s.key for s in still_outputs({"y": y}, ["y"], 2, TOL)] == ["y"]


def test_no_moving_key_output_is_a_refusal_naming_scene_output_and_window():
    values = {"winch.drum.speed": np.zeros(6), "rope.block_a.position": np.full(6, 15.0)}
    keys = (VarRef("winch", "drum.speed"), VarRef("rope", "block_a.position"))
    with pytest.raises(StudyError) as err:
        moving_key_outputs("drawworks", values, keys, (0.0, 1.0), 0, TOL)
    text = str(err.value)
    assert "'drawworks'" in text and "winch.drum.speed" in text and "[0, 1] s" in text
    assert "rope.block_a.position" in text and "quick_window" in text


def test_a_still_key_output_beside_moving_ones_is_left_out_with_a_warning(caplog):
    values = {"winch.drum.speed": np.zeros(6), "rope.block_a.position": np.linspace(15, 14, 6)}
    keys = (VarRef("winch", "drum.speed"), VarRef("rope", "block_a.position"))
    with caplog.at_level(logging.WARNING, logger="wire_fmu.study.key_outputs"):
        moving, notes = moving_key_outputs("drawworks", values, keys, (3.8, 4.8), 0, TOL)
    assert moving == (VarRef("rope", "block_a.position"),)
    assert len(notes) == 1 and "winch.drum.speed" in notes[0] and "[3.8, 4.8] s" in notes[0]
    assert "winch.drum.speed" in caplog.text


def test_an_error_is_never_scaled_by_a_zero_swing():
    reference = {"a": np.array([1.0, 2.0, 0.0, 0.0]), "b": np.array([0.0, 1.0, 2.0, 3.0])}
    got = {"a": np.array([1.0, 2.0, 0.5, 0.0]), "b": np.array([0.0, 1.0, 2.0, 3.3])}
    assert output_error(got, reference, ["a", "b"]) == (pytest.approx(0.25), "a")
    assert output_error(got, reference, ["b"], first=2) == (pytest.approx(0.3), "b")
    with pytest.raises(ValueError, match="no error can be scaled"):
        output_error(got, reference, ["a"], first=2)  # a is zero in the window


def test_accuracy_study_drops_still_outputs_and_compares_only_the_window():
    _, settings = study_scene_settings()
    settings = replace(
        settings, key_outputs=(VarRef("u", "x"), VarRef("u", "y")), window_start=0.04
    )
    time = np.arange(6) * 0.02
    reference = MonolithicResult(
        time, {"u.x": np.array([5.0, 0.0, 3.0, 3.0, 3.0, 3.0]), "u.y": np.arange(6.0)}, 1.0, 1, 1
    )
    kept, notes, comparison = _compared("fall", settings, reference)
    assert kept.key_outputs == (VarRef("u", "y"),) and "u.x" in notes[0]
    assert comparison.first == 2 and comparison.keys == ("u.y",)
    frozen = replace(reference, values={"u.x": np.full(6, 3.0), "u.y": np.full(6, 1.0)})
    with pytest.raises(StudyError, match=r"no key output moves in the studied window \[0.04"):
        _compared("fall", settings, frozen)


# ------------------------------------------------------------------------ orders
def test_order_fitted_on_the_asymptotic_range_of_c_h2_plus_a_floor():
    """Errors C h^2 + floor: the pre-asymptotic run and those near the floor are left out."""
    steps = [0.08 / 2**k for k in range(9)]
    rows = [run_row("f", h, 100.0 * h**2 + 1e-5) for h in steps] + [floor_row(1e-5)]
    (order,) = observed_orders(rows, fall_scene())
    assert order.steps_used[0] == 0.04  # 0.64 at 0.08 is beyond the asymptotic limit
    assert min(order.steps_used) > 5e-4  # below, within 4 x the floor 1e-5
    assert order.points == 7
    assert order.observed == pytest.approx(2.0, abs=0.15)


def test_a_solver_floor_the_runs_beat_is_not_used_and_the_row_says_so():
    """The monolithic model with the units' solver at 2e-2, co-simulation runs far below it."""
    rows = [run_row("f", h, 0.1 * h) for h in (0.004, 0.002, 0.001)] + [floor_row(2e-2)]
    (order,) = observed_orders(rows, fall_scene())
    assert order.points == 3 and order.observed == pytest.approx(1.0)
    assert "no floor here" in order.note and "reach 0.0001" in order.note
    honest = [run_row("f", h, 0.1 * h) for h in (0.004, 0.002, 0.001)] + [floor_row(4e-5)]
    (order,) = observed_orders(honest, fall_scene())  # 1e-4 is within 4 x the floor 4e-5
    assert order.points == 2 and math.isnan(order.observed) and "no floor" not in order.note


def test_growing_errors_and_two_point_lines_are_not_fitted():
    growing = [run_row("g", h, e) for h, e in ((0.004, 0.10), (0.002, 0.12), (0.001, 0.15))]
    pair = [run_row("p", h, 50 * h**2) for h in (0.04, 0.02)]
    orders = {o.family: o for o in observed_orders(growing + pair, fall_scene())}
    assert math.isnan(orders["g"].observed) and orders["g"].points == 1
    assert math.isnan(orders["p"].observed) and orders["p"].points == 2
    assert orders["g"].note.startswith("not fitted (1 run in the asymptotic range)")
    assert orders["p"].note.startswith("not fitted (2 runs in the asymptotic range)")


def test_a_failed_run_breaks_the_asymptotic_range():
    runs = [run_row("f", h, 10 * h) for h in (0.02, 0.01, 0.005, 0.0025, 0.00125)]
    runs[2] = replace(runs[2], status="failed", error=math.nan)
    kept = asymptotic_runs(runs, 0.0)
    assert [r.step for r in kept] == [0.0025, 0.00125]  # of two as long, the smaller steps


def test_summaries_say_not_fitted_instead_of_a_number():
    scene, settings = study_scene_settings()
    growing = [run_row("g", h, e) for h, e in ((0.004, 0.10), (0.002, 0.12), (0.001, 0.15))]
    study = AccuracyStudy(
        "riser", settings, 1.0, growing, observed_orders(growing, scene), [], notes=["n"]
    )
    text = summary_text(study)
    assert "observed not fitted (1 run in the asymptotic range)" in text
    assert "nan" not in text and "0 runs" not in text and "warning: n" in text
    assert "| not fitted (1 run in the asymptotic range) |" in accuracy_markdown(study)


# ----------------------------------------------------------------------- effects
def timed(columns: dict, cost: float = 1.0, status: str = "finished") -> TimedRun:
    return TimedRun(status, "", columns, Timing(wall=cost, simulated=1.0, physics=0.5, fmi=0.6))


def test_effect_changes_are_never_relative_to_a_still_or_nonfinite_baseline():
    time = np.arange(5) * 0.25
    baseline = timed(
        {
            "time": time,
            "w.speed": np.zeros(5),
            "w.torque": np.array([1.0, np.nan, 1.0, 1.0, 1.0]),
            "r.y": np.linspace(0.0, 1.0, 5),
        }
    )
    _, settings = study_scene_settings()
    keys = (VarRef("w", "speed"), VarRef("w", "torque"), VarRef("r", "y"))
    settings = replace(settings, key_outputs=keys)
    comparison, notes = _baseline_comparison("hoist", baseline, settings, 1.0)
    assert comparison.keys == ("r.y",) and len(notes) == 2
    with pytest.raises(StudyError, match="'hoist': no key output moves .* run with every effect"):
        _baseline_comparison("hoist", baseline, replace(settings, key_outputs=keys[:2]), 1.0)


def test_an_effect_run_that_blows_up_is_diverged_with_no_change():
    comparison = Comparison({"r.y": np.linspace(0.0, 1.0, 5)}, ("r.y",))
    baseline = timed({"r.y": np.linspace(0.0, 1.0, 5)}, cost=0.0)
    blown = timed({"r.y": np.array([0.0, 0.2, np.inf, np.nan, 1.0])})
    row = _effect_row(
        EffectCase("rope", "rope_damping"), blown, math.nan, baseline, math.nan, comparison
    )
    assert row.status == "diverged" and math.isnan(row.output_change)
    assert change_text(row) == "none (diverged)"
    short = timed({"r.y": np.zeros(3)})
    row = _effect_row(
        EffectCase("rope", "rope_damping"), short, math.nan, baseline, math.nan, comparison
    )
    assert row.status == "failed" and "3 samples" in row.message
    fine = timed({"r.y": np.linspace(0.0, 1.1, 5)})
    row = _effect_row(
        EffectCase("rope", "rope_damping"), fine, math.nan, baseline, math.nan, comparison
    )
    assert row.output_change == pytest.approx(0.1) and math.isnan(row.saved_share)  # zero cost


# ------------------------------------------------------------------ quick windows
@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_quick_windows_of_shipped_scenes_lie_inside_their_stop_times(path):
    scene, quick = StudyOptions(quick=True).prepare(path)
    start, stop = quick.window
    assert 0.0 <= start < stop <= scene.run.stop_time + 1e-9
    assert first_sample(np.arange(0.0, stop + 1e-9, quick.output_interval), start) >= 0
    full = study_settings(scene)
    assert full.window_start == 0.0 and not window_problems(list(quick.window), scene.run.stop_time)


def test_quick_windows_cover_the_action():
    by_name = {p.stem: StudyOptions(quick=True).prepare(p) for p in SCENES}
    scene, drawworks = by_name["drawworks"]
    stop_event = next(e.time for e in scene.events if "emergency" in e.label)
    assert drawworks.window[0] > 1.0 and drawworks.window[0] < stop_event < drawworks.window[1]
    scene, riser = by_name["riser_tensioner"]
    fade_in = max(float(d.spec.get("ramp_time", 0.0)) for d in scene.drivers)
    assert riser.window[0] >= fade_in == 10.0


@pytest.mark.parametrize(
    "window, message",
    [
        ([3.0, 2.0], "ends before it starts"),
        ([-1.0, 0.5], "before the scene starts"),
        ([0.5, 99.0], "after the scene's stop time"),
        ("3 to 4", "two numbers of seconds"),
        ([0.5, True], "two numbers of seconds"),
        ([0.50, 0.51], "fewer than two samples"),
    ],
)
def test_a_bad_quick_window_names_the_scene_and_the_parameter(window, message):
    scene = fall_scene(study={"key_outputs": ["rope.block_a.position"], "quick_window": window})
    with pytest.raises(SceneError, match=message) as err:
        study_settings(scene, quick=True)
    assert f"scene {scene.name!r} [study]" in str(err.value) and "quick_window" in str(err.value)


def test_quick_window_sets_the_runs_and_a_stop_time_must_leave_it_samples():
    _, settings = study_scene_settings()
    scene = fall_scene(study={"key_outputs": ["rope.block_a.position"], "quick_window": [0.4, 0.8]})
    quick = study_settings(scene, quick=True)
    assert quick.window == (pytest.approx(0.4), pytest.approx(0.8))
    assert study_settings(scene).window == (0.0, pytest.approx(1.0))  # full: from 0 s
    assert with_stop_time(quick, 0.9).window == (pytest.approx(0.4), pytest.approx(0.9))
    with pytest.raises(StudyError, match="starts at 0.4 s"):
        with_stop_time(quick, 0.3)
    with pytest.raises(StudyError, match="scene 'fall': a stop time of 0.3 s leaves no window"):
        StudyOptions(quick=True, stop_time=0.3).prepare(scene)
    with pytest.raises(StudyError, match="fewer than two samples"):
        StudyOptions(settings=replace(settings, window_start=0.99)).prepare(scene)
