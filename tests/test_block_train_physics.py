"""Block-train physics against closed forms (no FMI involved).

Every expected value here comes from a textbook formula or hand geometry,
never from numbers the code printed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from wire_fmu.core.components.rope import snap_load
from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.units.block_train.reeving_parse import parse_reeving
from wire_fmu.core.units.block_train.reevings import (
    drilling_block_train,
    heave_compensated_block_train,
    riser_tensioner,
    single_fall,
)

from .block_train_helpers import make_unit, run

G = 9.81


def pulley(
    *,
    mass=1000.0,
    radius=0.5,
    axial_stiffness=1.0e7,
    bearing_torque=0.0,
    efficiency=1.0,
    mu=0.1,
    inertia=2.0,
    linear_mass=2.0,
):
    """A rope from a fixed line end up over one sheave and down to a hanging mass."""
    return {
        "rope": {"axial_stiffness": axial_stiffness, "linear_mass": linear_mass},
        "bodies": {
            "load": {"kind": "block", "mass": mass, "direction": [0, 1, 0], "port": "block_a"}
        },
        "sheaves": {
            "pulley": {
                "centre": [0, 10, 0],
                "radius": radius,
                "inertia": inertia,
                "bearing_torque": bearing_torque,
                "efficiency": efficiency,
                "groove_friction": mu,
            }
        },
        "anchors": {"hook": {"body": "load", "point": [radius, 0, 0]}},
        "path": [
            {"line_end": "line_a", "point": [-radius, 0, 0]},
            {"sheave": "pulley", "wrap": "cw"},
            {"anchor": "hook"},
        ],
    }


def haul_in(rate):
    def drive(t, unit):
        unit.values["line_a.payout_rate"] = rate

    return drive


def first_event_time(unit, duration, step, text, drive):
    """Step until an event containing ``text``; return (time, unit)."""
    t = 0.0
    while t < duration:
        drive(t, unit)
        result = unit.advance(t, step)
        assert result.success, result.message
        unit.values["line_a.payout"] += unit.values["line_a.payout_rate"] * step
        t += step
        if any(text in e for e in result.events):
            return t
    raise AssertionError(f"no event {text!r} within {duration} s")


class TestSheaveFriction:
    def test_capstan_slip_threshold(self):
        """Rope slips over a held sheave when T_high / T_low reaches e^(mu alpha) (eq. 9)."""
        mu, mass = 0.1, 1000.0
        unit = make_unit(
            pulley(mu=mu, bearing_torque=1e9, mass=mass),
            "sheave_inertia,bearing_friction,rope_slip",
            solver_max_step=2e-4,
        )
        t = first_event_time(unit, 2.0, 1e-3, "rope on sheave 'pulley' sliding", haul_in(-0.01))
        ratio = unit.values["line_a.tension"] / (mass * G)
        assert ratio == pytest.approx(math.exp(mu * math.pi), rel=3e-3)
        assert t > 0.1

    def test_bearing_holds_exactly_below_capacity_and_breaks_away_at_it(self):
        radius, torque, mass = 0.5, 2000.0, 1000.0
        unit = make_unit(
            pulley(bearing_torque=torque, radius=radius, mass=mass),
            "sheave_inertia,bearing_friction",
            solver_max_step=5e-4,
        )
        model = unit.model
        rim = model.rim_index[1]
        # haul in slowly: held while T_a - T_b < M/R, with the sheave exactly at rest
        drive = haul_in(-0.002)
        t = 0.0
        while unit.values["line_a.tension"] - mass * G < 0.9 * torque / radius:
            drive(t, unit)
            assert unit.advance(t, 1e-3).success
            unit.values["line_a.payout"] += -0.002e-3
            t += 1e-3
            assert model.v[rim] == 0.0 and model.q[rim] == 0.0
            assert abs(unit.values["block_a.velocity"]) < 1e-12  # equilibrium round-off only
        first_event_time(unit, 5.0, 1e-3, "bearing sliding", drive)
        excess = unit.values["line_a.tension"] - mass * G
        assert excess == pytest.approx(torque / radius, rel=5e-3)


def expected_fast_line_tension(weight, efficiency, n_lines, hoisting):
    """Chain the sheave losses by hand: each sheave passes K times its input tension."""
    # hoisting: line i (1 = next to the fast line) carries K^i F; lowering F / K^i
    factors = [efficiency ** (i if hoisting else -i) for i in range(1, n_lines + 1)]
    return weight / sum(factors)


@pytest.mark.parametrize("hoisting", [True, False], ids=["hoisting", "lowering"])
def test_static_fast_line_tension_with_sheave_losses(hoisting):
    n, k_eff, mass = 4, 0.9615, 1.2e5
    reeving = drilling_block_train(n, hook_mass=mass, efficiency=k_eff)
    reeving["rope"]["damping"] = 1.0e7  # settle quickly
    unit = make_unit(reeving, "rope_damping,sheave_inertia,bearing_friction", solver_max_step=2e-3)
    speed = 0.5 * (-1 if hoisting else 1)

    def drive(t, u):
        u.values["line_a.payout_rate"] = speed * min(1.0, t / 1.0)

    out = run(unit, 4.0, 1e-2, drive, record=("line_a.tension", "block_a.velocity"))
    last = out["time"] > 3.0
    tension = out["line_a.tension"][last].mean()
    weight = mass * G
    assert tension == pytest.approx(
        expected_fast_line_tension(weight, k_eff, n, hoisting), rel=3e-3
    )
    # the textbook form F = W / (n E), E = K (1 - K^n) / (n (1 - K)), for hoisting
    if hoisting:
        e = k_eff * (1 - k_eff**n) / (n * (1 - k_eff))
        assert tension == pytest.approx(weight / (n * e), rel=3e-3)
    # the block moves at the rate the lines shorten: sum over lines of l_k' (1 + eps_k)
    ea = reeving["rope"]["axial_stiffness"]
    line_tensions = [tension * k_eff ** (i if hoisting else -i) for i in range(1, n + 1)]
    expected_speed = abs(speed) / sum(1 / (1 + t_k / ea) for t_k in line_tensions)
    assert abs(out["block_a.velocity"][last].mean()) == pytest.approx(expected_speed, rel=1e-3)


def total_rope_length(n_lines, radius, crown=45.0, block=15.0):
    """Fast line + n lines + dead line + the wrapped arcs (n + 1 half turns)."""
    return 2 * crown + n_lines * (crown - block) + (n_lines + 1) * math.pi * radius


class TestHookStiffness:
    def test_natural_frequency_with_rope_flowing_over_sheaves(self):
        """Massless sheaves: one spring of the whole rope, k = n^2 EA / l (not n EA / l_line)."""
        n, mass, radius = 10, 1.2e5, 0.762
        reeving = drilling_block_train(n, hook_mass=mass, radius=radius)
        ea = reeving["rope"]["axial_stiffness"]
        pretension = 0.98 * mass * G / n
        unit = make_unit(
            reeving,
            "",
            initial_equilibrium=False,
            pretension=pretension,
            solver="rk4",
            solver_max_step=1e-3,
        )
        out = run(unit, 3.0, 1e-3, record=("block_a.position",))
        y = out["block_a.position"] - out["block_a.position"].mean()
        crossings = out["time"][1:][np.diff(np.sign(y)) != 0]
        period = 2 * np.mean(np.diff(crossings))
        unstretched = total_rope_length(n, radius) * ea / (ea + pretension)
        k_flow = n**2 * ea / unstretched
        assert 2 * math.pi / period == pytest.approx(math.sqrt(k_flow / mass), rel=2e-3)
        k_independent = n * ea / 30.0  # n separate 30 m springs
        assert abs(math.sqrt(k_independent / k_flow) - 1) > 0.1

    def test_equilibrium_start_has_no_transient(self):
        unit = make_unit(drilling_block_train(10), "rope_damping,sheave_inertia")
        out = run(unit, 1.0, 1e-2, record=("block_a.position", "line_a.tension"))
        assert np.ptp(out["block_a.position"]) < 1e-9
        assert out["line_a.tension"][0] == pytest.approx(1.2e5 * G / 10, rel=1e-12)


class TestSlackAndSnap:
    def test_snap_load_matches_closed_form(self):
        mass, length, ea, drop = 1000.0, 10.0, 1.0e7, 0.05
        unit = make_unit(
            single_fall(mass=mass, length=length, axial_stiffness=ea),
            initial_equilibrium=False,
            pretension=0.0,
            solver_max_step=2e-4,
        )
        unit.values["line_a.payout"] = drop  # the rope is now `drop` too long: slack
        out = run(unit, 0.4, 2e-4, record=("line_a.tension", "slack_spans"))
        assert out["slack_spans"][1] == 1 and out["line_a.tension"][1] == 0.0
        v0 = math.sqrt(2 * G * drop)
        expected = snap_load(mass, ea / (length + drop), v0, G)
        assert out["line_a.tension"].max() == pytest.approx(expected, rel=2e-3)
        assert out["line_a.tension"].min() >= 0.0

    def test_rope_break_by_schedule_leaves_free_fall(self):
        unit = make_unit(single_fall(), solver_max_step=1e-3)
        run(unit, 0.2, 1e-2)
        y0, v0 = unit.values["block_a.position"], unit.values["block_a.velocity"]
        unit.values["break_segment"] = 1
        out = run(unit, 0.5, 1e-2, record=("block_a.position", "line_a.tension", "broken"))
        t = out["time"]
        assert np.all(out["line_a.tension"][1:] == 0.0) and out["broken"][-1]
        np.testing.assert_allclose(out["block_a.position"], y0 + v0 * t - 0.5 * G * t**2, atol=1e-9)

    def test_rope_breaks_at_its_breaking_load(self):
        reeving = single_fall(mass=1000.0)
        reeving["rope"]["breaking_load"] = 1.5e4
        unit = make_unit(reeving, initial_equilibrium=False, pretension=0.0, solver_max_step=2e-4)
        unit.values["line_a.payout"] = 0.05  # drop: snap load above 15 kN
        out = run(unit, 0.3, 1e-3, record=("line_a.tension", "broken", "energy_balance"))
        assert out["broken"][-1]
        assert out["line_a.tension"].max() <= 1.5e4 * (1 + 1e-6)
        assert abs(out["energy_balance"][-1]) < 1e-6 * 1000 * G * 0.05 * 100


ALL_EFFECTS = "rope_damping,sheave_inertia,bearing_friction,rope_slip,moving_geometry"


def passive_run(effects, solver, max_step, duration=1.0):
    """A 4-line block train released off equilibrium, nothing driving it."""
    reeving = drilling_block_train(4, efficiency=0.97)
    unit = make_unit(
        reeving,
        effects,
        initial_equilibrium=False,
        pretension=2.0e5,
        solver=solver,
        solver_max_step=max_step,
    )
    return run(
        unit,
        duration,
        1e-2,
        record=("energy_balance", "stored_energy", "dissipated_energy", "external_work"),
    )


def test_energy_ledger_closes_in_a_passive_run():
    """All effects: stored change + dissipated = external work, to integration error."""
    out = passive_run(ALL_EFFECTS, "rk4", 5e-4, duration=0.5)
    scale = out["dissipated_energy"][-1]
    assert scale > 1e3  # something was dissipated
    assert np.max(np.abs(out["energy_balance"])) < 1e-6 * scale
    assert np.all(np.diff(out["dissipated_energy"]) >= 0.0)  # friction never injects energy
    assert np.all(out["external_work"] == 0.0)  # nothing drives a passive run
    assert np.all(np.diff(out["stored_energy"]) <= 1e-6 * scale)  # passive: never gains


def test_energy_ledger_residual_shrinks_with_the_step():
    """ROS2 is second order: halving the step cuts the ledger residual at least fourfold."""
    effects = "sheave_inertia,bearing_friction"
    residual = [
        np.max(np.abs(passive_run(effects, "ros2", h, 0.5)["energy_balance"])) for h in (1e-3, 5e-4)
    ]
    assert residual[1] < residual[0] / 4


class TestBadInput:
    def test_malformed_reeving_lists_every_problem(self):
        reeving = drilling_block_train(4)
        reeving["sheaves"]["crown_0"]["radius"] = -1.0
        reeving["path"][2]["wrap"] = "sideways"
        reeving["path"].insert(3, {"sheave": "nowhere", "wrap": "cw"})
        reeving["colour"] = "red"
        with pytest.raises(ConfigurationError) as info:
            make_unit(reeving, "rope_damping, sheave_inertai")
        text = str(info.value)
        for needle in (
            "'radius' must be > 0",
            "'wrap' must be 'ccw' or 'cw'",
            "sheave 'nowhere' is not defined",
            "unknown key 'colour'",
            "unknown effect 'sheave_inertai'",
            "did you mean 'sheave_inertia'",
        ):
            assert needle in text
        assert len(info.value.problems) >= 5

    def test_a_rope_too_stiff_for_its_pretension_is_refused(self):
        """T / EA below the span lengths' round-off: the spans would start slack."""
        reeving = single_fall(axial_stiffness=1e30)
        with pytest.raises(ConfigurationError) as info:
            make_unit(reeving, initial_equilibrium=False, pretension=3.56e5)
        text = str(info.value)
        assert "starting tension 356000 N" in text and "'axial_stiffness' 1e+30 N" in text
        assert "3.56e-25, is below what the span lengths resolve" in text

    @pytest.mark.parametrize("equilibrium", [True, False])
    def test_a_start_at_or_above_the_breaking_load_is_refused(self, equilibrium):
        """A span breaks when its tension rises through the breaking load; one that starts
        above it never would: 1000 kg hanging on one line pulls m g = 9810 N (g = 9.81 m/s^2)."""
        reeving = single_fall(axial_stiffness=1.3e8)
        reeving["rope"]["breaking_load"] = 5000.0
        with pytest.raises(ConfigurationError) as info:
            make_unit(reeving, initial_equilibrium=equilibrium, pretension=9810.0)
        text = str(info.value)
        assert "starting tension 9810 N is at or above the rope's 'breaking_load' 5000 N" in text
        reeving["rope"]["breaking_load"] = 9900.0  # above the start: it starts, unbroken
        unit = make_unit(reeving, initial_equilibrium=equilibrium, pretension=9810.0)
        assert unit.values["line_a.tension"] == pytest.approx(9810.0, rel=1e-9)

    @pytest.mark.parametrize("pretension", [1e-3, 1.0, 3.56e5])
    def test_a_small_pretension_on_a_real_rope_starts_at_it(self, pretension):
        unit = make_unit(
            single_fall(axial_stiffness=1.3e8), initial_equilibrium=False, pretension=pretension
        )
        # the span lengths resolve the strain T / EA to about their round-off, eps L
        resolution = 10 * np.finfo(float).eps * 1.3e8 / pretension
        assert unit.values["line_a.tension"] == pytest.approx(pretension, rel=resolution)

    def test_overlapping_sheaves_are_named(self):
        reeving = drilling_block_train(4)
        reeving["sheaves"]["crown_1"]["centre"] = [0.5, 45.0, 0.0]  # on top of crown_0
        with pytest.raises(ConfigurationError) as info:
            make_unit(reeving)
        assert "crown_0" in str(info.value) and "crown_1" in str(info.value)

    def test_a_name_given_to_a_sheave_and_an_anchor_is_refused(self):
        reeving = riser_tensioner()
        reeving["anchors"]["fixed_1"] = reeving["anchors"].pop("dead_end")
        reeving["path"][0] = {"anchor": "fixed_1"}
        with pytest.raises(ConfigurationError) as info:
            make_unit(reeving)
        assert info.value.problems == [
            "parameter 'reeving': sheave 'fixed_1' and anchor 'fixed_1': the same name for two "
            "nodes; every sheave and anchor needs a name of its own"
        ]

    def test_a_sheave_passed_twice_is_refused_naming_both_places(self):
        """The model gives each passage of the path its own groove, rim and bearing: a sheave
        met twice would turn twice over, with its inertia and friction counted twice."""
        reeving = riser_tensioner()
        path = reeving["path"]
        reeving["path"] = path[:3] + path[1:3] + path[3:]  # ..., moving_1, fixed_1, moving_1, ...
        with pytest.raises(ConfigurationError) as info:
            make_unit(reeving)
        text = str(info.value)
        assert "path nodes 1 and 3: sheave 'moving_1' is passed twice" in text
        assert "path nodes 2 and 4: sheave 'fixed_1' is passed twice" in text
        assert "one sheave per groove" in text
        assert len(info.value.problems) == 2

    def test_a_list_or_table_given_for_a_name_is_named_not_raised(self):
        """Names are looked up in tables: a list or a table given for one is named as a
        problem (it raised TypeError: unhashable type)."""
        reeving = riser_tensioner()
        reeving["path"][0] = {"anchor": {"name": "dead_end"}}
        reeving["path"][1] = {"sheave": ["moving_1"], "wrap": ["cw"]}
        reeving["bodies"]["rod"]["port"] = ["mover_a"]
        reeving["bodies"]["riser"]["on"] = ["rod"]
        reeving["sheaves"]["guide"]["body"] = ["ground"]
        with pytest.raises(ConfigurationError) as info:
            parse_reeving(reeving)
        text = str(info.value)
        for needle in (
            "anchor {'name': 'dead_end'} is not defined",
            "sheave ['moving_1'] is not defined",
            "'wrap' must be 'ccw' or 'cw', got ['cw']",
            "'port' of a driven body must be one of ('mover_a', 'mover_b'), got ['mover_a']",
            "'on' names ['rod'], which is not a body",
            "sheave 'guide': 'body' ['ground'] is not a body",
        ):
            assert needle in text

    def test_coincident_sheaves_in_one_plane_are_refused(self):
        reeving = riser_tensioner()
        reeving["sheaves"]["fixed_2"]["centre"] = list(reeving["sheaves"]["fixed_1"]["centre"])
        with pytest.raises(ConfigurationError) as info:
            make_unit(reeving)
        assert "sheaves 'fixed_1' and 'fixed_2': discs coincide in the same plane" in str(
            info.value
        )

    @pytest.mark.parametrize("rope", [{"damping": 2.0e5}, {}])
    def test_a_rope_without_stiffness_names_both_ways_to_give_it(self, rope):
        reeving = riser_tensioner()
        reeving["rope"] = rope
        with pytest.raises(ConfigurationError) as info:
            parse_reeving(reeving)
        assert info.value.problems == [
            "rope: its stiffness is required: give 'axial_stiffness' (EA, N), or "
            "'metallic_area' (m2) and 'modulus' (Pa)"
        ]

    def test_half_a_metallic_area_and_modulus_pair_names_the_other_way(self):
        reeving = riser_tensioner()
        reeving["rope"] = {"metallic_area": 1.2e-3}
        with pytest.raises(ConfigurationError) as info:
            parse_reeving(reeving)
        assert info.value.problems == [
            "rope: 'modulus' is required with 'metallic_area' (or give 'axial_stiffness' instead)"
        ]

    def test_effect_that_needs_another(self):
        with pytest.raises(ConfigurationError, match="needs effect 'sheave_inertia'"):
            make_unit(drilling_block_train(4), "bearing_friction")

    def test_bad_json_and_solver(self):
        from wire_fmu.core.units.block_train.unit import BlockTrainUnit

        unit = BlockTrainUnit()
        unit.values["reeving"] = "{not json"
        unit.values["solver"] = "euler"
        with pytest.raises(ConfigurationError) as info:
            unit.configure()
        assert "not valid JSON" in str(info.value) and "solver 'euler' is unknown" in str(
            info.value
        )


