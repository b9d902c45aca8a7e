"""Files of an extracted SSP package: a reference confined to the package, XML parsed
without entities, DTDs or network access and bounded in size, annotations found."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from lxml import etree

from wire_fmu.master.files import UnreadableFileError, read_regular

from .ssp import NS

__all__ = ["MAX_XML_BYTES"]

_SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*:")
_SHOWN = 60  # characters of a value quoted in a message

MAX_XML_BYTES = 64 << 20
"""Largest SSD or SSV file read, bytes (64 MiB; real ones are kilobytes)."""


def _q(prefix: str, tag: str) -> str:
    return f"{{{NS[prefix]}}}{tag}"


def _shown(value: Any) -> str:
    """``value`` quoted for a message, shortened if long."""
    text = repr(value)
    return text if len(text) <= _SHOWN else text[: _SHOWN - 4] + "...'"


def _inside(
    folder: Path, source: Any, owner: str, problems: list[str], key: str = "source"
) -> Path | None:
    """The file ``source`` (a reference in the SSD) names inside ``folder``, or a problem."""
    if not isinstance(source, str) or not source.strip():
        problems.append(f"{owner}: '{key}' is required (a file in the package)")
        return None
    text = source[len("file:") :] if source.startswith("file:") else source
    if "\x00" in text:
        problems.append(f"{owner}: {key} {_shown(source)} has a NUL character")
        return None
    if _SCHEME.match(text) or text.startswith(("/", "\\")) or "\\" in text:
        problems.append(
            f"{owner}: {key} {_shown(source)} is outside the package (expected a relative "
            "path to a file in the package)"
        )
        return None
    base = folder.resolve()
    target = (base / text).resolve()
    if not target.is_relative_to(base) or target == base:
        problems.append(
            f"{owner}: {key} {_shown(source)} is outside the package (expected a relative "
            "path to a file in the package)"
        )
        return None
    if not target.is_file():
        problems.append(f"{owner}: {key} {_shown(source)} is not a file in the package")
        return None
    return target


def _parser() -> etree.XMLParser:
    """An XML parser that resolves no entities and loads no DTD or network resource."""
    return etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        huge_tree=False,
        remove_comments=True,
        remove_pis=True,
    )


def _read_xml(path: Path, label: str, problems: list[str]) -> etree._Element | None:
    """The root element of the XML file ``path`` (bounded in size), or a problem."""
    try:
        data = read_regular(path, MAX_XML_BYTES)
    except UnreadableFileError as err:
        problems.append(f"{label}: cannot be read ({err})")
        return None
    try:
        return etree.fromstring(data, _parser())
    except etree.XMLSyntaxError as err:
        problems.append(f"{label}: not well-formed XML ({err.msg})")
    except (etree.LxmlError, ValueError) as err:  # UnicodeDecodeError is a ValueError
        problems.append(f"{label}: not readable XML ({type(err).__name__}: {err})")
    return None


def _annotation(element: etree._Element, kind: str) -> etree._Element | None:
    for note in element.findall(f"{_q('ssd', 'Annotations')}/{_q('ssc', 'Annotation')}"):
        if note.get("type") == kind and len(note):
            return note[0]
    return None
