"""The Python a macro step runs: bytecodes per unit and step, by layer and by function.

Run ``python -m wire_fmu.bench.bytecodes [--stop-time S] [--scenes NAME ...] [--top N]
[--out FILE]``. Each shipped scene (or each one named) is run once, shortened to
``--stop-time`` (default 1 s), with an observer that counts, from the start of the
stepping loop to its end, every bytecode the interpreter executes (:func:`sys.settrace`
with opcode events). The count is the interpreter's work alone, and it is the same on
every machine and in every run: where wall-clock figures (:mod:`~wire_fmu.bench.master`)
move by a quarter from run to run on a busy machine, this one moves only when the code
does. It is not a time: calls into C run no bytecodes, however long they take -- the
compiled kernels, numba unboxing their arguments and boxing their results, numpy on
small arrays, the FMI crossings through ctypes and the FMU binary. A step's time follows
its bytecodes only where the interpreter is most of it (the master's own loop: some tens
of nanoseconds a bytecode); the units' doStep is mostly those calls.

The count is split by where the code lives:

* ``master``: ``wire_fmu/master`` (the coupling, drivers, recorder);
* ``FMU side``: ``wire_fmu/export`` (the FMI facade) and ``wire_fmu/core`` (the units'
  Python around their kernels);
* library code (numpy's Python wrappers, the standard library) counts to the layer
  of the ``wire_fmu`` code that called it.

A compiled kernel's first call (numba loading it from its cache, or compiling it) is a
cost of the start, paid once per run, and is left out of the count.

The results recorder writes its rows at the end of the run rather than every 0.1 s of
wall-clock time, so that the count does not depend on the clock: at full speed a batch
holds hundreds of rows, and its cost per row is numpy's.

Tracing slows the run about a hundredfold; a second of simulated time is enough, as
every macro step of a scene runs much the same code.
"""

from __future__ import annotations

import logging
import sys
import tempfile
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from types import CodeType, FrameType
from typing import Any

from wire_fmu.master.run import shipped_scenes

from .counted_run import run_counted
from .scene_options import (
    add_counting_window,
    counting_window_problems,
    parse_scene_options,
    report_table,
    scene_parser,
)
from .tables import markdown_table

__all__ = ["BytecodeCounter", "SceneBytecodes", "layer_of", "main", "measure", "short_file"]

logger = logging.getLogger(__name__)

LOOP_FUNCTION = "_stepping"
"""The master's function that runs the stepping loop: counting ends when it returns."""

KERNEL_LOAD = "_compile_for_args"
"""numba's function that loads or compiles a compiled function for new argument types."""

LAYERS = {"master": "master", "export": "FMU side", "core": "FMU side"}
"""The layer of each package folder of ``wire_fmu`` (any other folder: ``other``)."""


def layer_of(filename: str) -> str | None:
    """The layer of the code in ``filename``, or None outside the ``wire_fmu`` package.

    Parameters
    ----------
    filename : str
        A code object's file.
    """
    parts = Path(filename).parts
    if "wire_fmu" not in parts:
        return None
    at = len(parts) - 1 - parts[::-1].index("wire_fmu")
    return LAYERS.get(parts[at + 1], "other") if at + 2 < len(parts) else "other"


class BytecodeCounter:
    """An observer that counts the bytecodes of the stepping loop, per code object.

    Counting starts at the first accepted step that ends at or after ``warm_up``
    (the steps before load the units' compiled kernels, take their first events
    and fill the histories: costs a run pays once) and ends with the loop.

    Parameters
    ----------
    warm_up : float
        Simulated time before counting starts, s.

    Attributes
    ----------
    by_code : Counter
        Bytecodes executed per (code object, layer); library code counts with the
        layer of its nearest ``wire_fmu`` caller.
    steps : int
        Macro steps counted.
    kernel_loads : int
        First calls of a compiled function with new argument types while counting
        (numba loading, or compiling, it: a cost of the start, paid once per run
        and not counted).
    """

    def __init__(self, warm_up: float = 0.0) -> None:
        self.warm_up = warm_up
        self.by_code: Counter[tuple[CodeType, str]] = Counter()
        self.steps = 0
        self._counting = False
        self._loading = False
        self.kernel_loads = 0
        self._layers: dict[str, str | None] = {}

    def on_start(self, sim: Any) -> None:
        """Nothing at the start (the observer protocol)."""

    def on_step(self, sim: Any) -> None:
        """Count a step; start counting once the warm-up is over (the observer protocol)."""
        if self._counting:
            self.steps += 1
        elif sim.time >= self.warm_up:
            self._start(sys._getframe(1))

    def on_end(self, sim: Any, result: Any) -> None:
        """Stop counting, if the loop's end has not (the observer protocol)."""
        sys.settrace(None)
        self._counting = False

    def _start(self, caller: FrameType) -> None:
        """Trace every new call, and the calls under way up to the stepping loop's."""
        self._counting = True
        sys.settrace(self._call)
        frame: FrameType | None = caller
        while frame is not None:
            frame.f_trace = self._call(frame, "call", None)
            if frame.f_code.co_name == LOOP_FUNCTION:
                break
            frame = frame.f_back

    def _call(self, frame: FrameType, event: str, arg: Any):
        code = frame.f_code
        if self._loading or code in _OWN_CODE:
            return None
        if code.co_name == KERNEL_LOAD and "numba" in Path(code.co_filename).parts:
            return self._kernel_load(frame)
        key = (code, self._caller_layer(frame))
        frame.f_trace_opcodes = True
        counts = self.by_code
        loop = code.co_name == LOOP_FUNCTION and layer_of(code.co_filename) == "master"

        def opcode(frame: FrameType, event: str, arg: Any):
            if event == "opcode":
                counts[key] += 1
            elif loop and event == "return":  # the loop is over: the rest is clean-up
                sys.settrace(None)
            return opcode

        return opcode

    def _kernel_load(self, frame: FrameType):
        """Not count a compiled kernel's first call (its load), until it returns."""
        self._loading = True
        self.kernel_loads += 1

        def loaded(frame: FrameType, event: str, arg: Any):
            if event == "return":
                self._loading = False
            return loaded

        return loaded

    def _caller_layer(self, frame: FrameType | None) -> str:
        while frame is not None:
            name = frame.f_code.co_filename
            layer = self._layers.get(name, False)
            if layer is False:
                layer = self._layers[name] = layer_of(name)
            if layer is not None:
                return layer
            frame = frame.f_back
        return "other"


