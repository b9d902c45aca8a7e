"""What a callgrind output file says: its total, and the instructions run in each library.

The file format is valgrind's (*Callgrind Format Specification* in its manual). What
is read here:

* ``ob=`` names the object file (executable or shared library) the functions that
  follow belong to; ``fn=`` names a function, ``fl=``/``fi=``/``fe=`` its source file;
  a name is given once as ``(id) name`` and after that as ``(id)`` alone;
* a cost line, a position (a number, or ``+n``, ``-n`` or ``*`` relative to the last
  one) followed by the events' counts (here the instructions, ``Ir``), is the cost of
  that line of the present function;
* ``calls=`` announces a call from the present function to the one ``cfn=`` names
  (in the object file ``cob=`` names, for that call only; without it, the caller's);
  the cost line after it is the call's inclusive cost: counted again in the callee's
  own lines, so skipped in the exclusive costs, and summed by
  :func:`instructions_called_into`;
* ``totals:`` (or ``summary:``) is the file's total;
* ``calls=`` starts with the number of calls (:func:`calls_to` sums them for the
  functions ``cfn=`` names, whose ``(id)`` names ``fn=`` lines share).

The exclusive costs of all functions add up to the total, which the test of this
module checks.
"""

from __future__ import annotations

import re
from collections import Counter
from pathlib import Path

__all__ = [
    "callgrind_total",
    "calls_to",
    "FMU_BINARIES",
    "instructions_called_into",
    "instructions_by_library",
    "instructions_by_object",
    "library_of",
    "LIBRARIES",
    "OTHER",
]

_TOTALS = re.compile(r"^totals:\s+(\d+)", re.MULTILINE)
_SUMMARY = re.compile(r"^summary:\s+(\d+)", re.MULTILINE)
_NAMED = re.compile(r"\((\d+)\)(?:\s+(.*))?")

UNKNOWN_OBJECT = "???"
"""callgrind's name for code in no object file it knows (numba's machine code)."""

FMU_BINARIES = ("/binaries/",)
"""What the path of an FMU's binary contains (its folder in the unzipped FMU)."""

LIBRARIES = (
    ("the Python interpreter", ("libpython",)),
    ("the compiled kernels (numba's machine code)", (UNKNOWN_OBJECT,)),
    ("the C library (malloc, free, memset, memcpy)", ("libc.so", "libc-")),
    ("numpy", ("numpy", "_multiarray_umath", "libopenblas", "libscipy_openblas")),
    ("numba's runtime and dispatch", ("numba", "_nrt_python", "_dispatcher", "_helperlib")),
    ("ctypes and libffi (the FMI calls)", ("_ctypes", "libffi")),
    ("the FMU binaries", FMU_BINARIES),
    ("libm", ("libm.so", "libm-")),
)
"""The groups :func:`library_of` puts object files in, with what their paths contain."""


def callgrind_total(path: Path) -> int:
    """The instructions a callgrind output file counts: its last ``totals:`` line (a dump
    made while the program runs writes ``summary: 0`` in its header), else ``summary:``.

    Parameters
    ----------
    path : Path
        A file written by callgrind (``--callgrind-out-file``, or a dump of it).

    Raises
    ------
    ValueError
        If the file holds no total.
    """
    text = path.read_text(errors="replace")
    found = _TOTALS.findall(text) or _SUMMARY.findall(text)
    if not found:
        raise ValueError(f"{path}: no 'totals:' or 'summary:' line (not a callgrind file?)")
    return int(found[-1])


def instructions_by_object(path: Path) -> Counter[str]:
    """The instructions run in each object file (exclusive costs), from a callgrind file.

    Parameters
    ----------
    path : Path
        A callgrind output file with the event ``Ir`` first.

    Returns
    -------
    Counter
        Instructions per object file's path (:data:`UNKNOWN_OBJECT` for code in none).
    """
    return _costs(path)[0]


