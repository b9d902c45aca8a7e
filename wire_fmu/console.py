"""The ``wire-fmu`` command: one process setting, then :func:`wire_fmu.cli.main`.

BLAS runs on one thread in our processes. The units' linear algebra is on
matrices of a few dozen rows, where BLAS threads only cost, and OpenBLAS's
worker thread, joined when the process exits, aborted processes that had
loaded many FMUs ("corrupted double-linked list" in glibc's free of the
thread's TLS, after all work was done and written): 3 of 23 test processes,
none of 10 with one thread; the write that corrupts the heap was not found.
The setting must come before numpy is first loaded, hence this module, which
imports nothing else until it is made.
"""

from __future__ import annotations

import os

__all__ = ["main", "single_threaded_blas"]


def single_threaded_blas() -> None:
    """Ask OpenBLAS for one thread unless the user chose otherwise (before numpy loads)."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def main() -> int:
    """Entry point of the ``wire-fmu`` command."""
    single_threaded_blas()
    from wire_fmu.cli import main as cli_main

    return cli_main()