_OWN_CODE = frozenset(
    f.__code__
    for f in (
        BytecodeCounter.on_step,
        BytecodeCounter.on_end,
        BytecodeCounter._start,
        BytecodeCounter._call,
    )
)


@dataclass(frozen=True)
class SceneBytecodes:
    """Bytecodes of one scene's stepping loop.

    Attributes
    ----------
    scene : str
        The scene's name.
    units : int
        Its units.
    steps : int
        Macro steps taken.
    by_layer : dict of str to int
        Bytecodes per layer (``master``, ``FMU side``, ``other``), in the whole loop.
    by_function : Counter
        Bytecodes per ``"file:function (layer)"``, in the whole loop.
    """

    scene: str
    units: int
    steps: int
    by_layer: dict[str, int]
    by_function: Counter = field(default_factory=Counter)

    def per_unit_step(self, count: float) -> float:
        """``count`` per unit and macro step."""
        return count / max(1, self.units * self.steps)

    @property
    def total(self) -> int:
        """Bytecodes of the whole loop."""
        return sum(self.by_layer.values())


def measure(name: str, stop_time: float, warm_up: float, out: Path) -> SceneBytecodes:
    """Run one scene shortened to ``stop_time`` and count its loop's bytecodes after
    ``warm_up`` (both simulated, s).

    Parameters
    ----------
    name : str
        A shipped scene's name.
    stop_time, warm_up : float
        Simulated time of the run, and before counting starts, s.
    out : Path
        Folder the scene's results go into (in a subfolder named after it).
    """
    counter = BytecodeCounter(warm_up)
    outcome = run_counted(name, out / name, counter, stop_time)
    by_layer: Counter[str] = Counter()
    by_function: Counter[str] = Counter()
    for (code, layer), count in counter.by_code.items():
        by_layer[layer] += count
        by_function[f"{short_file(code.co_filename)}:{code.co_name} ({layer})"] += count
    units = len(outcome.simulation.slaves)
    return SceneBytecodes(name, units, counter.steps, dict(by_layer), by_function)


def short_file(filename: str) -> str:
    """``filename`` from its package on: ``wire_fmu/...``, ``numpy/...``, or the
    standard library's module (``dataclasses.py``).

    Parameters
    ----------
    filename : str
        A code object's file.
    """
    parts = Path(filename).parts
    for anchor in ("wire_fmu", "site-packages"):
        if anchor in parts:
            at = len(parts) - 1 - parts[::-1].index(anchor)
            return "/".join(parts[at if anchor == "wire_fmu" else at + 1 :])
    return parts[-1] if parts else filename


def table(rows: list[SceneBytecodes]) -> str:
    """Markdown table: bytecodes per unit and macro step, by layer, one row per scene.

    Parameters
    ----------
    rows : list of SceneBytecodes
        One per scene.
    """
    header = "scene | units | macro steps | master | FMU side | other | total"
    return markdown_table(
        header,
        (
            f"{r.scene} | {r.units} | {r.steps} | "
            + " | ".join(
                f"{r.per_unit_step(r.by_layer.get(layer, 0)):.0f}"
                for layer in ("master", "FMU side", "other")
            )
            + f" | {r.per_unit_step(r.total):.0f}"
            for r in rows
        ),
    )


def top_functions(row: SceneBytecodes, count: int) -> str:
    """Markdown table of the ``count`` functions that run the most bytecodes in ``row``.

    Parameters
    ----------
    row : SceneBytecodes
        One scene's figures.
    count : int
        How many functions.
    """
    return markdown_table(
        f"{row.scene}: function (layer) | bytecodes per unit and step",
        (
            f"{where} | {row.per_unit_step(n):.1f}"
            for where, n in row.by_function.most_common(count)
        ),
    )


def main(argv: list[str] | None = None) -> None:
    """Command-line entry point.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; None reads the command line.
    """
    parser = scene_parser(__doc__.splitlines()[0], list(shipped_scenes()), None)
    add_counting_window(parser, warm_up=0.2)
    parser.add_argument(
        "--top", type=int, default=0, help="also list each scene's N costliest functions"
    )
    args = parse_scene_options(parser, argv)
    problems = counting_window_problems(args)
    if args.top < 0:
        problems.append(f"--top must be at least 0, got {args.top}")
    if problems:
        parser.error("; ".join(problems))
    with tempfile.TemporaryDirectory() as tmp:
        rows = [
            measure(name, args.stop_time, args.warm_up * args.stop_time, Path(tmp))
            for name in args.scenes
        ]
    text = table(rows)
    if args.top:
        text += "".join("\n\n" + top_functions(row, args.top) for row in rows)
    report_table(text, args.out)


if __name__ == "__main__":
    main()
