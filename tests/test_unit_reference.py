"""The parameter reference (``wire-fmu info``, docs/units.md) shows the units' declarations."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from wire_fmu.cli import main
from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.variables import Causality
from wire_fmu.core.units.hydraulics.unit import HydraulicsUnit
from wire_fmu.registry import UNIT_TYPES
from wire_fmu.unit_reference.catalogue import format_range, unit_reference
from wire_fmu.unit_reference.markdown import units_markdown

DOCS = Path(__file__).resolve().parents[1] / "docs" / "units.md"


def test_the_checked_in_docs_units_md_is_what_the_declarations_give():
    assert DOCS.read_text(encoding="utf-8") == units_markdown(), (
        "docs/units.md is not current: run python -m wire_fmu.unit_reference"
    )


@pytest.mark.parametrize("unit_type", UNIT_TYPES, ids=lambda u: u.name)
def test_info_lists_every_variable_with_its_unit_and_every_effect_and_port(unit_type, capsys):
    assert main(["info", unit_type.name]) == 0
    text = capsys.readouterr().out
    cls = unit_type.core_class()
    types = ("Real", "Integer", "Boolean", "String")
    lines = [ln for ln in text.splitlines() if any(f"  {t}" in ln for t in types)]
    for var in cls.VARIABLES:
        (head,) = [ln for ln in lines if ln[2:].split("  ")[0] == var.name]
        assert (f"[{var.unit}]" in head) == bool(var.unit), head
        if var.causality is not Causality.output:
            assert "default" in head
    catalogue = unit_type.effect_catalogue()
    for effect in catalogue.effects if catalogue else ():
        assert re.search(rf"^  {effect.name}\s", text, re.MULTILINE)
    for port in cls.PORTS:
        assert re.search(rf"^  {port.name}  {port.kind}, {port.side.value} side", text, re.M)


def test_info_with_effects_marks_what_they_leave_without_influence(capsys):
    assert main(["info", "BlockTrain", "--effects", "rope_damping"]) == 0
    lines = capsys.readouterr().out.splitlines()
    marked = {ln.split()[1] for ln in lines if ln.startswith("- ")}
    assert {
        "sheaves.<name>.efficiency",
        "sheaves.<name>.inertia",
        "sheaves.<name>.groove_friction",
        "rope.linear_mass",
    } <= marked
    assert "rope.damping" not in marked and "pretension" not in marked
    at = next(i for i, ln in enumerate(lines) if ln.startswith("- sheaves.<name>.efficiency"))
    note = " ".join(" ".join(lines[at + 1 : at + 5]).split())
    assert "'bearing_friction' (which needs 'sheave_inertia')" in note


def test_info_with_every_needed_effect_marks_nothing_it_needs(capsys):
    assert main(["info", "Hydraulics", "--effects", "seal_friction,line_losses"]) == 0
    lines = capsys.readouterr().out.splitlines()
    marked = {ln.split()[1] for ln in lines if ln.startswith("- ")}
    assert "seal_coulomb_friction" not in marked and "oil_viscosity" not in marked
    assert {"bulk_modulus", "polytropic_exponent", "stop_stiffness"} <= marked


def test_an_unknown_unit_is_named_with_the_unit_types_and_no_traceback(capsys):
    assert main(["info", "Crane"]) == 1
    out = capsys.readouterr()
    assert "'Crane'" in out.out and "Traceback" not in out.out + out.err
    for u in UNIT_TYPES:
        assert u.name in out.out


def test_unknown_effects_are_all_named_with_the_units_effects(capsys):
    assert main(["info", "Winch", "--effects", "drum_inertia", "brakes", "layers"]) == 1
    out = capsys.readouterr().out
    assert "'brakes'" in out and "'layers'" in out and "band_brake" in out
    assert "rope_layers" in out and "Traceback" not in out


def test_a_unit_without_effects_refuses_effects_and_names_are_loose(capsys):
    assert main(["info", "machine_unit", "--effects", "drum_inertia"]) == 1
    assert "no optional effects" in capsys.readouterr().out
    assert unit_reference("block_train").name == "BlockTrain"


def test_ranges_read_as_intervals():
    assert format_range(0.0, None, True) == "> 0"
    assert format_range(0.0, None) == ">= 0"
    assert format_range(0.0, 1.0, True) == "(0, 1]"
    assert format_range(1.0, 2.0) == "[1, 2]"
    assert format_range(None, None) == ""


def _hydraulics(precharge: float) -> HydraulicsUnit:
    unit = HydraulicsUnit()
    unit.values["precharge_pressure"] = precharge
    unit.configure()
    unit.initialize(0.0)
    return unit


def test_the_precharge_window_the_reference_states_is_the_one_the_unit_keeps():
    """Static equilibrium of the default cylinder, computed here: the gas carries the rod force
    and the rod's weight on the bore area; the accumulator must then hold some oil, and not
    more than its dead volume leaves room for (isothermal charge p0 V_full = p V_gas)."""
    v = {x.name: x.start for x in HydraulicsUnit.VARIABLES}
    area = math.pi / 4.0 * v["bore_diameter"] ** 2
    load = -v["rod.force"] + v["moving_mass"] * 9.81
    p_start = v["ambient_pressure"] + load / area
    full = v["accumulator_volume"] + v["gas_bank_volume"]
    dead = v["accumulator_dead_volume"] + v["gas_bank_volume"]
    low = p_start * dead / full
    _hydraulics(low * 1.001)
    _hydraulics(p_start * 0.999)
    for outside in (low * 0.999, p_start * 1.001):
        with pytest.raises(ConfigurationError) as err:
            _hydraulics(outside)
        (window,) = re.findall(r"must lie in \(([\d.e+]+), ([\d.e+]+)\] Pa", str(err.value))
        assert float(window[0]) == pytest.approx(low, rel=1e-5)
        assert float(window[1]) == pytest.approx(p_start, rel=1e-5)
    description = HydraulicsUnit.variable("precharge_pressure").description
    assert "p_start V_dead / V_gas < precharge <= p_start" in description