def test_energy_ledger_books_work_done_by_position_jumps():
    """A master that sets positions without rates still gets a closed ledger."""
    unit = make_unit(single_fall(damping=2e4), "rope_damping", solver="rk4", solver_max_step=1e-3)
    for i in range(100):
        unit.values["line_a.payout"] = 0.01 * math.sin(0.3 * i)  # jumps, rate left at 0
        assert unit.advance(i * 1e-2, 1e-2).success
    v = unit.values
    assert abs(v["external_work"]) > 10.0
    assert abs(v["energy_balance"]) < 1e-5 * abs(v["external_work"])


def test_moving_geometry_fast_planar_path_matches_full_geometry():
    unit = make_unit(drilling_block_train(4), "moving_geometry")
    model = unit.model
    for y in (np.array([0.0]), np.array([3.7]), np.array([-5.2])):
        np.testing.assert_allclose(
            model._planar_segment_lengths(y), model._spatial_segment_lengths(y), rtol=0, atol=1e-12
        )
    # lines stay vertical as the block moves: each line shortens by the block's rise
    rise = model._planar_segment_lengths(np.array([0.0])) - model._planar_segment_lengths(
        np.array([1.0])
    )
    np.testing.assert_allclose(rise[1:5], 1.0, atol=1e-12)
    np.testing.assert_allclose(rise[[0, 5]], 0.0, atol=1e-12)


