"""Checks shared by the facade tests: a facade class loaded from ``models/`` without building.

Each of our facades must register exactly its core unit's declared
variables with their causality (then the timing variable every FMU has),
and step like the core once started.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from typing import Any

__all__ = ["load_facade_class", "assert_maps_every_declared_variable", "started_facade"]

ROOT = Path(__file__).resolve().parents[1]


def load_facade_class(model: str, class_name: str) -> type:
    """The facade class ``class_name`` of ``models/<model>.py``, loaded as a plain module."""
    spec = importlib.util.spec_from_file_location(
        f"{model}_facade", ROOT / "models" / f"{model}.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return getattr(module, class_name)


def assert_maps_every_declared_variable(facade: Any, unit_class: type, model_name: str) -> None:
    """The facade registers the unit's variables, in order, with their causality, and
    then its own timing variable ``physics_seconds`` (local)."""
    *declared, timing = facade.vars.values()
    assert (timing.name, timing.causality.name) == ("physics_seconds", "local")
    registered = {v.name: v for v in declared}
    assert list(registered) == [v.name for v in unit_class.VARIABLES]
    for var in unit_class.VARIABLES:
        assert registered[var.name].causality.name == var.causality.value
    assert facade.modelName == model_name


def started_facade(facade_class: type, instance_name: str, effects: str) -> tuple[Any, dict]:
    """A facade with ``effects``, initialised at t = 0, and its value references by name."""
    facade = facade_class(instance_name=instance_name, resources=None)
    refs = {v.name: v.value_reference for v in facade.vars.values()}
    facade.set_string([refs["effects"]], [effects])
    facade.setup_experiment(0.0, None, None)
    facade.enter_initialization_mode()
    facade.exit_initialization_mode()
    return facade, refs
