"""Shared pieces of the interop tests: test FMUs, the two-mass scene, runners, schemas.

The two-mass scene is the oscillator pair of ``test_master_convergence``
(unit ``a``: mass on a spring to the ground, force in; unit ``b``: mass hung
from ``a``'s flange, coupling spring inside, force out), bonded by a
translational power bond, plus units that exercise everything else an export
carries: ``c`` (an oscillator whose force is set by a scheduled event), ``d``
(a spring-damper whose flange a is driven by a sine with its rate, flange b
connected to ``c``) and ``e`` (a spring-damper whose flange a follows a ramp
at the step midpoint, flange b connected to ``a``).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np
from lxml import etree

SUPPORT = Path(__file__).resolve().parent / "support"
SCHEMAS = Path(__file__).resolve().parent / "data" / "schemas"
if str(SUPPORT) not in sys.path:
    sys.path.insert(0, str(SUPPORT))

STEP, STOP = 0.01, 1.0


def build_test_fmus(out: Path) -> dict[str, Path]:
    """Build the oscillator, coupled-mass and spring-damper test FMUs into ``out``."""
    from wire_fmu.export.builder import build_fmu

    facades = SUPPORT / "facades"
    units = SUPPORT / "wire_fmu_test_units.py"
    return {
        "osc": build_fmu(facades / "oscillator.py", out, extra_modules=[units]),
        "mass": build_fmu(
            facades / "coupled_mass.py", out, extra_modules=[SUPPORT / "wire_fmu_master_units.py"]
        ),
        "spring": build_fmu(facades / "spring_damper.py", out, extra_modules=[units]),
    }


def two_mass_data(
    fmus: dict[str, Path], *, a_x0: float = 0.0, b_x0: float = 0.1, signals: bool = True, **run: Any
) -> dict[str, Any]:
    """The test scene as plain data (see the module docstring)."""
    data: dict[str, Any] = {
        "name": "two_mass",
        "description": "Two masses on a translational power bond (test scene)",
        "run": {
            "stop_time": STOP,
            "step": STEP,
            "algorithm": "jacobi",
            "extrapolation": "constant",
            **run,
        },
        "units": {
            "a": {
                "fmu": str(fmus["osc"]),
                "parameters": {
                    "mass": 1.0,
                    "stiffness": 40.0,
                    "damping": 0.0,
                    "x0": a_x0,
                    "substeps": 50,
                    "label": 'left <mass> & "quoted" {"json": [1, 2]}',
                },
            },
            "b": {
                "fmu": str(fmus["mass"]),
                "parameters": {
                    "mass": 2.0,
                    "stiffness": 60.0,
                    "damping": 0.0,
                    "x0": b_x0,
                    "substeps": 50,
                },
            },
        },
        "bonds": [
            {
                "name": "spring",
                "kind": "translational",
                "effort": "b.force_on_flange -> a.force",
                "flow": "a.velocity -> b.flange.velocity",
                "position": "a.position -> b.flange.position",
            }
        ],
        "outputs": {"variables": "all"},
        "plots": [{"title": "Positions", "variables": ["a.position", "b.position"]}],
    }
    if signals:
        data["units"].update(
            {
                "c": {
                    "fmu": str(fmus["osc"]),
                    "parameters": {"mass": 0.5, "stiffness": 20.0, "damping": 0.3, "x0": 0.0},
                },
                "d": {
                    "fmu": str(fmus["spring"]),
                    "parameters": {"stiffness": 30.0, "damping": 0.5},
                },
                "e": {
                    "fmu": str(fmus["spring"]),
                    "parameters": {"stiffness": 10.0, "damping": 0.1},
                },
            }
        )
        data["connections"] = [
            {"from": "c.position", "to": "d.position_b"},
            {"from": "c.velocity", "to": "d.velocity_b"},
            {"from": "a.position", "to": "e.position_b"},
        ]
        data["drivers"] = [
            {
                "target": "d.position_a",
                "rate_target": "d.velocity_a",
                "kind": "sine",
                "amplitude": 0.2,
                "period": 0.7,
                "label": "heave",
            },
            {
                "target": "e.position_a",
                "kind": "ramp",
                "points": [[0.0, 0.0], [0.3, 2.0], [0.6, -1.0]],
            },
        ]
        data["events"] = [{"time": 0.5, "label": "push", "set": {"c.force": 1.5}}]
    return data


def two_mass_scene(fmus: dict[str, Path], base_dir: Path, **kw: Any):
    """The parsed test scene."""
    from wire_fmu.master.scene import parse_scene

    return parse_scene(two_mass_data(fmus, **kw), base_dir=base_dir)


class StepRecorder:
    """Observer: every Real output of every unit after every accepted step."""

    def __init__(self) -> None:
        self.names: list[tuple[str, str]] = []
        self.rows: list[list[float]] = []

    def on_start(self, sim) -> None:
        """Fix the columns (initial values are not compared: libcosim gives none)."""
        self.names = [
            (u, v.name)
            for u, s in sim.slaves.items()
            for v in s.model_description.modelVariables
            if v.causality == "output" and v.type == "Real"
        ]

    def on_step(self, sim) -> None:
        """Record the row at the new time."""
        row = [sim.time]
        for unit, slave in sim.slaves.items():
            names = [n for u, n in self.names if u == unit]
            values = slave.get(names)
            row += [values[n] for n in names]
        self.rows.append(row)

    def on_end(self, sim, result) -> None:
        """Nothing to close."""


def run_ours(scene) -> tuple[list[tuple[str, str]], np.ndarray]:
    """Run ``scene`` with our master; (columns, rows of time and every Real output)."""
    from wire_fmu.master.simulation import Simulation
    from wire_fmu.master.validate import validate_scene

    structure = validate_scene(scene, through_fmi=False)
    recorder = StepRecorder()
    result = Simulation(scene, structure, [recorder]).run()
    assert result.status == "finished", result.message
    return recorder.names, np.array(recorder.rows)


def run_libcosim(
    path: Path,
    names: list[tuple[str, str]],
    *,
    step: float,
    stop: float,
    kind: str = "ssp",
    watch_inputs: list[tuple[str, str]] = (),
) -> np.ndarray:
    """Run an exported system in libcosimpy one fixed step at a time.

    Returns rows of time and the ``names`` (then ``watch_inputs``) after each step.
    """
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    if kind == "ssp":
        execution = CosimExecution.from_ssp_file(str(path), step_size=int(round(step * 1e9)))
    else:
        execution = CosimExecution.from_osp_config_file(str(path))
    index = {info.name.decode(): info.index for info in execution.slave_infos()}
    refs = {
        u: {v.name.decode(): v.reference for v in execution.slave_variables(i)}
        for u, i in index.items()
    }
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer=observer)
    rows = []
    for _ in range(int(round(stop / step))):
        assert execution.step(1)
        row = [execution.status().current_time * 1e-9]
        for unit, name in [*names, *watch_inputs]:
            row += observer.last_real_values(index[unit], [refs[unit][name]])
        rows.append(row)
    return np.array(rows)


def schema(name: str) -> etree.XMLSchema:
    """A shipped schema, e.g. ``"ssp/SystemStructureDescription.xsd"``."""
    return etree.XMLSchema(etree.parse(str(SCHEMAS / name)))


def schema_errors(document: bytes | etree._Element, name: str) -> list[str]:
    """Validation errors of ``document`` against the shipped schema ``name``."""
    root = etree.fromstring(document) if isinstance(document, bytes) else document
    checker = schema(name)
    checker.validate(root)
    return [f"{e.line}: {e.message}" for e in checker.error_log]