class TestSpatialGeometry:
    @staticmethod
    def offset_pulley(offset):
        reeving = pulley()
        reeving["anchors"]["hook"]["point"] = [0.5, 0.0, offset]  # hangs off the sheave plane
        return reeving

    def test_a_non_planar_reeving_needs_the_effect(self):
        with pytest.raises(ConfigurationError, match="spatial_geometry"):
            make_unit(self.offset_pulley(0.2))

    def test_fleet_angle_length_and_equilibrium(self):
        offset = 0.2
        unit = make_unit(self.offset_pulley(offset), "spatial_geometry")
        fleet = unit.model.geometry0.fleet_angles[1, 0]
        drop = 10.0  # vertical distance from the sheave's tangent height to the hook
        assert fleet == pytest.approx(math.atan(offset / drop), rel=1e-6)
        # the hanging line is tilted, so the rope holds the weight with T cos(fleet) ... and
        # only the vertical motion of the block stretches it: T = m g / cos(fleet)
        assert unit.values["line_a.tension"] == pytest.approx(1000 * G / math.cos(fleet), rel=1e-6)

    def test_fleet_angle_above_the_limit_is_refused_naming_both_ends(self):
        with pytest.raises(ConfigurationError) as info:
            make_unit(self.offset_pulley(2.0), "spatial_geometry")
        assert "pulley" in str(info.value) and "hook" in str(info.value)


