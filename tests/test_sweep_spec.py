"""Sweep specs, cases and key figures, without running anything.

Key figures are checked against closed-form values of known signals; case
expansion against counting; Latin hypercube samples against their defining
property (one point in every stratum of every dimension).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from wire_fmu.master.scene import SceneError, VarRef, parse_scene
from wire_fmu.sweep.axes import Axis, Sampling
from wire_fmu.sweep.cases import apply_case, case_id, check_targets, expand, target_problems
from wire_fmu.sweep.figures import Figure
from wire_fmu.sweep.spec import SweepSpecError, parse_sweep_spec


def spec_data(**more):
    data = {
        "axes": [
            {"target": "units.b.parameters.mass", "values": [1, 2.5, 4]},
            {"target": "units.b.parameters.stiffness", "linspace": [40.0, 80.0, 2]},
            {"target": "drivers.0.amplitude", "distribution": "uniform", "low": 0.1, "high": 0.3},
        ],
        "sampling": {"samples": 3, "seed": 7},
        "figures": {"peak": "max(b.position)", "spread": 'range("a.position")'},
    }
    data.update(more)
    return data


def scene(**run):
    return parse_scene(
        {
            "name": "s",
            "run": {"stop_time": 1.0, "step": 0.01, **run},
            "units": {
                "a": {"fmu": "a.fmu", "parameters": {"mass": 1.0}},
                "b": {
                    "fmu": "b.fmu",
                    "parameters": {
                        "mass": 2.0,
                        "stiffness": 60.0,
                        "reeving": {"sheaves": [{"radius": 0.5}, {"radius": 0.7}], "rope": "wire"},
                    },
                },
            },
            "drivers": [{"target": "a.force", "kind": "sine", "amplitude": 1.0, "period": 2.0}],
            "events": [{"time": 0.5, "set": {"a.force": 0.0}}],
        },
        base_dir=Path("."),
    )


def test_grid_times_samples_first_axis_slowest():
    spec = parse_sweep_spec(spec_data())
    cases = expand(spec)
    assert spec.case_count == 3 * 2 * 3 == len(cases)
    masses = [c.values["units.b.parameters.mass"] for c in cases]
    assert masses == [1.0] * 6 + [2.5] * 6 + [4.0] * 6  # mixed whole/fractional -> float
    assert [c.index for c in cases] == list(range(18))
    assert len({c.case_id for c in cases}) == 18
    stiff = {c.values["units.b.parameters.stiffness"] for c in cases}
    assert stiff == {40.0, 80.0}
    amplitudes = [c.values["drivers.0.amplitude"] for c in cases[:3]]
    assert all(0.1 <= a < 0.3 for a in amplitudes)
    assert [c.values["drivers.0.amplitude"] for c in cases[3:6]] == amplitudes


def test_logspace_and_integer_axes():
    spec = parse_sweep_spec(
        {
            "axes": [
                {"target": "run.step", "logspace": [1e-3, 1e-1, 3]},
                {"target": "units.a.parameters.substeps", "linspace": [10, 20, 3], "integer": True},
            ]
        }
    )
    step, substeps = spec.axes
    assert step.values == pytest.approx((1e-3, 1e-2, 1e-1), rel=1e-12) and step.log_scale
    assert substeps.values == (10, 15, 20) and substeps.kind == "int"


def test_every_problem_is_listed_at_once():
    with pytest.raises(SweepSpecError) as err:
        parse_sweep_spec(
            {
                "colour": "red",
                "axes": [
                    {"target": "units.b.parameters.mass", "values": [1.0, 1.0]},
                    {"target": "vessel.heave", "values": [1.0]},
                    {"target": "units.b.parameters.k", "values": [1.0], "linspace": [0, 1, 2]},
                    {"target": "drivers.0.amplitude", "distribution": "triangular"},
                    {"target": "run.step", "distribution": "log_uniform", "low": 0.0, "high": 1.0},
                ],
                "figures": {"peak": "peak(b.position)", "status": "max(b.position)", "x": "b"},
            }
        )
    text = "\n".join(err.value.problems)
    for expected in (
        "unknown top-level key 'colour'",
        "appears twice",
        "must start with one of",
        "give exactly one of",
        "'distribution' must be one of",
        "needs 'low' > 0",
        "unknown function 'peak'",
        "reserved",
        "must read 'function(unit.variable)'",
        "needs [sampling]",
    ):
        assert expected in text, expected
    assert len(err.value.problems) >= 10


def test_case_id_depends_on_the_values_only():
    values = {"units.b.parameters.mass": 2.0, "run.step": 0.01}
    assert case_id(values) == case_id(dict(reversed(values.items())))
    assert case_id(values) != case_id({**values, "run.step": 0.02})
    assert case_id(values) != case_id({**values, "run.step": 0.010000000000000002})
    reordered = spec_data()
    reordered["axes"] = reordered["axes"][::-1]
    ids = {c.case_id for c in expand(parse_sweep_spec(spec_data()))}
    assert {c.case_id for c in expand(parse_sweep_spec(reordered))} == ids


@pytest.mark.parametrize("n", [1, 7, 50])
def test_latin_hypercube_puts_one_point_in_every_stratum(n):
    points = Sampling(n, "latin_hypercube", seed=3).unit_points(3)
    assert points.shape == (n, 3) and np.all((points >= 0) & (points < 1))
    for j in range(3):
        assert sorted(np.floor(points[:, j] * n).astype(int)) == list(range(n))
    assert np.array_equal(points, Sampling(n, "latin_hypercube", seed=3).unit_points(3))
    if n > 1:
        assert not np.array_equal(points, Sampling(n, "latin_hypercube", seed=4).unit_points(3))


def test_distributions_map_the_unit_interval():
    u = np.array([0.0, 0.5])
    assert Axis("run.step", distribution="uniform", arguments=(2.0, 4.0)).draw(u) == [2.0, 3.0]
    low, mid = Axis("run.step", distribution="log_uniform", arguments=(1e-4, 1e-2)).draw(u)
    assert low == pytest.approx(1e-4) and mid == pytest.approx(1e-3)
    phi_1 = 0.5 * (1 + math.erf(1 / math.sqrt(2)))  # P(Z < 1) of the standard normal
    normal = Axis("run.step", distribution="normal", arguments=(10.0, 2.0))
    assert normal.draw(np.array([0.5, phi_1])) == pytest.approx([10.0, 12.0])
    assert Axis("x.y", distribution="uniform", arguments=(0, 10), integer=True).draw(
        np.array([0.26])
    ) == [3]


def test_key_figures_against_closed_forms():
    t = np.linspace(0.0, 2 * math.pi, 2001)
    columns = {"time": t, "u.s": 1.0 + np.sin(t), "u.line": 3.0 * t - 1.0}
    value = {
        f: Figure(f, f, "u.s").evaluate(columns) for f in ("max", "min", "absmax", "range", "final")
    }
    assert value["max"] == pytest.approx(2.0, abs=1e-5)
    assert value["min"] == pytest.approx(0.0, abs=1e-5)
    assert value["range"] == pytest.approx(2.0, abs=1e-5)
    assert value["absmax"] == value["max"]
    assert value["final"] == pytest.approx(1.0, abs=1e-12)
    assert Figure("m", "mean", "u.s").evaluate(columns) == pytest.approx(1.0, abs=1e-12)
    # the trapezoidal mean of a straight line is exact: 3 * pi - 1
    assert Figure("m", "mean", "u.line").evaluate(columns) == pytest.approx(
        3 * math.pi - 1, rel=1e-13
    )
    uneven = {"time": np.array([0.0, 1.0, 3.0]), "u.s": np.array([0.0, 2.0, 2.0])}
    assert Figure("m", "mean", "u.s").evaluate(uneven) == pytest.approx((1.0 + 4.0) / 3.0)
    assert Figure("m", "max", "u.missing").evaluate(columns) is None


def test_apply_case_changes_a_copy_only():
    base = scene()
    changed = apply_case(
        base,
        {
            "units.b.parameters.mass": 3.0,
            "units.b.parameters.reeving.sheaves.1.radius": 0.9,
            "units.b.parameters.ground_stiffness": 5.0,
            "units.a.effects": ["rope_damping", "sheave_inertia"],
            "drivers.0.amplitude": 2.0,
            "drivers.0.phase_deg": 90.0,
            "events.0.time": 0.25,
            "events.0.set.a.force": 7.0,
            "run.step": 0.005,
        },
    )
    b = changed.units["b"].parameters
    assert b["mass"] == 3.0 and b["ground_stiffness"] == 5.0
    assert b["reeving"]["sheaves"][1]["radius"] == 0.9
    assert changed.units["a"].effects == ("rope_damping", "sheave_inertia")
    assert changed.drivers[0].spec["amplitude"] == 2.0
    assert changed.drivers[0].spec["phase_deg"] == 90.0
    assert changed.events[0].time == 0.25
    assert changed.events[0].values[VarRef("a", "force")] == 7.0
    assert changed.run.step == 0.005
    assert base == scene()  # nothing of the original changed, nested tables included
    assert base.units["b"].parameters["reeving"]["sheaves"][1]["radius"] == 0.7


def test_apply_case_checks_run_settings():
    with pytest.raises(SceneError, match="run.step"):
        apply_case(scene(), {"run.step": -0.01})


def test_check_targets_names_what_the_scene_lacks():
    spec = parse_sweep_spec(
        {
            "axes": [
                {"target": "units.c.parameters.mass", "values": [1.0]},
                {"target": "units.b.parameters.reeving.sheaves.5.radius", "values": [1.0]},
                {"target": "units.b.parameters.reeving.rope.grade", "values": [1.0]},
                {"target": "drivers.3.amplitude", "values": [1.0]},
                {"target": "drivers.0.significant_height", "values": [1.0]},
                {"target": "events.2.time", "values": [1.0]},
                {"target": "run.horizon", "values": [1.0]},
            ],
            "figures": {"peak": "max(c.position)", "bond": "final(bond.rod.power)"},
        }
    )
    problems = check_targets(spec, scene())
    text = "\n".join(problems)
    for expected in (
        "no unit 'c'",
        "not an index of a list of 2",
        "is a value, not a table",
        "1 drivers, no index 3",
        "sets no 'significant_height'",
        "1 events, no index 2",
        "no run setting 'horizon'",
        "'c.position' is neither",
        "no bond 'rod'",
    ):
        assert expected in text, expected
    assert len(problems) == 9


@pytest.mark.parametrize(
    ("target", "value", "words"),
    [
        ("events.0.time", -5.0, "no time of an event"),
        ("events.0.time", True, "no time of an event"),
        ("events.0.time", "soon", "no time of an event"),
        ("events.0.set.a.force", {"x": 1}, "an event sets a number"),
        ("units.a.effects", [True, False], "list of effect names"),
        ("run.order", "ab", "list of unit names"),
    ],
)
def test_a_case_value_the_scene_would_refuse_is_refused(target, value, words):
    """Such values were taken as they came: -5 s, True as 1.0 s, "ab" as the units a and b."""
    with pytest.raises(SceneError, match=words):
        apply_case(scene(), {target: value})


def test_a_distribution_whose_samples_overflow_is_refused():
    data = spec_data()
    data["axes"] = [
        {
            "target": "units.a.parameters.mass",
            "distribution": "normal",
            "mean": 1e308,
            "std": 1e308,
            "integer": True,
        }
    ]
    data["sampling"] = {"samples": 3}
    with pytest.raises(SweepSpecError, match="would overflow"):
        parse_sweep_spec(data)


def test_max_cases_that_is_no_number_is_said_with_the_other_problems():
    with pytest.raises(SweepSpecError) as err:
        parse_sweep_spec(
            {"max_cases": "many", "axes": [{"target": "units.b.parameters.mass", "values": []}]}
        )
    text = "\n".join(err.value.problems)
    assert "'values' must be a non-empty list" in text
    assert "'max_cases' must be a whole number >= 1, got 'many'" in text


def test_a_spec_with_problems_keeps_what_can_still_be_checked_against_a_scene():
    with pytest.raises(SweepSpecError) as err:
        parse_sweep_spec(
            {
                "axes": [
                    {"target": "units.c.parameters.mass", "linspace": [1.0, 2.0, -3]},
                    {"target": "vessel.heave", "values": [1.0]},
                ],
                "figures": {"peak": "maximum(c.position)", "spread": "range(b.position)"},
            }
        )
    assert err.value.targets == ("units.c.parameters.mass",)
    assert [f.column for f in err.value.figures] == ["c.position", "b.position"]
    problems = target_problems(err.value.targets, err.value.figures, scene())
    assert len(problems) == 2
    assert "no unit 'c'" in problems[0] and "'c.position' is neither" in problems[1]
