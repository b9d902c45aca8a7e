"""The ``wire-fmu`` entry point sets BLAS to one thread before numpy can load."""

from __future__ import annotations

import os
import subprocess
import sys

from wire_fmu.console import single_threaded_blas


def test_one_blas_thread_unless_the_user_chose(monkeypatch):
    monkeypatch.delenv("OPENBLAS_NUM_THREADS", raising=False)
    single_threaded_blas()
    assert os.environ["OPENBLAS_NUM_THREADS"] == "1"
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "4")
    single_threaded_blas()
    assert os.environ["OPENBLAS_NUM_THREADS"] == "4"


def test_the_entry_module_loads_no_numpy_before_the_setting():
    probe = "import sys, wire_fmu.console; print('numpy' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"