def test_a_body_riding_on_a_driven_body_moves_with_it():
    """A crown on cylinders on a heaving deck: its sheaves move by deck + rod displacement."""
    reeving = drilling_block_train(4)
    reeving["bodies"]["deck"] = {"kind": "driven", "direction": [0, 1, 0], "port": "mover_b"}
    reeving["bodies"]["crown"] = {
        "kind": "driven",
        "direction": [0, 1, 0],
        "port": "mover_a",
        "on": "deck",
    }
    for name, sheave in reeving["sheaves"].items():
        if name.startswith("crown"):
            sheave["body"] = "crown"
    unit = make_unit(reeving, "moving_geometry")
    before = unit.values["block_a.position"]
    # the deck rises 0.3 m and the rod retracts 0.3 m: the crown stays where it was
    unit.values["mover_b.position"], unit.values["mover_a.position"] = 0.3, -0.3
    unit.evaluate_outputs()
    assert unit.values["line_a.tension"] == pytest.approx(1.2e5 * G / 4, rel=1e-8)
    # the deck alone rises: every line between crown and block stretches by 0.3 m
    unit.values["mover_a.position"] = 0.0
    unit.evaluate_outputs()
    assert unit.values["line_a.tension"] > 1.2e5 * G / 4
    # the rope's force on the crown and on the deck (which carries the crown) are equal
    assert unit.values["mover_a.force"] == pytest.approx(unit.values["mover_b.force"], rel=1e-12)
    assert before == unit.values["block_a.position"]


