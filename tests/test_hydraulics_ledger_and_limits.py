"""Hydraulics energy ledger, limits and configuration checks (no FMI involved).

The ledger closes in normal operation and through cushion and stop impacts; a
step that would pass a limit is refused, saying which; bad parameters and an
impossible start are configuration errors listing every problem. The physics
against closed forms is in ``test_hydraulics_physics`` and
``test_hydraulics_mechanics``.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.units.hydraulics.unit import HydraulicsUnit

from .hydraulics_helpers import (
    ALL_EFFECTS,
    F_EQ,
    gas_spring,
    make_unit,
    quiet_cylinder,
    run,
)


# ------------------------------------------------------------- energy ledger
@pytest.mark.parametrize(
    "effects",
    [
        "",
        "polytropic_gas,line_losses,seal_friction",
        "oil_compressibility,line_losses,line_inertance",
        ALL_EFFECTS,
    ],
)
def test_energy_ledger_closes_in_normal_operation(effects):
    f0 = -4 * 356.0e3
    unit = make_unit(effects)

    def heave(t):
        return f0 * (1 + 0.04 * math.sin(2 * math.pi * 0.2 * t) + 0.02 * math.sin(8.2 * t))

    out = run(
        unit,
        3.0,
        0.01,
        force=heave,
        record=("energy_balance", "dissipated_energy", "external_work"),
    )
    assert np.all(np.diff(out["dissipated_energy"]) >= 0.0)
    tolerance = 1e-7 * np.max(np.abs(out["external_work"])) + 3e-3 * out["dissipated_energy"][-1]
    assert np.max(np.abs(out["energy_balance"])) < tolerance


def test_energy_ledger_closes_through_cushion_and_stop_impacts():
    """A rod whose wire broke: the full gas force drives it into the cushion and stop.

    Without oil compressibility and inertance: with them the released oil column
    swings the chamber pressure down to cavitation (see TestLimits)."""
    unit = make_unit("polytropic_gas,line_losses,seal_friction,end_stops")
    out = run(
        unit,
        2.0,
        0.01,
        force=lambda t: 0.0,
        record=("energy_balance", "dissipated_energy", "rod.position", "rod.velocity"),
    )
    assert unit.values["end_stop.contact"] or out["rod.position"][-1] > 3.6
    assert np.max(out["rod.velocity"]) > 3.0  # it really ran away
    assert np.all(np.diff(out["dissipated_energy"]) >= 0.0)
    assert np.max(np.abs(out["energy_balance"])) < 5e-3 * out["dissipated_energy"][-1]


# ------------------------------------------------------------------- limits
class TestLimits:
    def test_driven_towards_zero_gas_volume_the_step_is_refused(self):
        unit = gas_spring(
            "", accumulator_volume=0.05, accumulator_dead_volume=0.005, precharge_pressure=8.0e6
        )
        unit.values["rod.force"] = F_EQ - 3.0e6
        t, result = 0.0, None
        for _ in range(200):
            before = dict(unit.values)
            state = json.dumps(unit.get_state())
            result = unit.advance(t, 0.01)
            if not result.success:
                break
            t += 0.01
        assert not result.success
        assert "Hydraulics 'test'" in result.message
        assert "gas volume" in result.message and "dead volume 0.005 m3" in result.message
        assert unit.values == before and json.dumps(unit.get_state()) == state
        assert unit.values["gas.volume"] > 0.005
        assert all(math.isfinite(v) for v in unit.values.values() if isinstance(v, float))
        assert not unit.advance(t, 0.01).success  # refused again, deterministically

    def test_an_emptied_accumulator_refuses_the_step(self):
        unit = gas_spring("", accumulator_volume=0.2, precharge_pressure=9.9e6)
        unit.values["rod.force"] = 0.0  # the load is gone: the gas pushes the rod out
        results = [unit.advance(0.01 * i, 0.01) for i in range(100)]
        refused = [r for r in results if not r.success]
        assert refused and "no oil left" in refused[0].message

    def test_cavitation_refuses_the_step(self):
        """A wire break on the default tensioner: released, the rod springs off the
        compressible oil column faster than the 15 m line can feed it, and the
        chamber pressure swings down to cavitation."""
        unit = make_unit("oil_compressibility,line_inertance,line_losses")
        unit.values["rod.force"] = 0.0
        results = [unit.advance(0.01 * i, 0.01) for i in range(20)]
        refused = [r for r in results if not r.success]
        assert refused and "cavitation pressure 10000 Pa" in refused[0].message

    def test_without_end_stops_leaving_the_stroke_refuses_the_step(self):
        unit = gas_spring("", accumulator_volume=1.0, precharge_pressure=1.6e6)
        unit.values["rod.force"] = 0.0
        results = [unit.advance(0.01 * i, 0.01) for i in range(300)]
        refused = [r for r in results if not r.success]
        assert refused and "beyond the stroke 4 m" in refused[0].message
        assert "end_stops" in refused[0].message


# ------------------------------------------------------------ configuration
def test_bad_parameters_give_one_error_listing_every_problem():
    unit = HydraulicsUnit("bad")
    unit.values.update(
        effects="polytropic_gas, line_loss",
        solver="euler",
        bore_diameter=0.1,
        rod_diameter=0.2,
        stroke=0.0,
        pressurised_side="top",
        stop_restitution=1.5,
        seal_coulomb_friction=9e4,
        initial_velocity=1.0,
        bulk_modulus=-1.0,
        polytropic_exponent=0.7,
    )
    with pytest.raises(ConfigurationError) as info:
        unit.configure()
    text = str(info.value)
    for name in (
        "line_loss",
        "euler",
        "rod_diameter",
        "stroke",
        "pressurised_side",
        "stop_restitution",
        "seal_coulomb_friction",
        "initial_velocity",
        "bulk_modulus",
        "polytropic_exponent",
    ):
        assert name in text, name
    assert len(info.value.problems) == 10
    assert text.startswith("Hydraulics 'bad': 10 problems")


def test_an_impossible_start_is_a_configuration_error():
    unit = HydraulicsUnit("start")
    unit.values.update(quiet_cylinder(precharge_pressure=1.2e7))
    unit.values["rod.force"] = F_EQ  # needs 10 MPa, below the 12 MPa pre-charge
    unit.configure()
    with pytest.raises(ConfigurationError, match="below the pre-charge"):
        unit.initialize(0.0)
