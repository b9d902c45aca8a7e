"""A run's results as a DataFrame with units, and a unit for every column of ``metadata.json``.

A short run of the shipped drawworks scene (winch and block train, one bond,
both units' energy ledgers) is read back: every column has a unit; the units
of the unit variables are those the core units declare; the master's own
columns (time, bond channels, the ledger sum) are in units consistent with
the units' declarations (power = effort x flow, energy = power x time); the
numbers read are the file's, and are in the units given (the hook height
and load of the scene's own data). Bad folders give a clear error, a run cut
off gives the rows it wrote and says so.
"""

from __future__ import annotations

import csv
import json
import math
import shutil
from collections import Counter
from pathlib import Path

import pytest

from wire_fmu.master.column_units import DIMENSIONLESS, TEXT, UNDECLARED, variable_unit
from wire_fmu.master.observers import LEDGER_TERMS
from wire_fmu.master.plots import read_results
from wire_fmu.master.run import (
    IncompleteResultsWarning,
    Outcome,
    ResultsError,
    find_scene,
    load_scene_file,
    read_results_frame,
    run_scene,
)
from wire_fmu.registry import unit_type

pytestmark = pytest.mark.integration

STOP_TIME = 0.05
"""Simulated time of the run, s: a few recorded rows, the load held by the brake."""

SI = {"s": Counter(s=1), "J": Counter(kg=1, m=2, s=-2), "W": Counter(kg=1, m=2, s=-3)}
"""Dimensions of the units the master gives its own columns in (SI base units)."""


@pytest.fixture(scope="module")
def outcome(tmp_path_factory) -> Outcome:
    """The drawworks scene run for :data:`STOP_TIME` on FMUs built for this module (the
    FMU folder given as a string, as a user would type it)."""
    fmu_dir = tmp_path_factory.mktemp("results_frame_fmus")
    out = tmp_path_factory.mktemp("results_frame_run") / "drawworks"
    done = run_scene("drawworks", out, fmu_dir=str(fmu_dir), stop_time=STOP_TIME, plots=False)
    assert done.result.status == "finished", done.result.message
    return done


@pytest.fixture(scope="module")
def meta(outcome) -> dict:
    return json.loads((outcome.directory / "metadata.json").read_text())


