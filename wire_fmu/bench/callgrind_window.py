"""Counting a run's macro steps under callgrind, from inside the run: the client requests
that switch counting on and off, the observer that uses them, and the compiled kernels'
loads left out (the counted side of :mod:`~wire_fmu.bench.instructions`)."""

from __future__ import annotations

import ctypes
import gc
import os
import shutil
import subprocess
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

__all__ = ["CallgrindControl", "CallgrindWindow", "kernel_loads_left_out"]


_CLIENT_REQUESTS = r"""
#include <valgrind/callgrind.h>
void counting_on(void) { CALLGRIND_START_INSTRUMENTATION; }
void counting_off(void) { CALLGRIND_STOP_INSTRUMENTATION; }
void dump(void) { CALLGRIND_DUMP_STATS; }
"""
"""Callgrind's client requests as C functions: a few instructions each, where running
``callgrind_control`` would fork a process; outside valgrind they do nothing."""


class CallgrindControl:
    """Callgrind's client requests (count on, count off, dump), from a library built here.

    Parameters
    ----------
    folder : Path
        Where the library is built (with the C compiler ``CC``, else ``cc``).

    Raises
    ------
    RuntimeError
        If no C compiler or valgrind's ``callgrind.h`` is found, or the build fails.
    """

    def __init__(self, folder: Path) -> None:
        compiler = os.environ.get("CC", "").split() or [shutil.which("cc") or "gcc"]
        source, library = folder / "client_requests.c", folder / "client_requests.so"
        source.write_text(_CLIENT_REQUESTS)
        try:
            done = subprocess.run(
                [*compiler, "-O1", "-shared", "-fPIC", "-o", str(library), str(source)],
                capture_output=True,
                text=True,
            )
        except OSError as err:
            raise RuntimeError(
                f"no C compiler to build callgrind's client requests: {err}"
            ) from None
        if done.returncode != 0:
            raise RuntimeError(f"callgrind's client requests did not build: {done.stderr.strip()}")
        functions = ctypes.PyDLL(str(library))  # the GIL kept: nothing to release it for
        self.on, self.off, self.dump = functions.counting_on, functions.counting_off, functions.dump


class CallgrindWindow:
    """An observer that has callgrind count the stepping loop from the first macro step
    after the warm-up to the last one, without the compiled kernels' loads, then dump.

    The results recorder writes its rows after the last step (the run's
    ``flush_every`` is infinite), so the count holds keeping a row each step but not
    writing it as text.

    A compiled kernel's first call with new argument types (numba loading it from its
    cache, or compiling it) is a cost of the start, paid once per run, and costs
    thousands of macro steps' instructions: counting is off while one runs
    (:meth:`loading`).

    Parameters
    ----------
    warm_up : float
        Simulated time before counting starts, s.
    control : CallgrindControl
        Switches counting on and off and dumps (anything with ``on``, ``off``, ``dump``).

    Attributes
    ----------
    steps : int
        Macro steps counted.
    kernel_loads : int
        Kernel loads left out of the count.
    """

    def __init__(self, warm_up: float, control: Any) -> None:
        self.warm_up = warm_up
        self.control = control
        self.steps = 0
        self.kernel_loads = 0
        self.counting = False

    def on_start(self, sim: Any) -> None:
        """Nothing at the start (the observer protocol)."""

    def on_step(self, sim: Any) -> None:
        """Count a step; switch counting on once the warm-up is over, and off after the
        last step (the observer protocol)."""
        if self.counting:
            self.steps += 1
            if sim.time >= sim.run_settings.stop_time * (1.0 - 1e-12):
                self._stop()  # the loop is over: the results written after it are not a step's
        elif sim.time >= self.warm_up and not self.steps:
            # The cyclic garbage collector runs when allocations since its last run pass a
            # threshold: collected now, its runs inside the count follow from the counted
            # steps' allocations alone, not from what the start of the process allocated.
            gc.collect()
            self.counting = True
            self.control.on()

    def on_end(self, sim: Any, result: Any) -> None:
        """Switch counting off and dump, if a run that stopped early left it on (the
        observer protocol)."""
        self._stop()

    def _stop(self) -> None:
        if self.counting:
            self.control.off()
            self.control.dump()
        self.counting = False

    @contextmanager
    def loading(self) -> Iterator[None]:
        """Counting off inside the ``with`` block (a kernel's load), if it was on."""
        if not self.counting:
            yield
            return
        self.control.off()
        self.kernel_loads += 1
        try:
            yield
        finally:
            self.control.on()


@contextmanager
def kernel_loads_left_out(window: CallgrindWindow) -> Iterator[None]:
    """Inside the ``with`` block, every numba dispatcher's load of a kernel (its
    ``_compile_for_args``, which its C code calls when no loaded version takes the
    arguments) runs inside ``window.loading()``."""
    from numba.core.dispatcher import _DispatcherBase

    load = _DispatcherBase._compile_for_args

    def counted_apart(self, *args, **kwargs):
        with window.loading():
            return load(self, *args, **kwargs)

    _DispatcherBase._compile_for_args = counted_apart
    try:
        yield
    finally:
        _DispatcherBase._compile_for_args = load
