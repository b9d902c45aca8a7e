"""Test-session setup: BLAS on one thread, before anything loads numpy (see wire_fmu.console)."""

from wire_fmu.console import single_threaded_blas

single_threaded_blas()
