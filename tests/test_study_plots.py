"""Study diagrams: legends name only what ran, tick labels never collide."""

from __future__ import annotations

from types import SimpleNamespace

import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from wire_fmu.study import accuracy_report
from wire_fmu.study.accuracy_report import AccuracyStudy
from wire_fmu.study.effects_report import plot_effects
from wire_fmu.study.log_ticks import power_of_ten

from .test_study_accuracy import row


def _study(rows) -> AccuracyStudy:
    settings = SimpleNamespace(reference_rtol=1e-10)
    return AccuracyStudy("demo", settings, 4.0, rows, [], [])


def _rows():
    return [
        row("gs linear", "linear", h, 2e-4 * h / 1e-3, 0.3 * 1e-3 / h, algorithm="gauss_seidel")
        for h in (1e-3, 2e-3, 4e-3)
    ] + [row("j constant", "constant", h, 6e-3 * h / 1e-3, 0.25 * 1e-3 / h) for h in (1e-3, 2e-3)]


def _figure_of(draw, study, tmp_path):
    captured = {}
    original = accuracy_report._figure

    def keep(*args):
        fig, ax = original(*args)
        captured["fig"], captured["ax"] = fig, ax
        return fig, ax

    accuracy_report._figure = keep
    try:
        draw(study, tmp_path / "x.png")
    finally:
        accuracy_report._figure = original
    FigureCanvasAgg(captured["fig"]).draw()
    return captured["fig"], captured["ax"]


def _no_collision(fig, labels) -> None:
    renderer = fig.canvas.get_renderer()
    boxes = [t.get_window_extent(renderer) for t in labels if t.get_visible() and t.get_text()]
    assert len(boxes) >= 2
    for i, box in enumerate(boxes):
        for other in boxes[i + 1 :]:
            assert not box.overlaps(other)


@pytest.mark.parametrize("draw", ["plot_work_precision", "plot_convergence"])
def test_the_legend_lists_only_the_families_that_ran(draw, tmp_path):
    fig, ax = _figure_of(getattr(accuracy_report, draw), _study(_rows()), tmp_path)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert {"constant", "linear", "gauss_seidel", "jacobi", "s"} <= set(labels)
    assert "quadratic" not in labels
    assert "monolithic, Radau rtol" not in labels and "monolithic, unit solver" not in labels
    _no_collision(fig, ax.get_xticklabels())
    _no_collision(fig, ax.get_yticklabels())


def test_log_ticks_read_as_powers_of_ten():
    assert power_of_ten(0.2) == r"$2\times10^{-1}$"
    assert power_of_ten(1e-3) == "$10^{-3}$"
    assert power_of_ten(0.0) == ""


def test_effects_chart_says_no_change_instead_of_a_bar_at_an_arbitrary_floor(tmp_path):
    effect = SimpleNamespace(status="finished", saved_share=0.1, label="cylinder: x")
    rows = [
        SimpleNamespace(**vars(effect), output_change=0.5),
        SimpleNamespace(**{**vars(effect), "label": "cylinder: end_stops"}, output_change=0.0),
    ]
    study = SimpleNamespace(rows=rows, scene="demo", baseline_wall_per_sim_s=0.1)
    path = plot_effects(study, tmp_path / "effects.png")
    assert path.stat().st_size > 5_000
