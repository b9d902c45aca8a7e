"""One plot of a run as a matplotlib figure: engineering units, references, states, details.

A plot lists recorded columns. They are drawn on stacked panels sharing the
time axis:

* one panel per unit of the continuous columns, values in the engineering
  unit of :func:`~wire_fmu.master.plot_units.display_unit` (tension in kN,
  pressure in MPa, never an offset), each line in its own style so that one
  lying on another stays visible; the reference lines of
  :func:`~wire_fmu.master.plot_references.references` (a reference far off
  the data is named in the legend, not drawn); the scene's event times as
  faint vertical lines;
* when columns of a panel lie within 2 % of the panel's range of its first
  (a gas pressure and the chamber pressure behind a short line), a panel of
  their differences from it below;
* one short panel per discrete state, drawn in steps, its levels named
  (:mod:`~wire_fmu.master.plot_signals`);
* a column that turns faster than the plot can show is drawn as its envelope
  and mean, and a detail panel shows its raw samples where it moves most.

Legends stand to the right of the panels, outside the data.
"""

from __future__ import annotations

import logging
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from .plot_references import Parameters, Reference, references
from .plot_signals import busiest_window, envelope, finite_range, is_discrete, state_levels
from .plot_units import DisplayUnit, display_unit, pretty_unit

__all__ = ["PlotContext", "PlotRequest", "plot_figure"]

logger = logging.getLogger(__name__)

_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf")
_STYLES = ("-", "--", "-.", ":")
_REFERENCE_STYLE = {"limit": ("#7b241c", "--"), "set": ("#196f3d", "-.")}
_WIDTH = 10.0  # in: room for the legends to the right of the panels
_HEIGHTS = {"main": 3.0, "difference": 1.6, "state": 1.3, "detail": 1.9}
_CLOSE = 0.02  # two columns closer than this share of the panel's range get a difference panel
_OFF_SCALE = 0.5  # a reference further than this share of the data's span beyond it is not drawn


@dataclass(frozen=True)
class PlotContext:
    """What the plots of a run know besides the table.

    Attributes
    ----------
    units : mapping of str to str
        Unit of every column (``metadata.json``'s ``column_units``).
    descriptions : mapping of str to str
        Description of each unit variable's column (for state levels).
    parameters : Parameters
        The run's parameters by unit and name (for reference lines).
    events : sequence of (float, str)
        Time (s) and label of each scheduled event.
    """

    units: Mapping[str, str]
    descriptions: Mapping[str, str] = field(default_factory=dict)
    parameters: Parameters = field(default_factory=dict)
    events: Sequence[tuple[float, str]] = ()


@dataclass(frozen=True)
class PlotRequest:
    """One plot: a title, the columns, and the scene's axis label (its unit is replaced)."""

    title: str
    columns: tuple[str, ...]
    ylabel: str = ""


@dataclass
class _Panel:
    kind: str  # "main", "difference", "state" or "detail"
    columns: list[str]
    unit: str = ""


