"""The Markdown tables the benchmarks print and write."""

from __future__ import annotations

from collections.abc import Iterable

__all__ = ["markdown_table"]


def markdown_table(header: str, rows: Iterable[str]) -> str:
    """A Markdown table: the first column aligned left, the others right.

    Parameters
    ----------
    header : str
        The columns' headings, separated by ``" | "``.
    rows : iterable of str
        Each row's cells, formatted (with their units where they have any) and
        separated by ``" | "``.

    Returns
    -------
    str
        The table's lines, joined by newlines (no newline after the last).
    """
    lines = [f"| {header} |", "|---|" + "---:|" * header.count(" | ")]
    lines += [f"| {row} |" for row in rows]
    return "\n".join(lines)
