"""A second test unit for the master: a mass hung on a spring from a partner's flange.

Module name unique on purpose (bundled as a top-level module in test FMUs).

``CoupledMassUnit``
    Mass ``m`` on a spring-damper (``k``, ``c``) to the flange of another
    unit, whose position and velocity are inputs; optional spring ``k_ground``
    to the ground. The coupling spring lives here (the compliance is inside
    the unit that outputs the force), so ``force_on_flange`` has direct
    feedthrough from the flange inputs while the mass's own position and
    velocity do not. Within a step the flange moves as ``x_f + v_f * tau``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from wire_fmu.core.framework.unit import StepResult, Unit, input_, output, parameter

__all__ = ["CoupledMassUnit"]

_FLANGE = ("flange.position", "flange.velocity")


class CoupledMassUnit(Unit):
    """Mass on a spring-damper from another unit's flange (test unit)."""

    NAME = "CoupledMass"
    DESCRIPTION = "Mass on a spring-damper hung from another unit's flange (test unit)"
    VARIABLES = (
        parameter("mass", 2.0, "kg", "Mass of the body", min=0.0),
        parameter("stiffness", 50.0, "N/m", "Coupling spring stiffness", min=0.0),
        parameter("damping", 0.1, "N.s/m", "Coupling damping", min=0.0),
        parameter("ground_stiffness", 0.0, "N/m", "Spring from the mass to the ground"),
        parameter("x0", 0.0, "m", "Initial position of the mass"),
        parameter("substeps", 40, "", "RK4 steps per communication step", type=int, min=1),
        input_("flange.position", 0.0, "m", "Position of the partner's flange"),
        input_("flange.velocity", 0.0, "m/s", "Velocity of the partner's flange"),
        output(
            "force_on_flange",
            "N",
            "Spring-damper force on the partner's flange, along x",
            depends_on=_FLANGE,
        ),
        output(
            "stretch",
            "m",
            "Coupling spring stretch, mass minus flange position",
            depends_on=_FLANGE,
        ),
        output("position", "m", "Position of the mass"),
        output("velocity", "m/s", "Velocity of the mass"),
        output("stored_energy", "J", "Kinetic and spring energy", depends_on=_FLANGE),
        output("dissipated_energy", "J", "Energy dissipated by the damper"),
        output("external_work", "J", "Work done through the flange"),
        output("energy_balance", "J", "Ledger residual", depends_on=_FLANGE),
    )

    def __init__(self, instance_name: str = "unit") -> None:
        super().__init__(instance_name)
        self._y = np.zeros(4)  # x, v, dissipated, work
        self._flange0 = 0.0
        self._e0 = 0.0

    def configure(self) -> None:
        """Nothing to build."""

    def initialize(self, start_time: float) -> None:
        """At rest at ``x0``."""
        self._y = np.array([self.values["x0"], 0.0, 0.0, 0.0])
        self._flange0 = self.values["flange.position"]
        self._publish(self.values["flange.position"], self.values["flange.velocity"])
        self._e0 = self.values["stored_energy"]

    def _spring(self, x, v, xf, vf):
        p = self.values
        return p["stiffness"] * (x - xf) + p["damping"] * (v - vf)

    def _rate(self, y, xf, vf):
        p = self.values
        f = self._spring(y[0], y[1], xf, vf)  # pulls the mass towards the flange
        acc = (-f - p["ground_stiffness"] * y[0]) / p["mass"]
        return np.array([y[1], acc, p["damping"] * (y[1] - vf) ** 2, f * vf])

    def advance(self, time: float, step: float) -> StepResult:
        """RK4; the flange advances with its velocity over the step."""
        xf, vf = self.values["flange.position"], self.values["flange.velocity"]
        n = int(self.values["substeps"])
        h, y = step / n, self._y.copy()
        for i in range(n):
            x0 = xf + vf * i * h
            k1 = self._rate(y, x0, vf)
            k2 = self._rate(y + 0.5 * h * k1, x0 + 0.5 * h * vf, vf)
            k3 = self._rate(y + 0.5 * h * k2, x0 + 0.5 * h * vf, vf)
            k4 = self._rate(y + h * k3, x0 + h * vf, vf)
            y += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        self._y = y
        self._publish(xf + vf * step, vf)
        return StepResult(True)

    def evaluate_outputs(self) -> None:
        """Feedthrough outputs for newly set flange inputs."""
        self._publish(self.values["flange.position"], self.values["flange.velocity"])

    def _publish(self, xf: float, vf: float) -> None:
        p, (x, v, dissipated, work) = self.values, self._y
        p["force_on_flange"] = float(self._spring(x, v, xf, vf))
        p["position"], p["velocity"] = float(x), float(v)
        p["stretch"] = float(x - xf)
        energy = 0.5 * p["mass"] * v * v + 0.5 * p["stiffness"] * (x - xf) ** 2
        energy += 0.5 * p["ground_stiffness"] * x * x
        p["stored_energy"] = float(energy)
        p["dissipated_energy"], p["external_work"] = float(dissipated), float(work)
        p["energy_balance"] = float(energy - self._e0 + dissipated - work)

    def get_state(self) -> dict[str, Any]:
        """Integrator state."""
        return {"y": [float(c) for c in self._y], "e0": self._e0}

    def set_state(self, state: Mapping[str, Any]) -> None:
        """Restore :meth:`get_state`."""
        self._y = np.array(state["y"], dtype=float)
        self._e0 = float(state["e0"])