def csv_rows(path: Path) -> tuple[list[str], list[list[str]]]:
    with path.open(newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def declared_unit(outcome: Outcome, column: str) -> str:
    """The unit the core unit declares for a unit variable's column (``unit.variable``)."""
    unit, _, name = column.partition(".")
    declared = unit_type(outcome.scene.units[unit].fmu).core_class().variable(name)
    if declared.type is str:
        return TEXT
    return declared.unit if declared.type is float else DIMENSIONLESS


def dimensions(outcome: Outcome, column: str, units: dict[str, str]) -> Counter:
    """SI base-unit exponents of a unit variable's column, from its FMU's unit definitions."""
    slave = outcome.simulation.slaves[column.split(".", 1)[0]]
    (base,) = [
        u.baseUnit for u in slave.model_description.unitDefinitions if u.name == units[column]
    ]
    assert base.factor == 1.0 and base.offset == 0.0, f"{units[column]} is not coherent SI"
    return Counter({k: getattr(base, k) for k in ("kg", "m", "s", "A", "K", "mol", "cd", "rad")})


def times(a: Counter, b: Counter) -> Counter:
    """Dimensions of a product: the exponents added."""
    product = Counter(a)
    product.update(b)
    return product


def same(a: Counter, b: Counter) -> bool:
    """Whether two dimensions are equal (exponents of 0 as good as absent)."""
    return {k: v for k, v in a.items() if v} == {k: v for k, v in b.items() if v}


# ====================================================== metadata.json: a unit for every column
def test_every_column_of_the_table_has_a_unit(outcome, meta):
    header, _ = csv_rows(outcome.csv_path)
    assert meta["columns"] == header
    assert list(meta["column_units"]) == header
    blank = [c for c, unit in meta["column_units"].items() if unit in (UNDECLARED, None)]
    assert not blank, f"columns without a unit: {blank}"


def test_unit_variables_take_the_units_their_core_unit_declares(outcome, meta):
    units = meta["column_units"]
    recorded = [c for c in units if c.split(".", 1)[0] in outcome.scene.units]
    assert "rope.line_a.tension" in recorded and "winch.brake.state" in recorded
    for column in recorded:
        assert units[column] == declared_unit(outcome, column), column
        assert meta["variables"][column]["unit"] == units[column], column


def test_known_quantities_are_in_their_physical_units(meta):
    units = meta["column_units"]
    assert units["time"] == "s"
    assert units["rope.line_a.tension"] == "N"
    assert units["rope.block_a.position"] == "m"
    assert units["winch.brake.state"] == "1"
    for column in (
        "bond.fast_line.energy_residual",
        "bond.fast_line.energy_carried",
        "energy.units_balance",
        "rope.energy_balance",
        "winch.energy_balance",
    ):
        assert units[column] == "J", column
    assert units["bond.fast_line.power"] == "W"


def test_bond_power_is_in_the_unit_of_effort_times_flow(outcome, meta):
    """The master's power unit agrees with the units the bond's FMUs declare its effort and flow."""
    units = meta["column_units"]
    bond = outcome.scene.bonds[0]
    effort, flow = str(bond.effort.source), str(bond.flow.source)
    product = times(dimensions(outcome, effort, units), dimensions(outcome, flow, units))
    assert same(product, SI[units[f"bond.{bond.name}.power"]])
    energy = times(SI[units[f"bond.{bond.name}.power"]], SI[units["time"]])
    for channel in ("energy_residual", "energy_carried"):
        assert same(energy, SI[units[f"bond.{bond.name}.{channel}"]]), channel


def test_the_ledger_sum_is_in_the_unit_of_the_ledgers_it_sums(outcome, meta):
    units = meta["column_units"]
    for unit in ("rope", "winch"):
        assert same(dimensions(outcome, f"{unit}.energy_balance", units), SI["J"])
    assert same(SI[units["energy.units_balance"]], SI["J"])
    frame = outcome.frame()
    total = frame["rope.energy_balance"] + frame["winch.energy_balance"]
    assert (frame["energy.units_balance"] - total).abs().max() <= 1e-12 * max(
        1.0, total.abs().max()
    )


def test_every_units_whole_ledger_is_recorded_though_the_scene_names_few_outputs(outcome):
    """The drawworks names a handful of outputs; each unit's ledger terms come with its
    residual (what the report's energy books show), and they close it."""
    assert outcome.scene.outputs is not None
    frame = outcome.frame()
    for unit in ("rope", "winch"):
        terms = [f"{unit}.{t}" for t in LEDGER_TERMS]
        assert set(terms) <= set(frame.columns), unit
        stored, dissipated, external, balance = (frame[t] for t in terms)
        books = stored - stored.iloc[0] + dissipated - external
        scale = max(1.0, external.abs().max(), stored.abs().max())
        assert ((books - balance) - (books - balance).iloc[0]).abs().max() <= 1e-9 * scale


# ========================================================== the frame: the file's numbers, units
def test_the_frame_holds_the_numbers_of_the_file_exactly(outcome):
    frame = read_results_frame(outcome.directory)
    header, rows = csv_rows(outcome.csv_path)
    assert frame.index.name == "time" and list(frame.columns) == header[1:]
    assert len(frame) == len(rows) >= 5
    assert list(frame.index) == [float(r[0]) for r in rows]
    for i, column in enumerate(header[1:], start=1):
        assert list(frame[column]) == [float(r[i]) for r in rows], column
    assert frame["winch.brake.state"].dtype.kind == "i"


def test_the_frame_carries_the_units_and_how_the_run_ended(outcome, meta):
    frame = outcome.frame()
    assert frame.attrs["units"] == meta["column_units"]
    assert frame.attrs["status"] == "finished" and frame.attrs["complete"] is True
    assert frame.attrs["scene"] == "drawworks"
    assert frame.attrs["end_time"] == pytest.approx(STOP_TIME)
    assert frame.index[-1] == pytest.approx(STOP_TIME)


def test_the_numbers_are_in_the_units_given(outcome):
    """The hook height and load of the scene's data, held by the brake, read in m and N.

    The block starts 15 m up (the reeving's ``position``) and 10 lines carry
    its 120 t: their tensions add up to its weight within the sheaves'
    efficiencies (0.9615 each; at most 11 between the fast line and the deadline).
    """
    frame = outcome.frame()
    reeving = load_scene_file(find_scene("drawworks")).units["rope"].parameters["reeving"]
    block = reeving["bodies"]["travelling_block"]
    assert frame.attrs["units"]["rope.block_a.position"] == "m"
    assert frame["rope.block_a.position"].sub(block["position"]).abs().max() < 0.05
    assert frame.attrs["units"]["rope.line_a.tension"] == "N"
    weight = block["mass"] * 9.81
    lines = 2 * sum(s["body"] == "travelling_block" for s in reeving["sheaves"].values())
    share = frame["rope.line_a.tension"] * lines / weight
    assert share.between(0.9615**11, 1 / 0.9615**11).all(), share.describe()


def test_the_existing_column_reader_reads_the_same_table(outcome):
    frame = outcome.frame()
    columns = read_results(outcome.csv_path)
    assert list(columns["time"]) == list(frame.index)
    assert list(columns["rope.line_a.tension"]) == list(frame["rope.line_a.tension"])


# =================================================================== bad folders, cut-off runs
def copy_run(outcome: Outcome, tmp_path: Path) -> Path:
    folder = tmp_path / "copy"
    shutil.copytree(outcome.directory, folder)
    return folder


def edit_meta(folder: Path, change) -> None:
    path = folder / "metadata.json"
    meta = json.loads(path.read_text())
    change(meta)
    path.write_text(json.dumps(meta))


def test_a_missing_folder_is_named(tmp_path):
    with pytest.raises(ResultsError, match=r"nowhere: no such folder; expected .*timeseries.csv"):
        read_results_frame(tmp_path / "nowhere")


def test_a_file_given_as_the_folder_is_named(outcome):
    with pytest.raises(ResultsError, match="timeseries.csv: not a folder"):
        read_results_frame(outcome.csv_path)


def test_a_table_without_its_metadata_is_refused_naming_the_file(outcome, tmp_path):
    folder = copy_run(outcome, tmp_path)
    (folder / "metadata.json").unlink()
    with pytest.raises(ResultsError, match="metadata.json: no such file; the units"):
        read_results_frame(folder)


def test_a_folder_without_a_table_is_named(outcome, tmp_path):
    folder = copy_run(outcome, tmp_path)
    (folder / "timeseries.csv").unlink()
    with pytest.raises(ResultsError, match="timeseries.csv: no such file"):
        read_results_frame(folder)


def test_metadata_that_is_not_json_is_named(outcome, tmp_path):
    folder = copy_run(outcome, tmp_path)
    (folder / "metadata.json").write_text('{"scene": ')
    with pytest.raises(ResultsError, match="metadata.json: cannot be read as JSON"):
        read_results_frame(folder)


def test_metadata_of_another_table_is_refused_naming_the_columns(outcome, tmp_path):
    folder = copy_run(outcome, tmp_path)
    edit_meta(folder, lambda m: m["column_units"].pop("rope.line_a.tension"))
    with pytest.raises(ResultsError, match=r"no unit for column\(s\) rope.line_a.tension"):
        read_results_frame(folder)
    edit_meta(folder, lambda m: m.pop("column_units"))
    with pytest.raises(ResultsError, match="has no 'column_units'"):
        read_results_frame(folder)


def test_a_run_cut_off_mid_row_gives_the_rows_it_wrote_and_says_so(outcome, tmp_path):
    """A process killed while writing: the last row half written, no summary in the metadata."""
    folder = copy_run(outcome, tmp_path)
    text = (folder / "timeseries.csv").read_text()
    (folder / "timeseries.csv").write_text(text[: len(text) - 12])
    edit_meta(folder, lambda m: m.pop("result"))
    with pytest.warns(IncompleteResultsWarning) as caught:
        frame = read_results_frame(folder)
    said = str(caught[0].message)
    assert str(folder) in said and "cut off" in said and "no summary" in said
    assert f"timeseries.csv line {text.count(chr(10))}, the last, was cut off" in said
    header, rows = csv_rows(outcome.csv_path)
    assert len(frame) == len(rows) - 1
    assert list(frame["rope.line_a.tension"]) == [
        float(r[header.index("rope.line_a.tension")]) for r in rows[:-1]
    ]
    assert frame.attrs["complete"] is False and frame.attrs["status"] is None
    assert frame.attrs["units"]["rope.line_a.tension"] == "N"


def test_a_run_that_stopped_is_read_with_a_warning_naming_why(outcome, tmp_path):
    folder = copy_run(outcome, tmp_path)

    def stopped(meta: dict) -> None:
        meta["result"].update(status="stopped", message="energy guard on bond fast_line")

    edit_meta(folder, stopped)
    with pytest.warns(IncompleteResultsWarning, match="stopped at t = .* energy guard"):
        frame = read_results_frame(folder)
    assert frame.attrs["status"] == "stopped" and frame.attrs["complete"] is False
    assert len(frame) == len(csv_rows(outcome.csv_path)[1])


def test_a_table_of_the_header_alone_is_an_empty_frame_with_units(outcome, tmp_path):
    folder = copy_run(outcome, tmp_path)
    header = (folder / "timeseries.csv").read_text().splitlines()[0]
    (folder / "timeseries.csv").write_text(header + "\r\n")
    frame = read_results_frame(folder)
    assert frame.empty and list(frame.columns) == header.split(",")[1:]
    assert frame.attrs["units"]["time"] == "s"
    assert all(dtype.kind == "f" for dtype in frame.dtypes)


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("", "empty; expected at least the header line"),
        ("time,a.x", "its header line is cut off"),
        ("t,a.x\n0.0,1.0\n", "expected a header line starting with 'time'"),
        ("time,a.x\n0.0,1.0\n0.1,lots\n", "column 'a.x' holds cells that are not numbers"),
    ],
)
def test_a_table_not_as_a_run_writes_it_is_refused_naming_it(tmp_path, text, words):
    (tmp_path / "timeseries.csv").write_text(text)
    meta = {"column_units": {"time": "s", "a.x": "m"}, "result": {"status": "finished"}}
    (tmp_path / "metadata.json").write_text(json.dumps(meta))
    with pytest.raises(ResultsError, match="timeseries.csv: " + words):
        read_results_frame(tmp_path)
    if "not numbers" not in words:  # the column reader reads a text cell as NaN
        with pytest.raises(ResultsError, match="timeseries.csv: " + words):
            read_results(tmp_path / "timeseries.csv")


