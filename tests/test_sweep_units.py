"""Sweep plots name the unit of every axis, in engineering multiples."""

from __future__ import annotations

from matplotlib.figure import Figure

from wire_fmu.sweep import load_sweep_spec
from wire_fmu.sweep import results as sweep_results
from wire_fmu.sweep.units import sweep_units

SPEC = """
name = "small"
[[axes]]
target = "units.cylinder.parameters.precharge_pressure"
values = [13.5e6, 14.5e6]
[[axes]]
target = "drivers.0.significant_height"
values = [3.0, 6.0]
[figures]
peak_tension = "max(rope.path_end.tension)"
"""

META = {
    "column_units": {"rope.path_end.tension": "N", "rope.mover_b.position": "m"},
    "variables": {"rope.mover_b.position": {"unit": "m"}},
    "units": {"cylinder": {"parameters": {"precharge_pressure": {"value": 1.5e7, "unit": "Pa"}}}},
    "drivers": [{"target": "rope.mover_b.position", "kind": "sea_state", "label": "heave"}],
}


def test_units_of_targets_and_figure_columns_come_from_a_case_metadata():
    units = sweep_units(
        [
            "units.cylinder.parameters.precharge_pressure",
            "drivers.0.significant_height",
            "drivers.0.peak_period",
            "run.step",
            "units.cylinder.parameters.reeving.rope",
        ],
        ["rope.path_end.tension"],
        META,
    )
    assert units == {
        "units.cylinder.parameters.precharge_pressure": "Pa",
        "drivers.0.significant_height": "m",
        "drivers.0.peak_period": "s",
        "run.step": "s",
        "units.cylinder.parameters.reeving.rope": "",
        "rope.path_end.tension": "N",
    }


def test_every_sweep_plot_axis_names_its_unit(tmp_path, monkeypatch):
    spec_path = tmp_path / "small.toml"
    spec_path.write_text(SPEC)
    spec = load_sweep_spec(spec_path)
    rows = [
        {
            "case_id": f"c{i}",
            "status": "finished",
            "units.cylinder.parameters.precharge_pressure": p,
            "drivers.0.significant_height": h,
            "peak_tension": 3.6e5 + 1e3 * i,
        }
        for i, (p, h) in enumerate([(13.5e6, 3.0), (13.5e6, 6.0), (14.5e6, 3.0), (14.5e6, 6.0)])
    ]
    units = sweep_units([a.target for a in spec.axes], ["rope.path_end.tension"], META)
    figures = []
    original = Figure.savefig
    monkeypatch.setattr(Figure, "savefig", lambda self, path: figures.append(self))
    sweep_results.plot_summary(rows, spec, tmp_path / "plots", units)
    monkeypatch.setattr(Figure, "savefig", original)
    (fig,) = figures
    pressure, height = fig.axes
    assert pressure.get_xlabel() == "cylinder.precharge_pressure (MPa)"
    assert height.get_xlabel() == "drivers.0.significant_height (m)"
    assert pressure.get_ylabel() == height.get_ylabel() == "peak_tension (kN)"
    assert max(pressure.get_lines()[0].get_xdata()) == 14.5
    labels = [t.get_text() for t in height.get_legend().get_texts()]
    assert labels == ["precharge_pressure = 13.5 MPa", "precharge_pressure = 14.5 MPa"]
