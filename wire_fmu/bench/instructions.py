"""What a macro step costs in machine instructions, counted by valgrind's callgrind.

Run ``python -m wire_fmu.bench.instructions [--stop-time S] [--warm-up F]
[--scenes NAME ...] [--out FILE] [--keep FOLDER]``. The scenes (each shipped one, or
each one named) run one after another in one Python process under ``valgrind
--tool=callgrind``, each shortened to ``--stop-time`` (default 1 s). Counting is off
while the process starts and loads its units, and on from the first macro step after
the warm-up (``--warm-up``, a fraction of the run, default 0.4) to the last one (the
results recorder writes its rows as text after it, and that is not counted); an
observer of the run switches it with callgrind's client requests (a small C library
built for the purpose with the machine's C compiler). A compiled kernel's first call
(numba loading it from its cache: thousands of steps' instructions, once per run) is
left out of the count, as :mod:`~wire_fmu.bench.bytecodes` leaves it out; the table
says how many were.

The count is every instruction the machine executes for those steps: the master, the FMI
crossings through ctypes and the FMU binary, the facades and the units' Python, numba
unboxing the kernels' arguments and the compiled kernels themselves, numpy and the
allocator. Of these, the master's own are those outside the FMU binaries' FMI functions
(everything a call into a binary runs, callees included, is the unit's): the master's
Python, its recorder and the ctypes crossing, the figure the master's cost target speaks
of (:mod:`~wire_fmu.bench.master` measures it as a time). Where wall-clock figures
(:mod:`~wire_fmu.bench.master`, :mod:`~wire_fmu.bench.scenes`) move by a fifth from run
to run on a busy machine, this one is the same to the instruction in every run of the
same code and command, however busy the machine: the hash seed is fixed, the address
space is laid out the same in every run (``setarch -R``: objects' addresses, and the
hashes made from them, do not move), the garbage collector runs just before counting
starts (its runs inside the count then follow from the counted steps alone), and the
results recorder writes after the last step, not by the clock. It moves when the code
does, so it compares two versions of the code where a timing cannot tell them apart. It
is not a time -- an instruction that misses the cache costs more than one that does not,
and one machine runs more instructions a nanosecond than another -- so the speed targets
stay with the wall-clock benchmarks; this one says whether a change made a step cheaper,
and where (:mod:`~wire_fmu.bench.bytecodes` counts the interpreter's part alone). A
second table gives each library's share of the instructions (:mod:`.callgrind_file`).

Under valgrind the counted steps run some fifty times slower: a run of the three
hoisting scenes takes about a minute once their kernels are in numba's cache (ten, if
valgrind has to watch numba compile them first). valgrind (with its ``callgrind.h``),
``setarch`` and a C compiler are tools of the machine, not dependencies of the project:
without valgrind the command says so and stops; without ``setarch`` it counts with the
layout the system gives, and runs may then differ by a per cent.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import platform
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from wire_fmu.master.run import shipped_scenes

from .callgrind_file import (
    FMU_BINARIES,
    LIBRARIES,
    OTHER,
    callgrind_total,
    calls_to,
    instructions_by_library,
    instructions_called_into,
)
from .callgrind_window import CallgrindControl, CallgrindWindow, kernel_loads_left_out
from .counted_run import run_counted
from .scene_options import (
    add_counting_window,
    counting_window_problems,
    parse_scene_options,
    report_table,
    scene_parser,
)
from .tables import markdown_table

logger = logging.getLogger(__name__)

MODULE = "wire_fmu.bench.instructions"
"""This module's name, as ``python -m`` runs it under valgrind."""

ALLOCATOR = "NRT_MemInfo_alloc"
"""The start of the names of numba's runtime functions that make an array's memory."""

HASH_SEED = "0"
"""``PYTHONHASHSEED`` of the counted process: the same sets and dicts in every run."""


