"""The run report: one HTML page with every part an engineer sends, needing no other file."""

from __future__ import annotations

import base64
import json
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

from wire_fmu.cli import main
from wire_fmu.core.units.block_train.reevings import single_fall
from wire_fmu.tools.report import write_report

SECTIONS = ["scene", "summary", "warnings", "energy", "plots", "reeving", "settings", "columns"]
PNG = b"\x89PNG\r\n\x1a\n"


class _Page(HTMLParser):
    """Every tag's attributes, the ids, and the text."""

    def __init__(self) -> None:
        super().__init__()
        self.tags: list[tuple[str, dict[str, str | None]]] = []
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))

    def handle_data(self, data):
        self.text.append(data)


def _parse(path: Path) -> _Page:
    parsed = _Page()
    parsed.feed(path.read_text(encoding="utf-8"))
    return parsed


def _results(folder: Path, *, status: str = "finished") -> Path:
    """A results folder as a run writes it: a rope on a winch, a bond, an event, a warning."""
    t = np.arange(0.0, 2.0, 0.01)
    data = {
        "time": t,
        "rope.line_a.tension": 117_720.0 + 2e4 * np.sin(3 * t),
        "rope.energy_balance": 1e-3 * t,
        "winch.brake.state": np.where(t < 1.0, 2.0, 0.0),
        "bond.fast_line.energy_residual": 0.1 * t,
    }
    lines = [",".join(repr(float(data[c][i])) for c in data) for i in range(t.size)]
    (folder / "timeseries.csv").write_text(",".join(data) + "\n" + "\n".join(lines) + "\n")
    reeving = single_fall()
    meta = {
        "scene": "demo",
        "description": "A <demo> & its load.\nWatch the tension.",
        "run": {"stop_time": 2.0, "step": 0.002, "algorithm": "gauss_seidel"},
        "columns": list(data),
        "column_units": {
            "time": "s",
            "rope.line_a.tension": "N",
            "rope.energy_balance": "J",
            "winch.brake.state": "1",
            "bond.fast_line.energy_residual": "J",
        },
        "variables": {
            "rope.line_a.tension": {"unit": "N", "description": "Rope tension at line_a"},
            "winch.brake.state": {"unit": "1", "description": "Brake: 0 released, 1 slipping"},
        },
        "units": {
            "rope": {
                "fmu": "BlockTrain",
                "effects": ["rope_damping"],
                "parameters": {
                    "reeving": {"value": reeving, "unit": "text", "given": True},
                    "pretension": {"value": 1000.0, "unit": "N", "given": False},
                },
            },
            "winch": {"fmu": "Winch", "effects": [], "parameters": {}},
        },
        "events": [
            {"time": 1.0, "label": "brake released", "set": {"winch.brake.lever_force": 0.0}}
        ],
        "drivers": [],
        "plots": [
            {"title": "Tension", "ylabel": "tension (N)", "variables": ["rope.line_a.tension"]}
        ],
        "warnings": [{"level": "warning", "source": "wire_fmu.x", "message": "mind the <gap>"}],
        "result": {
            "status": status,
            "message": "" if status == "finished" else "rod went beyond its stroke",
            "end_time": 2.0,
            "wall_time": 0.5,
            "real_time_factor": 4.0,
            "steps": 1000,
            "bond_energy_residual": {"fast_line": 0.2},
            "bond_energy_carried": {"fast_line": 4.2e6},
            "bond_energy_error": {"fast_line": 3.0},
        },
    }
    (folder / "metadata.json").write_text(json.dumps(meta))
    return folder


def test_the_report_has_every_part_in_order(tmp_path):
    page = _parse(write_report(_results(tmp_path)))
    ids = [attrs["id"] for tag, attrs in page.tags if tag == "section"]
    assert ids == SECTIONS
    text = " ".join(page.text)
    assert "A <demo> & its load." in text  # the description, escaped and read back
    assert "mind the <gap>" in text and "brake released" in text
    assert "4.2 MJ" in text and "3 J" in text  # the bond's books in engineering units
    assert "rope_damping" in text and "1000 N" not in text.split("more parameters")[0]
    images = [attrs for tag, attrs in page.tags if tag == "img"]
    assert len(images) == 3  # the scene's plot, the energy plot, the reeving
    assert all(attrs["alt"] for attrs in images)


def test_the_report_is_one_self_contained_file(tmp_path):
    path = write_report(_results(tmp_path))
    page = _parse(path)
    for tag, attrs in page.tags:
        assert tag not in ("script", "link", "iframe", "object", "embed")
        for key in ("src", "href"):
            value = attrs.get(key)
            if value is not None:
                assert value.startswith(("data:image/png;base64,", "#")), (tag, key, value[:40])
        if tag == "img":
            data = base64.b64decode(attrs["src"].split(",", 1)[1], validate=True)
            assert data.startswith(PNG)
    assert "url(" not in path.read_text(encoding="utf-8")  # nothing loaded from the style either


