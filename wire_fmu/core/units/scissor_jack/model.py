"""Paper 003's scissor jack: a screw-nut pair lifting a load through a rhombus of tie rods.

Geometry and its kinematic reduction
------------------------------------
Four tie rods of length ``L`` form a rhombus: the bottom joint stands on
the base, the top joint carries the shoe with the load, and the screw runs
horizontally between the two side joints -- in a bearing at one, through
the nut at the other. With the rods at angle ``theta`` to the horizontal
the rhombus's diagonals are::

    height  y = 2 L sin(theta)        width  w = 2 L cos(theta)

Turning the handle (and the screw) by ``psi`` (rad) draws the side joints
together by the screw travel ``s = h psi``, ``h`` the lead per radian, so
``w = w0 - s`` and::

    y(s)   = sqrt(4 L^2 - (w0 - s)^2)
    dy/ds  = w / y = cot(theta)
    d2y/ds2 = -4 L^2 / y^3

The rods are massless; the screw and handle turn with inertia ``J_s`` and
the load (mass ``m``, weight ``W``) moves with the shoe, so the jack is a
one-degree-of-freedom machine in ``psi`` with the variable reduced inertia
of paper 004, ``I(psi) = J_s + m (h cot theta)^2``. The screw's centre of
mass moves with its bearing joint by ``s / 2`` horizontally (the paper's
"horizontal displacement of the screw").

Forces. Power through the massless linkage, ``F ds = F_v dy``, gives the
axial force in the thread from the force the shoe needs,
``F = (W + m y'') cot(theta)`` with ``y''`` the load's acceleration; the
screw turns under the handle torque ``M``, the lead torque ``h F``
(:meth:`ScrewThread.lead_torque`) and the thread friction ``M_f``::

    J_s psi'' = M - h F + M_f,        |M_f| <= r_mean mu |F|

Substituting ``y'' = (h cot theta) psi'' + h^2 y_ss psi'^2`` gives, while
sliding in direction ``sigma``, the equation linear in ``psi''``::

    (J_s + q m h^2 cot^2 theta) psi'' = M - q cot(theta) (W + m h^2 y_ss psi'^2)
    q = h + sigma r_mean mu sign(F)

-- identical to Lagrange's ``I psi'' + I' psi'^2 / 2 = M - W h cot(theta) + M_f``
with ``M_f = -sigma r_mean mu |F|`` evaluated at the same acceleration. When
``q < 0`` (lowering a self-locking thread) the coefficient can vanish for
a light handle: the dry-friction law then has no or two solutions
(Painlevé's paradox); :meth:`JackConfig.problems` refuses a handle too
light for the jack's travel.

Holding. At rest the force is static, ``F0 = W cot(theta)``, and the
handle torque the thread holds lies in ``h F0 +- r_mean mu F0``: with the
paper's numbers (``theta = 30 deg``, 2 mm per turn, ``r_mean = 0.01 m``,
``mu = 0.1``) the jack holds the load until
``M = (h + r_mean mu) W cot 30 deg = 6.850 N m`` -- the paper's "about
7 N m" -- and, since ``h < r_mean mu``, holds it with no handle torque at
all (self-locking; :meth:`JackConfig.breakaway_torques`).

Thread friction models
----------------------
``none``
    frictionless thread (the paper's section 2 experiment);
``stick_slip``
    exact dry friction with :class:`~wire_fmu.core.components.friction.StickSlip`: a
    stuck thread does not move at all;
``linear``, ``tanh``
    paper 003's regularised torque (linear inside ``|psi'| < w1``,
    saturated outside) or its ``tanh`` variant; stiff
    (``lambda ~ M1 / (I w1)``) and creeping while held
    (:meth:`~wire_fmu.core.components.screw_nut.thread.ScrewThread.creep_speed`).

The handle is driven either by a torque (dynamics as above) or by a speed
(kinematically, as in the paper's section 2: "the handle is turned at
2 rev/s, initial speeds consistent"); then ``M`` is the torque the drive
must supply, and a change of the commanded speed is an impulse whose work
``I (w_new^2 - w_old^2) / 2`` the drive supplies.

Energy: stored ``I psi'^2 / 2 + W y`` (J), dissipated by the thread
``-M_f psi'`` (W, >= 0), external work of the handle ``M psi'``.

Modules
-------
:mod:`~wire_fmu.core.units.scissor_jack.geometry`
    The rhombus of tie rods: height and its slopes over the screw travel.
:mod:`~wire_fmu.core.units.scissor_jack.config`
    Configuration, inputs and report of the jack.
:mod:`~wire_fmu.core.units.scissor_jack.mechanics`
    Kinematics and forces in the current mode (a part of the model).
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from wire_fmu.core.components.friction import GROUND, FrictionLink, StickSlip
from wire_fmu.core.errors import ModelError
from wire_fmu.core.framework.hybrid import IntegrationError, SolverSettings, make_solver
from wire_fmu.core.units.scissor_jack.config import JackConfig, JackInputs, JackReport
from wire_fmu.core.units.scissor_jack.mechanics import JackMechanics

__all__ = [
    "ScissorJackModel",
    "THREAD_FREE",
    "THREAD_SLIDING",
    "THREAD_STUCK",
    "THREAD_CREEPING",
]

logger = logging.getLogger(__name__)

THREAD_FREE, THREAD_SLIDING, THREAD_STUCK, THREAD_CREEPING = 0, 1, 2, 3
_STATE_WORDS = {
    THREAD_FREE: "frictionless",
    THREAD_SLIDING: "sliding",
    THREAD_STUCK: "stuck",
    THREAD_CREEPING: "creeping (regularised)",
}


# ============================================================== the model
class ScissorJackModel(JackMechanics):
    """The jack as a hybrid ODE in the handle angle (module docstring).

    State ``[psi, psi', dissipated, external work]`` (rad, rad/s, J, J).
    Modes: the thread's stick/slip mode (``stick_slip`` with a torque drive).

    Parameters
    ----------
    config : JackConfig
        The jack.
    settings : SolverSettings
        Internal solver of :mod:`wire_fmu.core.framework.hybrid`.
    """

    def __init__(self, config: JackConfig, settings: SolverSettings) -> None:
        self.config = config
        self.h = config.thread.lead_per_radian
        self.r_mu = config.thread.mean_radius * config.thread.friction
        self.exact = config.friction == "stick_slip"
        self.friction = StickSlip(
            np.array([config.handle_inertia]), (FrictionLink("screw thread", 0, GROUND),)
        )
        self.inputs = JackInputs()
        self.state = np.zeros(4)
        self.solver = make_solver(settings)
        self.mode_changes = 0
        self.last_events: list[tuple[float, str]] = []
        self._held_angle = 0.0

    # ------------------------------------------------ HybridSystem protocol
    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """``[psi', psi'', dissipated', external work']``.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[psi (rad), psi' (rad/s), dissipated (J), external work (J)]``.
        """
        f = self.forces(x)
        omega = float(x[1])
        if self._stuck():
            omega = 0.0
        return np.array(
            [omega, f.acceleration, -f.friction_torque * omega, f.handle_torque * omega]
        )

    def guard_directions(self) -> np.ndarray:
        """The thread's stick/slip guard fires on a downward crossing."""
        return -np.ones(1 if self._has_modes() else 0)

    def guards(self, t: float, x: np.ndarray) -> np.ndarray:
        """Holding margin (stuck) or direction times speed (sliding).

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[psi (rad), psi' (rad/s), dissipated (J), external work (J)]``.
        """
        if not self._has_modes():
            return np.zeros(0)
        f = self.forces(x)
        return self.friction.guards(
            np.array([x[1]]), np.array([f.friction_torque]), self._capacity(float(x[0]))
        )

    def handle_events(self, t: float, x: np.ndarray, fired: list[int]) -> np.ndarray:
        """The thread sticks or breaks away.

        Parameters
        ----------
        t : float
            Time, s.
        x : ndarray
            State ``[psi (rad), psi' (rad/s), dissipated (J), external work (J)]``.
        fired : list of int
            Indices of the guards that crossed.
        """
        return self._settle(t, x, fired)

    def project(self, x: np.ndarray) -> np.ndarray:
        """A stuck thread stays exactly where it stuck, at rest.

        Parameters
        ----------
        x : ndarray
            State, changed in place and returned.
        """
        if self._stuck():
            x[0] = self._held_angle
            x[1] = 0.0
        return x

    # ---------------------------------------------------------- modes
    def _has_modes(self) -> bool:
        return self.exact and self.config.drive == "torque"

    def _stuck(self) -> bool:
        return self._has_modes() and int(self.friction.mode[0]) == 0

    def thread_state(self, x: np.ndarray | None = None) -> int:
        """0 frictionless, 1 sliding, 2 stuck, 3 creeping (regularised).

        Parameters
        ----------
        x : ndarray, optional
            State ``[psi (rad), psi' (rad/s), ...]`` (default: the current one).
        """
        x = self.state if x is None else x
        if self.config.friction == "none":
            return THREAD_FREE
        if self.config.regularised:
            return THREAD_CREEPING if abs(x[1]) < self.config.speed_scale else THREAD_SLIDING
        if self._has_modes():
            return THREAD_STUCK if self._stuck() else THREAD_SLIDING
        return THREAD_STUCK if x[1] == 0.0 else THREAD_SLIDING

    def _settle(self, t: float, x: np.ndarray, fired: list[int]) -> np.ndarray:
        """Make the thread's mode fit the inputs at ``(t, x)``; log a change."""
        x = np.array(x, dtype=float)
        if not self._has_modes():
            return x
        before = self.thread_state(x)
        forces = self._free_torque(x)
        x[1:2] = self.friction.switch(x[1:2], forces, self._capacity(float(x[0])), fired)
        if self._stuck():
            self._held_angle = float(x[0])
        after = self.thread_state(x)
        if after != before or fired:
            self.mode_changes += 1
            self._event(
                t,
                f"thread {_STATE_WORDS[after]} at handle torque "
                f"{self.inputs.torque_command:.6g} N m",
            )
        return self.project(x)

    def _event(self, t: float, text: str) -> None:
        self.last_events.append((t, text))
        logger.debug("t = %.9g s: %s", t, text)

    # ---------------------------------------------------------- life cycle
    def initialize(self, t0: float, inputs: JackInputs) -> None:
        """Start at ``psi = 0``: at rest (or ``initial_speed``), or at the commanded speed.

        Parameters
        ----------
        t0 : float
            Start time, s.
        inputs : JackInputs
            Handle commands at the start.
        """
        self.inputs = inputs
        speed = inputs.speed_command if self.config.drive == "speed" else self.config.initial_speed
        x = np.array([0.0, speed, 0.0, 0.0])
        self.mode_changes = 0
        self.last_events = []
        if self._has_modes():
            self.friction.set_mode([int(np.sign(speed))])
            self._held_angle = 0.0
            x = self._settle(t0, x, [])
        self.mode_changes = 0
        self.last_events = []
        self.state = x

    def advance(self, t: float, h: float, inputs: JackInputs) -> int:
        """Advance by ``h`` with ``inputs`` held; return the number of events.

        Parameters
        ----------
        t : float
            Start of the step, s.
        h : float
            Step length, s.
        inputs : JackInputs
            Handle commands held over the step.

        Raises
        ------
        ModelError
            The shoe would leave the jack's travel (the state is left as it was).
        """
        self.last_events = []
        self.inputs = inputs
        x = np.array(self.state, dtype=float)
        if self.config.drive == "speed":
            x = self._speed_jump(x, inputs.speed_command)
        else:
            x = self._settle(t, x, [])
        try:
            x, events = self.solver.advance(self, t, x, t + h)
        except IntegrationError as err:
            raise IntegrationError(f"{err}{self._overrun(inputs, h)}") from None
        geometry = self.config.geometry
        height = self.height(float(x[0]))
        if not geometry.min_height <= height <= geometry.max_height:
            raise ModelError(
                f"the shoe would reach {height:.6g} m, outside the jack's travel "
                f"[{geometry.min_height}, {geometry.max_height}] m (end of travel)"
            )
        self.state = x
        return events

    def _overrun(self, inputs: JackInputs, h: float) -> str:
        """Why a step of ``h`` (s) failed, when a speed command turns the screw past the
        jack's whole travel within it (the rods' geometry then has no solution); else ""."""
        if self.config.drive != "speed":
            return ""
        geometry = self.config.geometry
        span = geometry.travel_at_height(geometry.max_height) - geometry.travel_at_height(
            geometry.min_height
        )
        travel = self.config.thread.lead_per_radian * abs(inputs.speed_command) * h
        if not travel > span:
            return ""
        return (
            f": input handle.speed_command = {inputs.speed_command:g} rad/s (handle_drive "
            f"'speed') turns the screw {travel:.3g} m in this step, beyond the jack's whole "
            f"travel of {span:.3g} m"
        )

    def _speed_jump(self, x: np.ndarray, command: float) -> np.ndarray:
        """Adopt a new commanded speed; the drive supplies the kinetic-energy jump."""
        if command != x[1]:
            x[3] += 0.5 * self.inertia(float(x[0])) * (command * command - x[1] * x[1])
            x[1] = command
        return x

    # ---------------------------------------------------------- outputs
    def stored_energy(self, x: np.ndarray | None = None) -> float:
        """Kinetic energy of handle and load plus ``W y``, J.

        Parameters
        ----------
        x : ndarray, optional
            State ``[psi (rad), psi' (rad/s), ...]`` (default: the current one).
        """
        x = self.state if x is None else x
        psi, omega = float(x[0]), float(x[1])
        return 0.5 * self.inertia(psi) * omega**2 + self.config.load_weight * self.height(psi)

    def report(self, x: np.ndarray | None = None) -> JackReport:
        """Outputs at state ``x`` (default: the current one) for the held inputs.

        Parameters
        ----------
        x : ndarray, optional
            State ``[psi (rad), psi' (rad/s), ...]`` (default: the current one).
        """
        x = self.state if x is None else np.asarray(x, dtype=float)
        psi, omega = float(x[0]), float(x[1])
        f = self.forces(x)
        travel = self.travel(psi)
        _, slope, _ = self.config.geometry.slopes(travel)
        return JackReport(
            handle_angle=psi,
            handle_speed=omega,
            handle_torque=f.handle_torque,
            screw_travel=travel,
            load_height=self.height(psi),
            load_velocity=self.h * slope * omega,
            screw_displacement=0.5 * travel,
            rod_angle=self.config.geometry.rod_angle(travel),
            screw_axial_force=f.axial_force,
            thread_lead_torque=self.h * f.axial_force,
            thread_friction_torque=f.friction_torque,
            thread_state=self.thread_state(x),
            stored_energy=self.stored_energy(x),
            dissipated_energy=float(x[2]),
            external_work=float(x[3]),
        )

    @contextmanager
    def trial(self, inputs: JackInputs) -> Iterator[np.ndarray]:
        """The state as it would start a step with ``inputs``; undone on exit.

        Parameters
        ----------
        inputs : JackInputs
            The handle commands to read the outputs for.
        """
        saved = (
            self.inputs,
            self.friction.get_mode(),
            self.mode_changes,
            list(self.last_events),
            self._held_angle,
            self.state.copy(),
        )
        try:
            self.inputs = inputs
            x = np.array(self.state, dtype=float)
            if self.config.drive == "speed":
                x = self._speed_jump(x, inputs.speed_command)
            else:
                x = self._settle(0.0, x, [])
            yield x
        finally:
            (
                self.inputs,
                mode,
                self.mode_changes,
                self.last_events,
                self._held_angle,
                self.state,
            ) = saved
            self.friction.set_mode(mode)

    def get_state(self) -> dict[str, Any]:
        """Complete model state as plain data."""
        return {
            "x": [float(c) for c in self.state],
            "friction_mode": self.friction.get_mode(),
            "held_angle": float(self._held_angle),
            "mode_changes": int(self.mode_changes),
            "inputs": [float(self.inputs.speed_command), float(self.inputs.torque_command)],
            "solver": {"rhs_calls": int(self.solver.rhs_calls), "steps": int(self.solver.steps)},
        }

    def set_state(self, data: dict[str, Any]) -> None:
        """Restore a state from :meth:`get_state`.

        Parameters
        ----------
        data : dict
            A state from :meth:`get_state`.
        """
        self.state = np.array(data["x"], dtype=float)
        self.friction.set_mode(list(data["friction_mode"]))
        self._held_angle = float(data["held_angle"])
        self.mode_changes = int(data["mode_changes"])
        self.inputs = JackInputs(*data["inputs"])
        self.solver.rhs_calls = int(data["solver"]["rhs_calls"])
        self.solver.steps = int(data["solver"]["steps"])