@dataclass(frozen=True)
class SceneInstructions:
    """Instructions of one scene's counted macro steps.

    Attributes
    ----------
    scene : str
        The scene's name.
    units : int
        Its units.
    steps : int
        Macro steps counted.
    instructions : int
        Instructions executed in them.
    kernel_loads : int
        Compiled kernels' loads in them, left out of the count.
    by_library : dict of str to int
        The instructions by where they ran (see :func:`.callgrind_file.library_of`).
    in_fmi_calls : int
        Of :attr:`instructions`, those run inside the FMU binaries' FMI functions
        (everything a unit's ``fmi2DoStep``, ``fmi2SetReal``, ... ran: its facade, its
        Python, its kernels); the rest is the master's own, the ctypes crossing included.
    arrays_made : int
        Arrays the compiled kernels made in them (calls of numba's allocator,
        :data:`ALLOCATOR`): each costs a ``malloc``, a ``free`` and numba's bookkeeping,
        a few hundred instructions.
    """

    scene: str
    units: int
    steps: int
    instructions: int
    kernel_loads: int = 0
    by_library: dict[str, int] = field(default_factory=dict)
    in_fmi_calls: int = 0
    arrays_made: int = 0

    @property
    def per_step(self) -> float:
        """Instructions per macro step."""
        return self.instructions / max(1, self.steps)

    @property
    def per_unit_step(self) -> float:
        """Instructions per unit and macro step."""
        return self.per_step / max(1, self.units)

    @property
    def arrays_per_step(self) -> float:
        """Arrays the compiled kernels made per macro step."""
        return self.arrays_made / max(1, self.steps)

    @property
    def master_per_unit_step(self) -> float:
        """The master's own instructions (outside the FMI calls) per unit and macro step."""
        return (self.instructions - self.in_fmi_calls) / max(1, self.steps * self.units)


def valgrind_problem() -> str | None:
    """Why this benchmark cannot run here (valgrind not on the ``PATH``), or None."""
    if shutil.which("valgrind") is None:
        return "valgrind not found: install valgrind to count instructions"
    return None


def count_scenes(names: Sequence[str], stop_time: float, warm_up: float, report: Path) -> None:
    """Run ``names`` in this process (under callgrind) and write each one's units and
    counted steps to ``report`` (JSON), in the order of the dumps.

    Parameters
    ----------
    names : sequence of str
        Shipped scenes' names.
    stop_time, warm_up : float
        Simulated time of each run, and before counting starts, s.
    report : Path
        The JSON file written.
    """
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        control = CallgrindControl(Path(tmp))
        for name in names:
            window = CallgrindWindow(warm_up, control)
            with kernel_loads_left_out(window):
                outcome = run_counted(name, Path(tmp) / name, window, stop_time)
            units = len(outcome.simulation.slaves)
            rows.append(
                {"scene": name, "units": units, "steps": window.steps, "loads": window.kernel_loads}
            )
    report.write_text(json.dumps(rows))


def measure(
    names: Sequence[str], stop_time: float, warm_up: float, keep: Path | None = None
) -> list[SceneInstructions]:
    """Count the instructions of ``names``' macro steps after ``warm_up`` (s), one process
    under callgrind running them all.

    Parameters
    ----------
    names : sequence of str
        Shipped scenes' names.
    stop_time, warm_up : float
        Simulated time of each run, and before counting starts, s.
    keep : Path, optional
        A folder to copy callgrind's files into, one per scene
        (``callgrind.<scene>.out``), for ``callgrind_annotate`` to say which functions
        the instructions ran in.

    Raises
    ------
    RuntimeError
        If valgrind is missing, or the counted process fails (with its last lines).
    """
    missing = valgrind_problem()
    if missing:
        raise RuntimeError(missing)
    with tempfile.TemporaryDirectory() as tmp:
        out, report = Path(tmp) / "callgrind.out", Path(tmp) / "steps.json"
        done = subprocess.run(
            _counted_command(out, report, names, stop_time, warm_up),
            env=dict(os.environ, PYTHONHASHSEED=HASH_SEED, OPENBLAS_NUM_THREADS="1"),
            capture_output=True,
            text=True,
        )
        if done.returncode != 0 or not report.exists():
            tail = "\n".join((done.stderr or "").splitlines()[-15:])
            raise RuntimeError(f"the counted run failed (exit code {done.returncode}):\n{tail}")
        rows = json.loads(report.read_text())
        dumps = sorted(Path(tmp).glob("callgrind.out.*"), key=lambda p: int(p.suffix[1:]))
        if len(dumps) != len(rows):
            raise RuntimeError(f"{len(dumps)} callgrind dumps for {len(rows)} scenes")
        if keep is not None:
            keep.mkdir(parents=True, exist_ok=True)
            for row, dump in zip(rows, dumps, strict=True):
                shutil.copyfile(dump, keep / f"callgrind.{row['scene']}.out")
        return [
            SceneInstructions(
                row["scene"],
                row["units"],
                row["steps"],
                callgrind_total(dump),
                row["loads"],
                instructions_by_library(dump),
                instructions_called_into(dump, FMU_BINARIES),
                calls_to(dump, ALLOCATOR),
            )
            for row, dump in zip(rows, dumps, strict=True)
        ]