def test_both_readers_leave_out_a_cut_off_last_line_naming_it(tmp_path, caplog):
    table = tmp_path / "timeseries.csv"
    table.write_text("time,a.x\r\n0.0,1.0\r\n0.5,2.0\r\n1.0,3")
    meta = {"column_units": {"time": "s", "a.x": "m"}, "result": {"status": "finished"}}
    (tmp_path / "metadata.json").write_text(json.dumps(meta))
    with pytest.warns(IncompleteResultsWarning, match="timeseries.csv line 4, the last, was cut"):
        frame = read_results_frame(tmp_path)
    with caplog.at_level("WARNING", logger="wire_fmu.master.plots"):
        columns = read_results(table)
    assert f"{table}: line 4, the last, was cut off" in caplog.text
    assert list(frame["a.x"]) == list(columns["a.x"]) == [1.0, 2.0]


def test_a_row_of_another_width_is_refused_naming_its_line(tmp_path):
    table = tmp_path / "timeseries.csv"
    table.write_text("time,a.x\n0.0,1.0\n0.5\n1.0,3.0,4.0\n1.5,2.0\n")
    lines = r"line 3 \(1 cell\), 4 \(3 cells\) differ"
    with pytest.raises(ResultsError, match=r"expected 2 cells in every line, .* " + lines):
        read_results(table)