def test_a_run_that_stopped_says_so_among_the_warnings(tmp_path):
    page = _parse(write_report(_results(tmp_path, status="stopped")))
    text = " ".join(page.text)
    assert "the run stopped: rod went beyond its stroke" in text
    statuses = [a for t, a in page.tags if t == "span" and "status" in (a.get("class") or "")]
    assert statuses[0]["class"] == "status stopped"


def test_report_command_writes_the_page_and_refuses_a_folder_without_metadata(tmp_path, capsys):
    (tmp_path / "run").mkdir()
    folder = _results(tmp_path / "run")
    assert main(["report", str(folder), "-o", str(tmp_path / "x.html")]) == 0
    assert (tmp_path / "x.html").is_file() and "report:" in capsys.readouterr().out
    assert main(["report", str(tmp_path / "nothing")]) == 1
    out = capsys.readouterr().out
    assert out.startswith("error:") and "metadata.json" in out


def test_report_command_writes_report_html_into_a_folder_given_as_output(tmp_path, capsys):
    (tmp_path / "run").mkdir()
    folder = _results(tmp_path / "run")
    (tmp_path / "pages").mkdir()
    assert main(["report", str(folder), "-o", str(tmp_path / "pages")]) == 0
    written = tmp_path / "pages" / "report.html"
    assert f"report: {written.resolve()}" in capsys.readouterr().out
    assert [a["id"] for t, a in _parse(written).tags if t == "section"] == SECTIONS
    assert main(["report", str(folder), "-o", str(tmp_path / "nowhere" / "x.html")]) == 1
    out = capsys.readouterr().out
    assert out.startswith(f"error: {tmp_path / 'nowhere' / 'x.html'}: the report cannot be written")
    assert f"no folder {tmp_path / 'nowhere'}" in out and "unexpected" not in out


def test_report_of_a_run_cut_off_mid_line_leaves_the_line_out_and_says_which(
    tmp_path, capsys, caplog
):
    folder = _results(tmp_path)
    table = folder / "timeseries.csv"
    text = table.read_text()
    table.write_text(text[: len(text) - 12])  # the process killed while writing its last row
    last = text.count("\n")
    with caplog.at_level("WARNING", logger="wire_fmu"):
        assert main(["report", str(folder)]) == 0
    assert f"{table}: line {last}, the last, was cut off" in caplog.text
    assert f"the {last - 2} rows before it are read" in caplog.text
    assert "report:" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("", "empty; expected at least the header line"),
        ("t,a.x\n0.0,1.0\n", "expected a header line starting with 'time', found 't,a.x'"),
    ],
)
def test_report_of_an_empty_or_headerless_table_is_an_error_naming_it(
    tmp_path, capsys, text, words
):
    folder = _results(tmp_path)
    (folder / "timeseries.csv").write_text(text)
    assert main(["report", str(folder)]) == 1
    assert capsys.readouterr().out.startswith(f"error: {folder / 'timeseries.csv'}: {words}")


@pytest.mark.integration
def test_run_writes_the_report_of_a_shipped_scene(tmp_path, capsys):
    assert main(["run", "riser_tensioner", "-q", "--stop-time", "0.5", "-o", str(tmp_path)]) == 0
    assert f"report: {(tmp_path / 'report.html').resolve()}" in capsys.readouterr().out
    page = _parse(tmp_path / "report.html")
    assert [a["id"] for t, a in page.tags if t == "section"] == SECTIONS
    images = [a for t, a in page.tags if t == "img"]
    from wire_fmu.master.run import shipped_scenes
    from wire_fmu.master.scene import load_scene

    plots = len(load_scene(shipped_scenes()["riser_tensioner"]).plots)
    assert len(images) == plots + 2  # the scene's plots, the energy plot, the rope's reeving
    assert all(a["src"].startswith("data:image/png;base64,") for a in images)


def test_the_warnings_a_run_logs_are_kept_in_its_metadata(tmp_path):
    import logging

    from wire_fmu.master.run import WarningLog, note_warnings

    meta = tmp_path / "metadata.json"
    meta.write_text(json.dumps({"scene": "demo"}))
    with WarningLog() as said:
        logging.getLogger("wire_fmu.master.x").warning("parameter %r has no influence", "k")
        logging.getLogger("wire_fmu.master.x").warning("parameter %r has no influence", "k")
        logging.getLogger("wire_fmu.master.x").info("not a warning")
        logging.getLogger("elsewhere").warning("not ours")
    logging.getLogger("wire_fmu.master.x").warning("after the run")
    note_warnings(meta, said.messages)
    assert json.loads(meta.read_text())["warnings"] == [
        {
            "level": "warning",
            "source": "wire_fmu.master.x",
            "message": "parameter 'k' has no influence",
        }
    ]
