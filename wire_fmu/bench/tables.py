"""The Markdown tables the benchmarks print and write."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

__all__ = ["markdown_table"]


def markdown_table(headings: Sequence[str], rows: Iterable[Sequence[str]]) -> str:
    """A Markdown table: the first column aligned left, the others right.

    Parameters
    ----------
    headings : sequence of str
        The columns' headings.
    rows : iterable of sequence of str
        Each row's cells, formatted (with their units where they have any).

    Returns
    -------
    str
        The table's lines, joined by newlines (no newline after the last).
    """
    lines = ["| " + " | ".join(headings) + " |", "|---|" + "---:|" * (len(headings) - 1)]
    lines += ["| " + " | ".join(cells) + " |" for cells in rows]
    return "\n".join(lines)
