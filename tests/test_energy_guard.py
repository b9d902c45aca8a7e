"""The coupling energy guard's books and verdicts, without FMUs.

The guard's physics (a blow-up is a coupling energy error comparable to the
energy the bond carries; a stable coupling's is orders smaller) is tested
against the two-mass oscillator in ``test_master_convergence`` and against
the winch and rope in ``test_hard_cases``; here, its arithmetic and messages.
"""

from __future__ import annotations

import math

import pytest

from wire_fmu.master.energy_guard import DEFAULT_SHARE, EnergyGuard
from wire_fmu.master.scene import SceneError, parse_scene


def test_books_net_and_gross_coupling_energy_and_carried_energy():
    guard = EnergyGuard(["rod", "line"], share=0.1, floor=1.0)
    guard.book({"rod": 0.5, "line": -0.2}, {"rod": -100.0, "line": 40.0}, 0.01)
    guard.book({"rod": -0.1, "line": -0.2}, {"rod": 50.0, "line": 40.0}, 0.01)
    rod, line = guard.bonds["rod"], guard.bonds["line"]
    assert (rod.created, rod.error) == pytest.approx((0.4, 0.6))
    assert rod.carried == pytest.approx(1.5)  # |-100| 0.01 + 50 0.01
    assert (line.created, line.error, line.carried) == pytest.approx((-0.4, 0.4, 0.8))


def test_stops_only_above_both_the_share_and_the_floor():
    guard = EnergyGuard(
        ["rod"], share=0.1, floor=5.0, remedies=["a smaller step", "iterations > 1"]
    )
    guard.book({"rod": 4.0}, {"rod": 1.0}, 10.0)  # 40 % of 10 J carried, but under 5 J
    assert guard.blow_up(1.0, 0.01) is None
    guard.book({"rod": 0.0}, {"rod": 1.0}, 90.0)  # 4 J of 100 J: under 10 %
    assert guard.limit("rod") == pytest.approx(10.0)
    assert guard.blow_up(2.0, 0.01) is None
    guard.book({"rod": 6.5}, {"rod": 0.0}, 0.01)  # 10.5 J of 100 J: over both
    message = guard.blow_up(3.0, 0.01)
    assert message is not None
    for part in (
        "t = 3 s",
        "macro step 0.01 s",
        "bond 'rod' created and destroyed 10.5 J",
        "(net +10.5 J)",
        "10.5 % of the 100 J it carried",
        "energy_guard = 0.1",
        "energy_tolerance 5 J",
        "use a smaller step or iterations > 1",
    ):
        assert part in message, (part, message)


def test_a_limit_cycle_that_creates_and_destroys_alike_is_a_blow_up_too():
    """Slack-and-snap ringing: large residuals of alternating sign, nothing net."""
    guard = EnergyGuard(["line"], share=0.1, floor=1.0)
    for k in range(100):
        guard.book({"line": 3.0 * (-1) ** k}, {"line": 1000.0}, 0.01)  # 10 J a step carried
    assert guard.bonds["line"].created == pytest.approx(0.0, abs=1e-12)
    assert "(net +0 J), 30 % of the 1e+03 J it carried" in guard.blow_up(1.0, 0.01)


def test_names_every_bond_that_blows_up_and_treats_nan_as_a_blow_up():
    guard = EnergyGuard(["a", "b", "c"], share=0.1, floor=1.0)
    guard.book({"a": 50.0, "b": math.nan, "c": 0.0}, {"a": 10.0, "b": 10.0, "c": 10.0}, 1.0)
    message = guard.blow_up(0.5, 0.1)
    assert "bond 'a' created and destroyed 50 J" in message
    assert "bond 'b' created and destroyed nan J" in message
    assert "bond 'c'" not in message


def test_an_infinite_share_turns_the_guard_off():
    guard = EnergyGuard(["rod"], share=math.inf, floor=0.0)
    guard.book({"rod": 1e9}, {"rod": 0.0}, 1.0)
    assert guard.blow_up(1.0, 0.1) is None


def test_the_run_setting_defaults_to_the_measured_share_and_is_checked():
    base = {"name": "s", "units": {"a": {"fmu": "X.fmu"}}}
    assert parse_scene(base, base_dir=".").run.energy_guard == DEFAULT_SHARE
    off = parse_scene({**base, "run": {"energy_guard": math.inf}}, base_dir=".")
    assert math.isinf(off.run.energy_guard)
    for bad in (0.0, -0.1, "high", True, math.nan):
        with pytest.raises(SceneError, match="run.energy_guard must be a positive number"):
            parse_scene({**base, "run": {"energy_guard": bad}}, base_dir=".")