def test_blocks_cannot_ride_on_bodies():
    reeving = drilling_block_train(4)
    reeving["bodies"]["travelling_block"]["on"] = "ground"
    with pytest.raises(ConfigurationError, match="cannot ride"):
        make_unit(reeving)


class TestWrapWarning:
    """A rope wrapping a sheave by more than 200 deg crosses itself in the sheave's plane:
    legal (a capstan, its rope leaving the plane) but most often a wrap direction given the
    wrong way round, so a warning naming the unit, the sheave, the angle and the other wrap."""

    def test_a_flipped_wrap_is_warned_of(self, caplog):
        reeving = riser_tensioner()
        reeving["path"][2]["wrap"] = "cw"  # fixed_1: the rope goes round it the long way
        with caplog.at_level("WARNING", logger="wire_fmu"):
            make_unit(reeving)
        warnings = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
        assert len(warnings) == 1, warnings
        assert warnings[0].startswith(
            "BlockTrain 'test': parameter 'reeving': sheave 'fixed_1' (path node 2): the rope "
            "wraps it by 221.1 deg, more than 200 deg, so in the sheave's plane the rope "
            "leaving it crosses the rope coming in; wrap = 'cw' may be the wrong way round: "
            "with wrap = 'ccw' the rope goes round the other side"
        )
        # by hand: the spans from the moving sheaves at (0.75, 4) and (3.75, 4) m reach
        # fixed_1 at (2.25, 0) m (all r = 0.75 m) on its far sides, each crossing the centre
        # line: theta = 180 deg + 2 asin(2 r / d), d = |(1.5, 4)| m
        theta = 180.0 + 2.0 * math.degrees(math.asin(1.5 / math.hypot(1.5, 4.0)))
        assert theta == pytest.approx(221.1, abs=0.05)

    @pytest.mark.parametrize(
        "reeving",
        [riser_tensioner, drilling_block_train, heave_compensated_block_train],
    )
    def test_the_shipped_reevings_are_not_warned_of(self, reeving, caplog):
        with caplog.at_level("WARNING", logger="wire_fmu"):
            make_unit(reeving())
        assert [r.getMessage() for r in caplog.records if r.levelname == "WARNING"] == []
