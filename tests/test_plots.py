"""Plots a person can read: engineering units, references, states, envelopes, legends outside."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from matplotlib import mathtext
from matplotlib.backends.backend_agg import FigureCanvasAgg

from wire_fmu.master.plot_figure import PlotContext, PlotRequest, plot_figure
from wire_fmu.master.plot_references import references
from wire_fmu.master.plot_signals import busiest_window, envelope, is_discrete, state_levels
from wire_fmu.master.plot_ticks import power_of_ten
from wire_fmu.master.plot_units import display_unit, pretty_unit
from wire_fmu.master.plots import plot_results

BRAKE = "Band brake: 0 released, 1 slipping, 2 holding"
REEVING = {
    "rope": {"axial_stiffness": 5.8e7, "breaking_load": 1.0e6},
    "bodies": {"block": {"kind": "block", "port": "block_a", "floor": {"position": 12.0}}},
}


@pytest.mark.parametrize(
    ("unit", "largest", "label", "factor"),
    [
        ("N", 117_720.0, "kN", 1e3),
        ("N", 2.8e6, "kN", 1e3),  # tension stays in kN up to 10 MN
        ("N", 25.0, "N", 1.0),
        ("Pa", 1.475e7, "MPa", 1e6),
        ("Pa", 6.3e3, "kPa", 1e3),
        ("J", 4.7e6, "MJ", 1e6),
        ("W", 2.0e5, "kW", 1e3),
        ("N.m", 5.0e4, "kN·m", 1e3),
        ("m", 15.0, "m", 1.0),
        ("1", 2.0, "", 1.0),
    ],
)
def test_display_units_are_the_engineering_ones(unit, largest, label, factor):
    shown = display_unit(unit, largest)
    assert (shown.label, shown.factor) == (label, factor)
    assert shown.show(largest) == pytest.approx(largest / factor)


@pytest.mark.parametrize(
    ("unit", "text"),
    [
        ("N.m", "N·m"),
        ("kg.m2", "kg·m²"),
        ("m/s2", "m/s²"),
        ("m3", "m³"),
        ("1", ""),
        ("rad/s", "rad/s"),
    ],
)
def test_unit_symbols_are_printed_as_written(unit, text):
    assert pretty_unit(unit) == text


def test_state_levels_are_read_from_the_description():
    assert state_levels(BRAKE) == {0: "released", 1: "slipping", 2: "holding"}
    thread = "Thread: 0 frictionless, 1 sliding, 2 stuck, 3 creeping (regularised)"
    assert state_levels(thread)[3] == "creeping (regularised)"
    assert state_levels("Number of slack rope spans") == {}


def test_a_discrete_state_is_a_pure_number_taking_few_whole_values():
    assert is_discrete(np.array([0.0, 2.0, 2.0, 1.0]), "1")
    assert not is_discrete(np.array([0.0, 2.0]), "rad/s")
    assert not is_discrete(np.array([0.0, 0.5]), "1")
    assert not is_discrete(np.arange(100.0), "1")  # a counter, drawn as a line


def test_fast_oscillation_is_summarised_as_an_envelope_a_slow_one_is_not():
    t = np.arange(0.0, 40.0, 0.01)
    fast = 100.0 + 5.0 * np.sin(2 * np.pi * 12.0 * t)  # stick-slip: 12 Hz at 100 Hz output
    slow = 100.0 + 5.0 * np.sin(2 * np.pi * 0.1 * t)
    summary = envelope(t, fast)
    assert summary is not None and envelope(t, slow) is None
    assert summary.low.min() == pytest.approx(fast.min()) and summary.high.max() == fast.max()
    assert np.all(summary.low <= summary.mean) and np.all(summary.mean <= summary.high)
    assert summary.window == pytest.approx(40.0 / 300, rel=1e-2)
    burst = np.where((t > 20) & (t < 21), fast, 100.0)
    window = busiest_window(burst, 50)
    assert 19.9 <= t[window][0] and t[window][-1] <= 21.1


def _parameters(**rope):
    rope_parameters = {"reeving": {"value": REEVING, "unit": "text", "given": True}}
    rope_parameters.update({k: {"value": v, "given": True} for k, v in rope.items()})
    return {"rope": rope_parameters, "cylinder": {"stroke": {"value": 3.81, "unit": "m"}}}


def test_references_come_from_the_run_parameters():
    set_free = _parameters(initial_equilibrium=False, pretension=356.0e3)
    tension = references("rope.line_a.tension", set_free)
    assert [(r.label, r.value, r.kind) for r in tension] == [
        ("breaking load", 1.0e6, "limit"),
        ("set tension", 356.0e3, "set"),
    ]
    at_equilibrium = _parameters(initial_equilibrium=True, pretension=356.0e3)
    assert [r.label for r in references("rope.tension_max", at_equilibrium)] == ["breaking load"]
    assert [r.value for r in references("rope.block_a.position", set_free)] == [12.0]
    assert [r.value for r in references("cylinder.rod.position", set_free)] == [0.0, 3.81]
    assert references("cylinder.rod.velocity", set_free) == []
    assert references("other.line_a.tension", set_free) == []  # another unit's parameters


def _tension_run() -> dict[str, np.ndarray]:
    t = np.arange(0.0, 20.0, 0.01)
    return {
        "time": t,
        "rope.line_a.tension": 117_720.0 + 20e3 * np.sin(t),
        "winch.drum.speed": 12.0 * np.sin(0.3 * t),
        "winch.brake.state": np.where(t < 5.0, 2.0, 0.0),
    }


_CONTEXT = PlotContext(
    units={
        "time": "s",
        "rope.line_a.tension": "N",
        "winch.drum.speed": "rad/s",
        "winch.brake.state": "1",
        "cylinder.gas.pressure": "Pa",
        "cylinder.chamber.pressure": "Pa",
    },
    descriptions={"winch.brake.state": BRAKE},
    parameters=_parameters(initial_equilibrium=True),
    events=((1.0, "brake released"), (4.0, "stop")),
)


def _drawn(fig):
    FigureCanvasAgg(fig).draw()  # lays out the legends, resolves the tick labels
    return fig.axes


def test_tension_is_in_kilonewtons_without_offset_and_its_limit_named():
    request = PlotRequest("Fast-line tension", ("rope.line_a.tension",), "tension (N)")
    (ax,) = _drawn(plot_figure(request, _tension_run(), _CONTEXT))
    assert ax.get_ylabel() == "tension (kN)"
    assert ax.yaxis.get_offset_text().get_text() == ""
    line = ax.get_lines()[0]
    assert np.max(line.get_ydata()) == pytest.approx(137.72, rel=1e-4)
    labels = ax.get_legend_handles_labels()[1]
    assert "breaking load 1000 kN (above)" in labels  # far off the data: named, not drawn
    assert "scheduled events" in labels


def test_a_brake_state_gets_its_own_axis_with_named_levels():
    request = PlotRequest(
        "Drum speed and brake", ("winch.drum.speed", "winch.brake.state"), "rad/s ; state"
    )
    speed, state = _drawn(plot_figure(request, _tension_run(), _CONTEXT))
    assert speed.get_ylabel() == "drum speed (rad/s)"
    assert [t.get_text() for t in state.get_yticklabels()] == [
        "0 released",
        "1 slipping",
        "2 holding",
    ]
    assert state.get_ylabel() == "brake state"
    assert speed.get_title() == "Drum speed and brake"


def test_legends_stand_outside_the_data():
    request = PlotRequest("Fast-line tension", ("rope.line_a.tension",), "tension (N)")
    fig = plot_figure(request, _tension_run(), _CONTEXT)
    (ax,) = _drawn(fig)
    renderer = fig.canvas.get_renderer()
    legend = ax.get_legend().get_window_extent(renderer)
    assert legend.x0 >= ax.get_window_extent(renderer).x1


def test_a_curve_lying_on_another_stays_visible_and_their_difference_is_shown():
    t = np.linspace(0.0, 30.0, 3001)
    gas = 14.75e6 + 0.15e6 * np.sin(0.5 * t)
    data = {
        "time": t,
        "cylinder.gas.pressure": gas,
        "cylinder.chamber.pressure": gas + 5e3 * np.cos(0.5 * t),
    }
    request = PlotRequest(
        "Gas pressure", ("cylinder.gas.pressure", "cylinder.chamber.pressure"), "pressure (Pa)"
    )
    main, difference = _drawn(plot_figure(request, data, _CONTEXT))
    assert main.get_ylabel() == "pressure (MPa)"
    gas_line, chamber_line = main.get_lines()[:2]
    assert gas_line.get_linestyle() != chamber_line.get_linestyle()
    assert gas_line.get_linewidth() > chamber_line.get_linewidth()  # the lower one is wider
    assert difference.get_ylabel() == "difference (kPa)"
    assert np.max(np.abs(difference.get_lines()[0].get_ydata())) == pytest.approx(5.0, rel=1e-3)


def test_stick_slip_is_drawn_as_an_envelope_with_a_detail_of_the_samples():
    t = np.arange(0.0, 40.0, 0.01)
    data = {"time": t, "rope.line_a.tension": 117e3 + 3e3 * np.sin(2 * np.pi * 10.0 * t)}
    request = PlotRequest("Fast-line tension", ("rope.line_a.tension",), "tension (N)")
    main, detail = _drawn(plot_figure(request, data, _CONTEXT))
    assert main.collections  # the envelope
    labels = main.get_legend_handles_labels()[1]
    assert any("range per" in label for label in labels)
    assert any("mean per" in label for label in labels)
    assert detail.get_title().startswith("detail of rope.line_a.tension")
    assert detail.get_lines()[0].get_marker() == "."


def test_a_results_folder_is_plotted_again_from_its_own_files(tmp_path: Path):
    data = _tension_run()
    columns = list(data)
    rows = np.column_stack([data[c] for c in columns])
    lines = [",".join(repr(float(v)) for v in row) for row in rows]
    text = ",".join(columns) + "\n" + "\n".join(lines) + "\n"
    (tmp_path / "timeseries.csv").write_text(text)
    meta = {
        "scene": "demo",
        "column_units": dict(_CONTEXT.units),
        "variables": {"winch.brake.state": {"unit": "1", "description": BRAKE}},
        "units": {"rope": {"fmu": "BlockTrain", "effects": [], "parameters": _parameters()}},
        "events": [{"time": 1.0, "label": "go", "set": {}}],
        "plots": [
            {"title": "Fast-line tension", "ylabel": "tension (N)", "variables": [columns[1]]},
            {"title": "Brake", "ylabel": "", "variables": ["winch.brake.state"]},
        ],
    }
    (tmp_path / "metadata.json").write_text(json.dumps(meta))
    written = plot_results(tmp_path)
    assert [p.name for p in written] == ["fast_line_tension.png", "brake.png"]
    assert all(p.stat().st_size > 10_000 for p in written)


@pytest.mark.parametrize(
    ("given", "label"),
    [
        ("torque (N m)", "torque (kN·m)"),
        ("torque (N.m)", "torque (kN·m)"),
        ("speed (N m, motor shaft)", "speed, motor shaft (kN·m)"),
        ("N.m", "motor drive torque (kN·m)"),
        ("force (N)", "motor drive torque (kN·m)"),  # another unit's label names another panel
        ("", "motor drive torque (kN·m)"),
    ],
)
def test_the_scene_s_axis_label_keeps_its_quantity_and_gets_the_unit_shown(given, label):
    t = np.linspace(0.0, 1.0, 11)
    data = {"time": t, "full.motor.drive_torque": 2e3 * t}
    context = PlotContext(units={"full.motor.drive_torque": "N.m"})
    request = PlotRequest("Torque", ("full.motor.drive_torque",), given)
    (ax,) = _drawn(plot_figure(request, data, context))
    assert ax.get_ylabel() == label


@pytest.mark.parametrize(("exponent", "text"), [(6, "×10⁶"), (-3, "×10⁻³"), (12, "×10¹²"), (0, "")])
def test_a_power_of_ten_is_written_with_superscripts(exponent, text):
    assert power_of_ten(exponent) == text


def test_value_axes_label_their_ticks_in_plain_text_and_a_power_of_ten_above(monkeypatch):
    # mathtext's parser costs half a second at the first label a process draws
    def refuse(self, text, *args, **kwargs):
        raise AssertionError(f"mathtext parsed {text!r}")

    monkeypatch.setattr(mathtext.MathTextParser, "parse", refuse)
    run = _tension_run()
    run["winch.drum.speed"] = 3.0e-7 * np.sin(0.3 * run["time"])  # tiny: needs a power
    request = PlotRequest("Drum", ("winch.drum.speed",), "speed (rad/s)")
    (ax, *_) = _drawn(plot_figure(request, run, _CONTEXT))
    assert ax.yaxis.get_offset_text().get_text() == "×10⁻⁷"
    labels = [label.get_text() for label in ax.get_yticklabels()]
    assert labels and not any("$" in label for label in labels)
    assert "−2" in labels and "2" in labels  # the numbers themselves, a true minus sign
    (ax,) = _drawn(plot_figure(PlotRequest("T", ("rope.line_a.tension",), ""), run, _CONTEXT))
    assert ax.yaxis.get_offset_text().get_text() == ""  # no power where none is needed