def plot_figure(request: PlotRequest, data: Mapping[str, np.ndarray], context: PlotContext):
    """The figure of one plot (see the module docstring).

    Parameters
    ----------
    request : PlotRequest
        The plot.
    data : mapping of str to ndarray
        Recorded columns by name, ``"time"`` (s) among them, shape (rows,).
    context : PlotContext
        Units, descriptions, parameters and events of the run.

    Returns
    -------
    matplotlib.figure.Figure
        The figure (not saved).
    """
    from matplotlib.figure import Figure

    columns = [c for c in request.columns if c in data]
    for missing in sorted(set(request.columns) - set(columns)):
        logger.warning("plot %r: column %r was not recorded", request.title, missing)
    panels = _panels(columns, data, context)
    heights = [_HEIGHTS[p.kind] for p in panels] or [_HEIGHTS["main"]]
    fig = Figure(figsize=(_WIDTH, sum(heights) + 0.9), dpi=100, layout="constrained")
    grid = fig.add_gridspec(len(heights), 1, height_ratios=heights)
    time = data["time"]
    axes_of_time = []
    home = {}  # the main panel of each column
    for i, panel in enumerate(panels):
        share = axes_of_time[0] if axes_of_time and panel.kind != "detail" else None
        ax = fig.add_subplot(grid[i], sharex=share)
        shown = _DRAW[panel.kind](ax, panel, request, data, context)
        if panel.kind == "main":
            home.update(dict.fromkeys(panel.columns, ax))
        if panel.kind == "detail" and panel.columns[0] in home:
            home[panel.columns[0]].axvspan(*shown, color="0.5", alpha=0.12, lw=0, zorder=0)
        if panel.kind != "detail":
            _draw_events(ax, context.events, time, labelled=not axes_of_time)
            axes_of_time.append(ax)
        _legend(ax)
    if not panels:
        fig.add_subplot(grid[0]).text(0.5, 0.5, "nothing recorded", ha="center")
    for ax in axes_of_time[:-1]:
        ax.tick_params(labelbottom=False)
    if axes_of_time:
        axes_of_time[-1].set_xlabel("time (s)")
        low, high = finite_range(time)
        if high > low:
            axes_of_time[0].set_xlim(low, high)
        axes_of_time[0].set_title(request.title)
    return fig


# ----------------------------------------------------------------------------- panels
def _panels(columns: list[str], data: Mapping[str, np.ndarray], context: PlotContext):
    """The panels of a plot: one per unit of the continuous columns, differences, states."""
    states = [c for c in columns if is_discrete(data[c], context.units.get(c, ""))]
    by_unit: dict[str, list[str]] = {}
    for c in columns:
        if c not in states:
            by_unit.setdefault(context.units.get(c, ""), []).append(c)
    panels: list[_Panel] = []
    details: list[_Panel] = []
    for unit, group in by_unit.items():
        panels.append(_Panel("main", group, unit))
        close = _close_to_first(group, data)
        if close:
            panels.append(_Panel("difference", [group[0], *close], unit))
        details += [_Panel("detail", [c], unit) for c in group if envelope(data["time"], data[c])]
    panels += [_Panel("state", [c], "1") for c in states]
    return panels + details


def _close_to_first(group: list[str], data: Mapping[str, np.ndarray]) -> list[str]:
    """Columns of the panel within :data:`_CLOSE` of its range of the first column."""
    if len(group) < 2:
        return []
    low, high = finite_range(*(data[c] for c in group))
    span = high - low
    if not span > 0.0:
        return []
    first = data[group[0]]
    close = []
    for other in group[1:]:
        gap = np.nanmax(np.abs(data[other] - first)) if first.size else np.nan
        if np.isfinite(gap) and gap <= _CLOSE * span:
            close.append(other)
    return close


def _draw_main(ax, panel: _Panel, request: PlotRequest, data, context: PlotContext) -> None:
    time = data["time"]
    low, high = finite_range(*(data[c] for c in panel.columns))
    shown = display_unit(panel.unit, max(abs(low), abs(high)) if np.isfinite(low) else np.nan)
    for i, column in enumerate(panel.columns):
        _draw_column(ax, time, data[column], column, shown, i, len(panel.columns))
    refs = [r for c in panel.columns for r in references(c, context.parameters)]
    _draw_references(ax, _unique(refs), shown, low, high)
    ax.set_ylabel(_ylabel(request.ylabel, panel, shown, context))
    _plain_numbers(ax)


