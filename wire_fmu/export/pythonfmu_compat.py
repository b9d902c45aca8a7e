"""Work-arounds for two reference-counting bugs in pythonfmu 0.7.0's binary.

Both were reproduced with the ``libpythonfmu-export.so`` shipped in the
pythonfmu 0.7.0 wheel (source: ``pythonfmu-export/src/pythonfmu/
PySlaveInstance.cpp``):

1. ``findClass`` runs on every ``fmi2Instantiate``. It takes the script
   module's ``__dict__`` with ``PyModule_GetDict`` (a *borrowed* reference),
   executes the script source once more in it, and then ``Py_DECREF``\\ s it.
   Each instantiation therefore steals one reference from the module dict.
   A thin facade script (one class, no functions) has a single reference,
   so its second instantiation in a process fails with
   ``AttributeError("module has no attribute '<Class>'")`` and memory is
   corrupted. :func:`hold_module_globals`, called from the script body that
   ``findClass`` executes, adds back exactly the reference it steals.

2. When a Python call raises, ``handle_py_exception`` calls
   ``cleanPyObject()``, which releases the class, the instance and its log
   queue but keeps the dangling pointers; ``fmi2FreeInstance`` (or
   ``fmi2Reset``) then releases them a second time and the process
   segfaults a few instances later. :func:`pin_for_fatal` adds the one
   reference that the second release consumes, so a master can free an
   instance after ``fmi2Fatal`` (leaking one small object graph).
"""

from __future__ import annotations

import ctypes
from typing import Any

__all__ = ["hold_module_globals", "pin_for_fatal"]


def _incref(obj: object) -> None:
    ctypes.pythonapi.Py_IncRef(ctypes.py_object(obj))


def hold_module_globals(module_globals: dict[str, Any]) -> None:
    """Add one reference to a facade script's globals (pythonfmu bug 1).

    The builder appends a call to this at the end of every bundled facade
    script, so that each execution of the script body (the import, and one
    ``findClass`` pass per instantiation) balances the reference that
    ``findClass`` releases afterwards.
    """
    _incref(module_globals)


def pin_for_fatal(instance: Any) -> None:
    """Keep ``instance`` alive across pythonfmu's double release (bug 2).

    Call it just before an exception leaves any method that pythonfmu's
    C++ layer calls on the slave instance.
    """
    for obj in (instance, type(instance), instance.log_queue):
        _incref(obj)