def instructions_called_into(path: Path, marks: tuple[str, ...]) -> int:
    """The instructions run inside calls into the object files whose paths contain one of
    ``marks``, made from object files whose paths contain none (everything those calls
    ran, callees included: their inclusive costs).

    Parameters
    ----------
    path : Path
        A callgrind output file with the event ``Ir`` first.
    marks : tuple of str
        What the called object files' paths contain (e.g. ``("/binaries/",)``, the FMUs).
    """

    def inside(obj: str) -> bool:
        return any(mark in obj for mark in marks)

    return sum(
        count
        for (caller, callee), count in _costs(path)[1].items()
        if inside(callee) and not inside(caller)
    )


def calls_to(path: Path, prefix: str) -> int:
    """How many calls the file counts into the functions whose names start with ``prefix``
    (``calls=`` lines under a ``cfn=`` of such a name).

    Parameters
    ----------
    path : Path
        A callgrind output file.
    prefix : str
        The start of the called functions' names, e.g. ``"NRT_MemInfo_alloc"`` (numba's
        allocator: one call per array a compiled function makes).
    """
    names: dict[tuple[str, str], str] = {}
    called = ""
    total = 0
    with path.open(errors="replace") as lines:
        for line in lines:
            if line.startswith("cfn="):
                called = _name(names, "fn", line[4:].strip())
            elif line.startswith("fn="):
                _name(names, "fn", line[3:].strip())  # defines a name cfn= may refer to
            elif line.startswith("calls=") and called.startswith(prefix):
                total += int(line[6:].split()[0])
    return total


def _costs(path: Path) -> tuple[Counter[str], Counter[tuple[str, str]]]:
    """Exclusive instructions per object file, and the inclusive instructions of the calls
    from each object file to each other one (keyed ``(caller, callee)``)."""
    names: dict[tuple[str, str], str] = {}
    by_object: Counter[str] = Counter()
    calls: Counter[tuple[str, str]] = Counter()
    obj = UNKNOWN_OBJECT
    callee: str | None = None  # the object file of the next call, if ``cob=`` named one
    call_cost_next = False
    with path.open(errors="replace") as lines:
        for line in lines:
            first = line[:1]
            if first.isdigit() or first in "+-*":
                fields = line.split()
                if len(fields) < 2:
                    continue
                if call_cost_next:
                    call_cost_next = False
                    target = obj if callee is None else callee
                    if target != obj:
                        calls[(obj, target)] += int(fields[1])
                    callee = None
                    continue
                by_object[obj] += int(fields[1])
            elif line.startswith("ob="):
                obj = _name(names, "ob", line[3:].strip())
            elif line.startswith("cob="):
                callee = _name(names, "ob", line[4:].strip())
            elif line.startswith("calls="):
                call_cost_next = True
    return by_object, calls


def _name(names: dict[tuple[str, str], str], kind: str, text: str) -> str:
    """The name ``text`` gives (``(id) name`` defines one, ``(id)`` refers to it)."""
    found = _NAMED.fullmatch(text)
    if found is None:
        return text or UNKNOWN_OBJECT
    key = (kind, found.group(1))
    if found.group(2):
        names[key] = found.group(2)
    return names.get(key, f"({found.group(1)})")


OTHER = "other (the standard library's C modules, ...)"
"""The group of an object file in none of :data:`LIBRARIES`."""


def library_of(obj: str) -> str:
    """The group of :data:`LIBRARIES` the object file ``obj`` belongs to, else :data:`OTHER`.

    Parameters
    ----------
    obj : str
        An object file's path, as callgrind names it.
    """
    if obj == UNKNOWN_OBJECT:
        return LIBRARIES[1][0]
    for group, marks in LIBRARIES:
        if any(mark in obj for mark in marks if mark != UNKNOWN_OBJECT):
            return group
    return OTHER


def instructions_by_library(path: Path) -> dict[str, int]:
    """The instructions run in each group of :data:`LIBRARIES` (and :data:`OTHER`), from a
    callgrind file, most first.

    Parameters
    ----------
    path : Path
        A callgrind output file with the event ``Ir`` first.
    """
    by_library: Counter[str] = Counter()
    for obj, count in instructions_by_object(path).items():
        by_library[library_of(obj)] += count
    return dict(by_library.most_common())