def _counted_command(
    out: Path, report: Path, names: Sequence[str], stop_time: float, warm_up: float
) -> list[str]:
    """The command that runs this module's counting side (:func:`count_scenes`) on
    ``names`` under callgrind; with the address space laid out the same in every run
    (``setarch -R``), where the machine has ``setarch``."""
    fixed_layout = ["setarch", platform.machine(), "-R"] if shutil.which("setarch") else []
    return [
        *fixed_layout,
        "valgrind",
        "--tool=callgrind",
        "--instr-atstart=no",
        f"--callgrind-out-file={out}",
        sys.executable,
        "-m",
        MODULE,
        "--count",
        str(report),
        "--stop-time",
        str(stop_time),
        "--warm-up-time",
        str(warm_up),
        "--scenes",
        *names,
    ]


def table(rows: list[SceneInstructions]) -> str:
    """Markdown tables: instructions per macro step and per unit and step (and of these,
    the master's own, outside the FMI calls), one row per scene; then each library's
    share of them, one column per scene.

    Parameters
    ----------
    rows : list of SceneInstructions
        One per scene.
    """
    counts = markdown_table(
        "scene | units | macro steps counted | instructions per step | per unit and step"
        " | of which the master's own | arrays the kernels made per step"
        " | kernel loads left out",
        (
            f"{r.scene} | {r.units} | {r.steps} | {r.per_step:,.0f} | {r.per_unit_step:,.0f}"
            f" | {r.master_per_unit_step:,.0f} | {r.arrays_per_step:,.0f} | {r.kernel_loads}"
            for r in rows
        ),
    )
    groups = [group for group, _ in LIBRARIES] + [OTHER]
    shown = [g for g in groups if any(r.by_library.get(g) for r in rows)]
    if not shown:
        return counts
    shares = markdown_table(
        "where the instructions ran | " + " | ".join(r.scene for r in rows),
        (
            f"{group} | "
            + " | ".join(
                f"{100 * r.by_library.get(group, 0) / max(1, r.instructions):.1f} %" for r in rows
            )
            for group in shown
        ),
    )
    return counts + "\n\n" + shares


def _parser() -> argparse.ArgumentParser:
    parser = scene_parser(__doc__.splitlines()[0], list(shipped_scenes()), None)
    add_counting_window(parser, warm_up=0.4)
    parser.add_argument(
        "--keep",
        type=Path,
        metavar="FOLDER",
        help="also keep callgrind's file of each scene here (for callgrind_annotate)",
    )
    # the process valgrind runs: counts the scenes and writes their steps here
    parser.add_argument("--count", type=Path, help=argparse.SUPPRESS)
    parser.add_argument("--warm-up-time", type=float, help=argparse.SUPPRESS)
    return parser


def main(argv: list[str] | None = None) -> None:
    """Command-line entry point.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads the command line.
    """
    parser = _parser()
    args = parse_scene_options(parser, argv)
    if args.count is not None:
        count_scenes(args.scenes, args.stop_time, args.warm_up_time, args.count)
        return
    problems = counting_window_problems(args)
    missing = valgrind_problem()
    if missing:
        problems.append(missing)
    if problems:
        parser.error("; ".join(problems))
    try:
        rows = measure(args.scenes, args.stop_time, args.warm_up * args.stop_time, args.keep)
    except RuntimeError as err:
        parser.exit(1, f"{parser.prog}: {err}\n")
    report_table(table(rows), args.out)


if __name__ == "__main__":
    main()