def _draw_column(
    ax,
    time: np.ndarray,
    values: np.ndarray,
    column: str,
    shown: DisplayUnit,
    i: int,
    count: int,
    colour: str | None = None,
) -> None:
    """A column as a line, or as its envelope and mean when it turns too fast to draw.

    ``i`` of ``count`` columns on the panel sets its colour (unless given),
    line style and width: later ones thinner, so one on another shows.
    """
    colour = colour or _COLOURS[i % len(_COLOURS)]
    summary = envelope(time, values)
    if summary is None:
        width = max(1.0, 2.4 - 0.8 * i) if count > 1 else 1.3
        ax.plot(
            time,
            shown.show(values),
            color=colour,
            lw=width,
            ls=_STYLES[i % len(_STYLES)],
            label=column,
            zorder=3 + i,
        )
        return
    window = f"{1000 * summary.window:.0f} ms" if summary.window < 1 else f"{summary.window:.2g} s"
    ax.fill_between(
        summary.time,
        shown.show(summary.low),
        shown.show(summary.high),
        color=colour,
        alpha=0.28,
        lw=0,
        label=f"{column}: range per {window}",
        zorder=2 + i,
    )
    ax.plot(
        summary.time,
        shown.show(summary.mean),
        color=colour,
        lw=1.0,
        label=f"{column}: mean per {window}",
        zorder=3 + i,
    )


def _draw_difference(ax, panel: _Panel, request: PlotRequest, data, context: PlotContext) -> None:
    """Each close column less the panel's first, in a unit of their own size."""
    base, *others = panel.columns
    differences = [data[other] - data[base] for other in others]
    low, high = finite_range(*differences)
    shown = display_unit(panel.unit, max(abs(low), abs(high)) if np.isfinite(low) else np.nan)
    for i, (other, difference) in enumerate(zip(others, differences, strict=True)):
        colour = _COLOURS[(i + 1) % len(_COLOURS)]
        label = f"{other} − {base}"
        _draw_column(ax, data["time"], difference, label, shown, i, len(others), colour)
    ax.axhline(0.0, color="0.7", lw=0.8, zorder=0)
    unit = f" ({shown.label})" if shown.label else ""
    ax.set_ylabel(f"difference{unit}")
    _plain_numbers(ax)


def _draw_state(ax, panel: _Panel, request: PlotRequest, data, context: PlotContext) -> None:
    (column,) = panel.columns
    values = data[column]
    ax.step(data["time"], values, where="post", color="#6c3483", lw=1.4, label=column)
    levels = state_levels(context.descriptions.get(column, ""))
    seen = np.unique(values[np.isfinite(values)]).astype(int)
    ticks = sorted(set(levels) | set(seen.tolist())) if levels else seen.tolist()
    if levels:
        ticks = list(range(min(ticks), max(ticks) + 1))
    ax.set_yticks(ticks)
    ax.set_yticklabels([f"{n} {levels[n]}" if n in levels else str(n) for n in ticks])
    if ticks:
        ax.set_ylim(min(ticks) - 0.4, max(ticks) + 0.4)
    ax.set_ylabel(_words(column))


