"""HTML pieces of a run report: escaped text, tables, embedded images, the page's style.

Everything is inline: the style sheet is in the page, images are ``data:``
URIs, links point inside the page. The page needs no other file and loads
nothing from anywhere.
"""

from __future__ import annotations

import base64
import html
from collections.abc import Iterable, Sequence
from pathlib import Path

__all__ = ["Raw", "esc", "cell", "table", "image", "section", "page", "details", "STYLE"]

STYLE = """
body { font-family: "DejaVu Sans", Arial, sans-serif; margin: 0; color: #1b1b1b;
       background: #f4f5f7; line-height: 1.45; }
main { max-width: 1060px; margin: 0 auto; padding: 24px 28px 48px; background: #fff; }
header { border-bottom: 3px solid #1f5fa8; margin-bottom: 18px; }
h1 { font-size: 26px; margin: 8px 0 4px; }
h2 { font-size: 19px; margin: 30px 0 10px; padding-bottom: 4px; border-bottom: 1px solid #ddd; }
h3 { font-size: 15px; margin: 18px 0 6px; }
nav { font-size: 13px; margin: 8px 0 14px; }
nav a { margin-right: 14px; color: #1f5fa8; text-decoration: none; }
.meta { color: #555; font-size: 13px; margin: 0 0 12px; }
.status { display: inline-block; padding: 2px 10px; border-radius: 10px; font-weight: bold;
          font-size: 13px; color: #fff; vertical-align: middle; }
.status.finished { background: #2e7d32; } .status.stopped { background: #b9770e; }
.status.failed, .status.interrupted { background: #b03a2e; }
.description { white-space: pre-wrap; background: #f7f9fc; border-left: 4px solid #1f5fa8;
               padding: 10px 14px; margin: 0; font-size: 14px; }
table { border-collapse: collapse; font-size: 13px; margin: 6px 0 12px; }
th, td { border: 1px solid #d9dce1; padding: 4px 9px; text-align: left; vertical-align: top; }
th { background: #eef1f5; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
.warnings li { margin: 4px 0; } .warning { color: #8a4b00; } .error { color: #b03a2e; }
.none { color: #555; font-style: italic; }
figure { margin: 14px 0 24px; }
figure img { max-width: 100%; border: 1px solid #e3e3e3; }
figcaption { font-size: 13px; color: #444; margin-top: 4px; }
details { margin: 8px 0; } summary { cursor: pointer; color: #1f5fa8; font-size: 13px; }
code { font-size: 12.5px; background: #f1f1f1; padding: 0 3px; }
pre { font-size: 12px; background: #f7f7f7; padding: 8px; max-height: 420px; overflow: auto; }
th[scope="row"] { font-weight: normal; background: #f6f7f9; }
footer { margin-top: 36px; font-size: 12px; color: #777; }
"""


class Raw(str):
    """HTML that a table cell takes as it is (made by this module's functions, never from data)."""


def esc(text: object) -> str:
    """``text`` as HTML text (``&``, ``<``, ``>`` and quotes escaped).

    Parameters
    ----------
    text : object
        Anything; shown as ``str(text)``.
    """
    return html.escape(str(text), quote=True)


def cell(value: object) -> str:
    """A table cell's content: :class:`Raw` HTML as it is, anything else escaped.

    Parameters
    ----------
    value : object
        The cell.
    """
    return value if isinstance(value, Raw) else esc(value)


def table(
    header: Sequence[str] | None, rows: Iterable[Sequence[object]], numeric: Sequence[int] = ()
) -> str:
    """An HTML table, with a header row unless ``header`` is None; cells escaped.

    Parameters
    ----------
    header : sequence of str or None
        Column headings; None for a table of labels and values (the first
        column as row headings).
    rows : iterable of sequences
        The cells of each row (:class:`Raw` cells are HTML).
    numeric : sequence of int
        Columns aligned as numbers (right, tabular figures).
    """
    head = "" if header is None else "".join(f"<th>{esc(h)}</th>" for h in header)
    body = []
    for row in rows:
        cells = []
        for i, value in enumerate(row):
            if header is None and i == 0:
                cells.append(f'<th scope="row">{cell(value)}</th>')
            elif i in numeric:
                cells.append(f'<td class="num">{cell(value)}</td>')
            else:
                cells.append(f"<td>{cell(value)}</td>")
        body.append(f"<tr>{''.join(cells)}</tr>")
    thead = f"<thead><tr>{head}</tr></thead>" if head else ""
    return f"<table>{thead}<tbody>{''.join(body)}</tbody></table>"


def details(summary: str, body: str) -> Raw:
    """A folded block: ``summary`` shown, ``body`` (HTML) on a click.

    Parameters
    ----------
    summary : str
        The text shown folded.
    body : str
        HTML shown unfolded.
    """
    return Raw(f"<details><summary>{esc(summary)}</summary>{body}</details>")


def image(path: Path, caption: str) -> str:
    """A PNG embedded in the page as a ``data:`` URI, with its caption.

    Parameters
    ----------
    path : Path
        The PNG file.
    caption : str
        Text under the image (also its alternative text).
    """
    data = base64.b64encode(Path(path).read_bytes()).decode("ascii")
    return (
        f'<figure><img alt="{esc(caption)}" src="data:image/png;base64,{data}">'
        f"<figcaption>{esc(caption)}</figcaption></figure>"
    )


def section(anchor: str, title: str, body: str) -> str:
    """A titled section the page's navigation links to (``#anchor``).

    Parameters
    ----------
    anchor : str
        The section's id.
    title : str
        Its heading.
    body : str
        Its HTML.
    """
    return f'<section id="{esc(anchor)}"><h2>{esc(title)}</h2>{body}</section>'


def page(title: str, header: str, sections: Sequence[tuple[str, str, str]], footer: str) -> str:
    """The whole page: head with the inline style, header, navigation, sections, footer.

    Parameters
    ----------
    title : str
        The document title.
    header : str
        HTML of the header (title, status, where the results are).
    sections : sequence of (anchor, title, body)
        The sections in order.
    footer : str
        Text of the footer.
    """
    nav = "".join(f'<a href="#{esc(a)}">{esc(t)}</a>' for a, t, _ in sections)
    body = "".join(section(a, t, b) for a, t, b in sections)
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en"><head><meta charset="utf-8">'
        '<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>{esc(title)}</title><style>{STYLE}</style></head>"
        f"<body><main><header>{header}<nav>{nav}</nav></header>{body}"
        f"<footer>{esc(footer)}</footer></main></body></html>\n"
    )
