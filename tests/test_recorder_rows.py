"""The recorder writes a batch of rows as one array: the same text as row by row.

Each shipped scene here records every macro step; its rows are written both ways as
the run goes (a batch at a time) and compared character for character: one scene
records Reals only, one an Integer among them (written as its digits).
"""

from __future__ import annotations

import pytest

from wire_fmu.master import run as run_module
from wire_fmu.master.observers import CsvRecorder
from wire_fmu.master.results_text import number_lines

pytestmark = pytest.mark.integration


class _CheckedRecorder(CsvRecorder):
    """A recorder that writes each batch row by row too, and keeps where the two differ."""

    batches: list[tuple[int, int, bool]] = []  # (rows, integer columns, same text) per batch

    def _write_rows(self) -> None:
        if self._rows and not self._converted:
            by_row = number_lines([self._values(row) for row in self._rows])
            as_array = number_lines(self._number_cells(self._rows))
            self.batches.append((len(self._rows), len(self._integers), by_row == as_array))
        super()._write_rows()


@pytest.mark.parametrize(("scene", "integers"), [("riser_tensioner", 0), ("scissor_jack", 1)])
def test_a_batch_is_written_as_its_rows_one_by_one_are(scene, integers, tmp_path, monkeypatch):
    monkeypatch.setattr(_CheckedRecorder, "batches", [])
    monkeypatch.setattr(run_module, "CsvRecorder", _CheckedRecorder)
    outcome = run_module.run_scene(scene, tmp_path / scene, plots=False, stop_time=0.2)
    assert outcome.result.status == "finished", outcome.result.message
    batches = _CheckedRecorder.batches
    assert sum(rows for rows, _, _ in batches) == outcome.result.steps + 1  # and the start
    assert {columns for _, columns, _ in batches} == {integers}
    assert all(same for _, _, same in batches), batches
