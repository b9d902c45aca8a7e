"""Small but real core units for testing the export layer.

The module name is unique on purpose: it is bundled as a top-level module
in the test FMUs, and all FMUs of a process share one interpreter.

``OscillatorUnit``
    Damped mass-spring, ``m x'' + c x' + k x = F``, force input, state
    outputs without feedthrough, RK4 sub-stepping of ``[x, v, E_diss, W_ext]``
    held in a numpy array (the hidden state the FMU state must carry).
``SpringDamperUnit``
    Massless spring-damper between two flanges: positions and velocities in,
    force out (direct feedthrough).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.unit import StepResult, Unit, input_, output, parameter

__all__ = ["OscillatorUnit", "SpringDamperUnit", "oscillator_position"]


class OscillatorUnit(Unit):
    """Damped mass on a spring to ground, driven by an external force.

    Ports: input ``force`` (N, acting on the mass, positive along x);
    outputs ``position``/``velocity`` of the mass (no feedthrough) and
    ``acceleration`` (direct feedthrough from ``force``).
    """

    NAME = "Oscillator"
    DESCRIPTION = "Damped mass-spring oscillator driven by an external force (test unit)"
    VARIABLES = (
        parameter("mass", 1.0, "kg", "Mass of the body", min=0.0),
        parameter("stiffness", 4 * math.pi**2, "N/m", "Spring stiffness", min=0.0),
        parameter("damping", 0.4, "N.s/m", "Viscous damping coefficient", min=0.0),
        parameter("x0", 0.1, "m", "Initial position"),
        parameter("v0", 0.0, "m/s", "Initial velocity"),
        parameter("max_position", 1e3, "m", "Steps that would exceed |x| > this are refused"),
        parameter("substeps", 20, "", "RK4 steps per communication step", type=int, min=1),
        parameter("label", "osc", "", "Free text label", type=str),
        parameter("flag", False, "", "Free tunable flag, no physics", type=bool, fixed=False),
        input_("force", 0.0, "N", "External force on the mass, positive along x"),
        output("position", "m", "Position of the mass"),
        output("velocity", "m/s", "Velocity of the mass"),
        output("acceleration", "m/s2", "Acceleration of the mass", depends_on=("force",)),
        output("spring_force", "N", "Spring force on the mass, -k x"),
        output("stored_energy", "J", "Kinetic plus spring energy"),
        output("dissipated_energy", "J", "Energy dissipated by the damper since start"),
        output("external_work", "J", "Work done by the external force since start"),
        output("moving_forward", "", "True while the velocity is positive", type=bool),
    )

    def __init__(self, instance_name: str = "unit") -> None:
        super().__init__(instance_name)
        self._y = np.zeros(4)  # x, v, dissipated energy, external work
        self._time = 0.0

    def configure(self) -> None:
        """Check the parameters, listing every problem."""
        p = self.values
        problems = [
            f"{name} = {p[name]!r} must be {rule}"
            for name, rule, ok in (
                ("mass", "> 0", p["mass"] > 0.0),
                ("stiffness", ">= 0", p["stiffness"] >= 0.0),
                ("damping", ">= 0", p["damping"] >= 0.0),
                ("substeps", ">= 1", p["substeps"] >= 1),
            )
            if not ok
        ]
        if problems:
            raise ConfigurationError(f"{self.NAME} {self.instance_name!r}", problems)

    def initialize(self, start_time: float) -> None:
        """Start at rest state ``(x0, v0)`` with empty energy ledgers."""
        self._time = start_time
        self._y = np.array([self.values["x0"], self.values["v0"], 0.0, 0.0])
        self._publish()

    def _rate(self, y: np.ndarray, force: float) -> np.ndarray:
        p = self.values
        x, v = y[0], y[1]
        accel = (force - p["stiffness"] * x - p["damping"] * v) / p["mass"]
        return np.array([v, accel, p["damping"] * v * v, force * v])

    def advance(self, time: float, step: float) -> StepResult:
        """RK4 with ``substeps`` sub-steps, the force held."""
        if not (step > 0.0 and math.isfinite(step)):
            return StepResult(False, f"{self.NAME}: step size {step!r} must be positive")
        force, n = self.values["force"], int(self.values["substeps"])
        h, y = step / n, self._y.copy()
        for _ in range(n):
            k1 = self._rate(y, force)
            k2 = self._rate(y + 0.5 * h * k1, force)
            k3 = self._rate(y + 0.5 * h * k2, force)
            k4 = self._rate(y + h * k3, force)
            y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        if abs(y[0]) > self.values["max_position"]:
            message = (
                f"{self.NAME} {self.instance_name!r}: position would reach {y[0]:.6g} m, "
                f"beyond max_position = {self.values['max_position']} m"
            )
            return StepResult(False, message)
        self._y, self._time = y, time + step
        self._publish()
        return StepResult(True)

    def evaluate_outputs(self) -> None:
        """Recompute the feedthrough output after an input change."""
        self._publish()

    def _publish(self) -> None:
        p, (x, v, dissipated, work) = self.values, self._y
        p["position"], p["velocity"] = float(x), float(v)
        p["acceleration"] = float(self._rate(self._y, p["force"])[1])
        p["spring_force"] = float(-p["stiffness"] * x)
        p["stored_energy"] = float(0.5 * p["mass"] * v * v + 0.5 * p["stiffness"] * x * x)
        p["dissipated_energy"], p["external_work"] = float(dissipated), float(work)
        p["moving_forward"] = bool(v > 0.0)

    def get_state(self) -> dict[str, Any]:
        """Integrator state (a copy, as an array: the facade must convert it)."""
        return {"y": self._y.copy(), "time": self._time}

    def set_state(self, state: Mapping[str, Any]) -> None:
        """Restore a state from :meth:`get_state` (arrays or lists)."""
        self._y = np.array(state["y"], dtype=float)
        self._time = float(state["time"])


class SpringDamperUnit(Unit):
    """Massless spring-damper between flanges a and b.

    Ports: inputs position/velocity of both flanges; output ``force``, the
    tension pulling flange a towards b (positive when stretched).
    """

    NAME = "SpringDamper"
    DESCRIPTION = "Massless linear spring-damper between two flanges (test unit)"
    VARIABLES = (
        parameter("stiffness", 100.0, "N/m", "Spring stiffness", min=0.0),
        parameter("damping", 1.0, "N.s/m", "Damping coefficient", min=0.0),
        parameter("rest_length", 0.0, "m", "Unstretched length"),
        input_("position_a", 0.0, "m", "Position of flange a"),
        input_("position_b", 0.0, "m", "Position of flange b"),
        input_("velocity_a", 0.0, "m/s", "Velocity of flange a"),
        input_("velocity_b", 0.0, "m/s", "Velocity of flange b"),
        output(
            "force",
            "N",
            "Tension, pulling flange a towards b",
            depends_on=("position_a", "position_b", "velocity_a", "velocity_b"),
        ),
        output("stored_energy", "J", "Spring energy", depends_on=("position_a", "position_b")),
        output("dissipated_energy", "J", "Energy dissipated since start"),
    )

    def __init__(self, instance_name: str = "unit") -> None:
        super().__init__(instance_name)
        self._dissipated = 0.0

    def configure(self) -> None:
        """Check the parameters."""
        problems = [f"{n} must be >= 0" for n in ("stiffness", "damping") if self.values[n] < 0]
        if problems:
            raise ConfigurationError(f"{self.NAME} {self.instance_name!r}", problems)

    def initialize(self, start_time: float) -> None:
        """Nothing stored yet; compute the outputs."""
        self._dissipated = 0.0
        self.evaluate_outputs()

    def advance(self, time: float, step: float) -> StepResult:
        """Accumulate the damper's loss over the step."""
        rate = self.values["velocity_b"] - self.values["velocity_a"]
        self._dissipated += self.values["damping"] * rate * rate * step
        self.evaluate_outputs()
        return StepResult(True)

    def evaluate_outputs(self) -> None:
        """Force and energy from the current inputs."""
        p = self.values
        stretch = p["position_b"] - p["position_a"] - p["rest_length"]
        rate = p["velocity_b"] - p["velocity_a"]
        p["force"] = p["stiffness"] * stretch + p["damping"] * rate
        p["stored_energy"] = 0.5 * p["stiffness"] * stretch * stretch
        p["dissipated_energy"] = self._dissipated

    def get_state(self) -> dict[str, Any]:
        """The accumulated loss."""
        return {"dissipated": self._dissipated}

    def set_state(self, state: Mapping[str, Any]) -> None:
        """Restore :meth:`get_state`'s result."""
        self._dissipated = float(state["dissipated"])


def oscillator_position(
    t: np.ndarray, mass: float, stiffness: float, damping: float, x0: float, v0: float, force: float
) -> np.ndarray:
    """Closed-form position of the underdamped oscillator with constant force."""
    omega0 = math.sqrt(stiffness / mass)
    zeta = damping / (2.0 * math.sqrt(stiffness * mass))
    omega_d = omega0 * math.sqrt(1.0 - zeta**2)
    x_static = force / stiffness
    a = x0 - x_static
    b = (v0 + zeta * omega0 * a) / omega_d
    decay = np.exp(-zeta * omega0 * t)
    return x_static + decay * (a * np.cos(omega_d * t) + b * np.sin(omega_d * t))