def _draw_detail(
    ax, panel: _Panel, request: PlotRequest, data, context: PlotContext
) -> tuple[float, float]:
    (column,) = panel.columns
    time, values = data["time"], data[column]
    window = busiest_window(values, max(50, values.size // 40))
    low, high = finite_range(values)
    shown = display_unit(panel.unit, max(abs(low), abs(high)))
    ax.plot(
        time[window],
        shown.show(values[window]),
        color=_COLOURS[0],
        lw=0.8,
        marker=".",
        ms=3,
        label=f"{column}: every recorded sample",
    )
    t0, t1 = float(time[window][0]), float(time[window][-1])
    ax.set_title(f"detail of {column}, {t0:.2f} to {t1:.2f} s (shaded above)", fontsize="medium")
    ax.set_xlabel("time (s)")
    unit = f" ({shown.label})" if shown.label else ""
    ax.set_ylabel(f"{_words(column)}{unit}")
    _plain_numbers(ax)
    return t0, t1


_DRAW = {
    "main": _draw_main,
    "difference": _draw_difference,
    "state": _draw_state,
    "detail": _draw_detail,
}


# ------------------------------------------------------------------------- decorations
def _draw_references(
    ax, refs: list[Reference], shown: DisplayUnit, low: float, high: float
) -> None:
    """Reference lines near the data; those far off it named in the legend only."""
    from matplotlib.lines import Line2D

    if not np.isfinite(low):
        return
    span = (high - low) or abs(high) or 1.0
    for ref in refs:
        colour, style = _REFERENCE_STYLE[ref.kind]
        value = shown.show(ref.value)
        text = f"{ref.label} {_number(value)} {shown.label}".rstrip()
        if low - _OFF_SCALE * span <= ref.value <= high + _OFF_SCALE * span:
            ax.axhline(value, color=colour, ls=style, lw=1.2, label=text, zorder=1)
        else:
            where = "above" if ref.value > high else "below"
            ax.add_line(Line2D([], [], color=colour, ls=style, lw=1.2, label=f"{text} ({where})"))


def _draw_events(
    ax, events: Sequence[tuple[float, str]], time: np.ndarray, *, labelled: bool
) -> None:
    """The scheduled events' times as faint vertical lines (in the legend once: ``labelled``)."""
    if time.size < 2:
        return
    first = labelled
    for t, _label in events:
        if time[0] < t <= time[-1]:
            ax.axvline(
                t,
                color="0.55",
                lw=0.8,
                ls=":",
                zorder=0,
                label="scheduled events" if first else None,
            )
            first = False


def _legend(ax) -> None:
    handles, labels = ax.get_legend_handles_labels()
    if handles:
        ax.legend(
            handles,
            labels,
            loc="upper left",
            bbox_to_anchor=(1.01, 1.0),
            borderaxespad=0.0,
            fontsize="small",
            frameon=False,
        )
    ax.grid(True, alpha=0.3)


def _plain_numbers(ax) -> None:
    """Tick labels as the numbers themselves, never less an offset (a power of ten may stand
    above very small or large ones): :class:`~.plot_ticks.PlainTicks`."""
    from .plot_ticks import PlainTicks

    ax.yaxis.set_major_formatter(PlainTicks())


def _unique(refs: list[Reference]) -> list[Reference]:
    seen: dict[tuple[str, float], Reference] = {}
    for ref in refs:
        seen.setdefault((ref.label, ref.value), ref)
    return list(seen.values())


def _number(value: float) -> str:
    return f"{value:.4g}"


_LABEL = re.compile(r"\s*(.*?)\s*(?:\(([^)]*)\))?\s*")


def _ylabel(given: str, panel: _Panel, shown: DisplayUnit, context: PlotContext) -> str:
    """The axis label: the scene's quantity with the unit shown, else the column's name.

    The scene's label (``"tension (N)"``; of ``"a ; b"`` the first part) names
    the panel whose unit it gives (``N m`` is ``N.m``; a note after a comma,
    ``"speed (rad/s, motor shaft)"``, is kept), or every panel if it gives
    none; a label that is only a unit (``"rad/s"``) names nothing.
    """
    quantity, said = _LABEL.fullmatch((given or "").split(";")[0]).groups()
    units = {_same(u) for u in (panel.unit, pretty_unit(panel.unit), shown.label)}
    head, _, note = (said or "").partition(",")
    if not quantity or _same(quantity) in units or (said is not None and _same(head) not in units):
        quantity = _words(panel.columns[0])
    elif note.strip():
        quantity = f"{quantity}, {note.strip()}"
    return f"{quantity} ({shown.label})" if shown.label else quantity


_SUPERSCRIPTS = str.maketrans({"²": "2", "³": "3", "⁴": "4", "⁻": "-", "¹": "1", "·": " "})


def _same(unit: str) -> str:
    """A unit made comparable however written: ``N m``, ``N.m``, ``N·m``; ``m^2``, ``m²``."""
    text = unit.translate(_SUPERSCRIPTS).replace("^", "").replace(".", " ").replace("*", " ")
    return " ".join(text.split())


def _words(column: str) -> str:
    """A column's variable as words: ``winch.drum.speed`` -> ``drum speed``."""
    variable = column.split(".", 1)[-1]
    return variable.replace(".", " ").replace("_", " ")