def test_text_columns_stay_text_and_numbers_read_nan_and_inf(tmp_path):
    (tmp_path / "timeseries.csv").write_text(
        "time,j.solver,j.x\r\n0.0,nan,nan\r\n0.5,,inf\r\n1.0,rk4,-inf\r\n"
    )
    meta = {
        "column_units": {"time": "s", "j.solver": TEXT, "j.x": "m"},
        "result": {"status": "finished", "end_time": 1.0},
    }
    (tmp_path / "metadata.json").write_text(json.dumps(meta))
    frame = read_results_frame(tmp_path)
    assert list(frame["j.solver"]) == ["nan", "", "rk4"]
    x = list(frame["j.x"])
    assert math.isnan(x[0]) and x[1:] == [math.inf, -math.inf]


# ========================================================== units from the model description
def test_a_variable_takes_its_own_unit_else_its_declared_types():
    from fmpy.model_description import ScalarVariable, SimpleType

    force = SimpleType(name="Force", type="Real", unit="N")
    assert variable_unit(ScalarVariable(name="f", type="Real", declaredType=force)) == "N"
    assert variable_unit(ScalarVariable(name="f", type="Real", unit="kN", declaredType=force)) == (
        "kN"
    )
    assert variable_unit(ScalarVariable(name="x", type="Real")) == UNDECLARED
    assert variable_unit(ScalarVariable(name="n", type="Integer")) == DIMENSIONLESS
    assert variable_unit(ScalarVariable(name="b", type="Boolean")) == DIMENSIONLESS
    assert variable_unit(ScalarVariable(name="s", type="String")) == TEXT
