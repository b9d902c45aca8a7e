"""Two rigid bodies joined by a screw pair, stepped in time with exact thread friction."""

from __future__ import annotations

import logging

import numpy as np

from wire_fmu.core.components.screw_nut.bodies import (
    BodyState,
    RigidBody,
    _cross,
    _quaternion_rate,
    _rotate_quaternion,
    _velocities,
)
from wire_fmu.core.components.screw_nut.joint import ScrewNutJoint

__all__ = ["ScrewNutSystem"]

logger = logging.getLogger(__name__)


class ScrewNutSystem:
    """Two rigid bodies joined by a :class:`ScrewNutJoint`, stepped in time.

    Each body keeps its own full state (as in paper 003's general-purpose
    formulation); the joint enters as Lagrange multipliers from
    ``[[M, -G^T], [G, 0]] [a; lambda] = [f; gamma]``. After each RK4 step
    positions and velocities are projected onto the joint (mass-weighted
    least change), unless ``stabilise`` is False -- which is the paper's
    velocity-level model, and drifts.

    Thread friction (``thread_friction=True``) is exact dry friction about
    the axis, bounded by ``r_mean mu |F_axial|`` with ``F_axial`` the joint's
    own axial multiplier. Modes as in :class:`~wire_fmu.core.components.friction.StickSlip`:
    *stuck* adds a sixth constraint, no relative rotation (the pair is a
    weld; its multiplier is the holding torque, and the relative angle is
    held at position level too), *sliding* in direction ``sigma`` applies
    ``-sigma r_mean mu |F_axial|``, solved together with the axial force it
    depends on. Guards (holding margin, ``sigma`` times the relative speed)
    are located within a step by bisection to ``event_tolerance``; a thread
    that stops sticks if it can hold, else slides back.

    Parameters
    ----------
    body_1, body_2 : RigidBody
        Screw and nut; ``body_1.fixed`` makes the screw the ground.
    joint : ScrewNutJoint
        The screw pair.
    state_1, state_2 : BodyState
        Initial states; velocities are made consistent with the joint.
    gravity : array_like, shape (3,)
        m/s^2.
    stabilise : bool
        Project onto the position-level constraints after every step.
    thread_friction : bool
        Dry friction in the thread (``joint.thread``'s radius and coefficient).
    event_tolerance : float
        Stick/slip transitions are located to within this time, s.
    """

    def __init__(
        self,
        body_1: RigidBody,
        body_2: RigidBody,
        joint: ScrewNutJoint,
        state_1: BodyState,
        state_2: BodyState,
        gravity=(0.0, 0.0, 0.0),
        stabilise: bool = True,
        thread_friction: bool = False,
        event_tolerance: float = 1e-10,
    ) -> None:
        if body_2.fixed:
            raise ValueError("the nut (body 2) must be free; fix the screw (body 1) instead")
        self.bodies = (body_1, body_2)
        self.joint = joint
        self.gravity = np.asarray(gravity, dtype=float)
        self.stabilise = stabilise
        self.thread_friction = thread_friction
        self.event_tolerance = event_tolerance
        self.r_mu = joint.thread.mean_radius * joint.thread.friction
        self.states = [state_1, state_2]
        self.time = 0.0
        self.mode = 0  # thread: 0 stuck, +1/-1 sliding (relative rotation about c)
        self.held_angle = 0.0
        self.events: list[tuple[float, str]] = []
        self.last_multipliers = np.zeros(ScrewNutJoint.N_CONSTRAINTS)
        self.friction_torque = 0.0
        self._free = np.r_[
            np.zeros(6, bool) if body_1.fixed else np.ones(6, bool), np.ones(6, bool)
        ]
        self.project()

    # -- dynamics -----------------------------------------------------------------
    def _mass_matrix(self, states: list[BodyState]) -> np.ndarray:
        m = np.zeros((12, 12))
        for i, (body, s) in enumerate(zip(self.bodies, states, strict=True)):
            r = s.rotation
            m[6 * i : 6 * i + 3, 6 * i : 6 * i + 3] = body.mass * np.eye(3)
            m[6 * i + 3 : 6 * i + 6, 6 * i + 3 : 6 * i + 6] = r @ body.inertia @ r.T
        return m[np.ix_(self._free, self._free)]

    def _forces(self, states: list[BodyState]) -> np.ndarray:
        f = np.zeros(12)
        for i, (body, s) in enumerate(zip(self.bodies, states, strict=True)):
            r = s.rotation
            inertia = r @ body.inertia @ r.T
            w = s.angular_velocity
            f[6 * i : 6 * i + 3] = body.mass * self.gravity
            f[6 * i + 3 : 6 * i + 6] = -_cross(w, inertia @ w)
        return f[self._free]

    def _axis_row(self, states: list[BodyState]) -> tuple[np.ndarray, float]:
        """Relative rotation about the axis: row ``c . (w2 - w1)`` and its ``gamma``."""
        c = self.joint.frame(states[0])[:, 2]
        row = np.zeros(12)
        row[3:6], row[9:12] = -c, c
        dw = states[1].angular_velocity - states[0].angular_velocity
        return row, -float(_cross(states[0].angular_velocity, c) @ dw)

    def relative_speed(self, states: list[BodyState] | None = None) -> float:
        """``c . (w2 - w1)``: the nut's speed relative to the screw about the axis, rad/s.

        Parameters
        ----------
        states : list of BodyState, optional
            Screw and nut (default: the current states).
        """
        states = self.states if states is None else states
        row, _ = self._axis_row(states)
        return float(row @ _velocities(*states))

    def _rows(self, states: list[BodyState], stuck: bool) -> tuple[np.ndarray, np.ndarray]:
        g, gamma = self.joint.jacobian(*states)
        if stuck:
            row, extra = self._axis_row(states)
            g, gamma = np.vstack([g, row]), np.r_[gamma, extra]
        return g, gamma

    def _solve(self, states: list[BodyState], mode: int) -> tuple[np.ndarray, np.ndarray, float]:
        """Accelerations, multipliers and the friction torque on the nut in ``mode``."""
        stuck = self.thread_friction and mode == 0
        g, gamma = self._rows(states, stuck)
        g = g[:, self._free]
        m = self._mass_matrix(states)
        n, rows = m.shape[0], g.shape[0]
        k = np.zeros((n + rows, n + rows))
        k[:n, :n], k[:n, n:], k[n:, :n] = m, -g.T, g
        rhs = np.r_[self._forces(states), gamma]
        if not self.thread_friction or stuck:
            sol = np.linalg.solve(k, rhs)
            torque = float(sol[n + 5]) if stuck else 0.0
        else:
            sol, torque = self._sliding(states, k, rhs, n, mode)
        acc = np.zeros(12)
        acc[self._free] = sol[:n]
        return acc, sol[n:], torque

    def _sliding(self, states, k, rhs, n, mode) -> tuple[np.ndarray, float]:
        """Solve with the torque ``-mode r mu |lambda_axial|`` consistent with its axial force."""
        row, _ = self._axis_row(states)
        unit = np.r_[row[self._free], np.zeros(k.shape[0] - n)]
        base, per_torque = np.linalg.solve(k, np.column_stack([rhs, unit])).T
        axial = n + 4
        for sign in (1.0, -1.0):
            denominator = 1.0 + mode * self.r_mu * sign * per_torque[axial]
            if denominator <= 0.0:
                continue
            torque = -mode * self.r_mu * sign * base[axial] / denominator
            sol = base + torque * per_torque
            if sign * sol[axial] >= 0.0:
                return sol, torque
        raise ArithmeticError("thread friction has no consistent solution (Painleve's paradox)")

    def accelerations(self, states: list[BodyState]) -> tuple[np.ndarray, np.ndarray]:
        """Accelerations ``[a1, alpha1, a2, alpha2]`` (zeros for a fixed body) and multipliers.

        The multipliers are the joint's five (bending moments, reaction
        force); a stuck thread's holding torque is :attr:`friction_torque`.

        Parameters
        ----------
        states : list of BodyState
            Screw and nut.

        Returns
        -------
        accelerations : ndarray, shape (12,)
            ``[a1 (m/s^2), alpha1 (rad/s^2), a2, alpha2]``.
        multipliers : ndarray, shape (5,)
            The joint's multipliers (N m, N m, N, N, N).
        """
        acc, lam, _ = self._solve(states, self.mode)
        return acc, lam[: ScrewNutJoint.N_CONSTRAINTS]

    def _rate(self, y: np.ndarray) -> np.ndarray:
        states = [BodyState.unpack(y[:13]), BodyState.unpack(y[13:])]
        acc, _ = self.accelerations(states)
        out = np.zeros(26)
        for i, s in enumerate(states):
            if self.bodies[i].fixed:
                continue
            o = 13 * i
            out[o : o + 3] = s.velocity
            out[o + 3 : o + 7] = _quaternion_rate(s.quaternion, s.angular_velocity)
            out[o + 7 : o + 10] = acc[6 * i : 6 * i + 3]
            out[o + 10 : o + 13] = acc[6 * i + 3 : 6 * i + 6]
        return out

    # -- stepping ---------------------------------------------------------------------
    def _rk4(self, y: np.ndarray, h: float) -> list[BodyState]:
        k1 = self._rate(y)
        k2 = self._rate(y + 0.5 * h * k1)
        k3 = self._rate(y + 0.5 * h * k2)
        k4 = self._rate(y + h * k3)
        y = y + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        states = [BodyState.unpack(y[:13]), BodyState.unpack(y[13:])]
        for s in states:
            s.quaternion /= np.linalg.norm(s.quaternion)
        return states

    def _adopt(self, states: list[BodyState], h: float) -> None:
        self.states = states
        self.time += h
        self.joint.angle = self.joint.relative_angle(*self.states)
        if self.stabilise:
            self._project_positions(self._stuck())
            self._project_velocities(self._stuck())

    def guard(self, states: list[BodyState] | None = None) -> float:
        """Thread guard, >= 0 inside the mode: holding margin (N m) or ``sigma`` times speed.

        Parameters
        ----------
        states : list of BodyState, optional
            Screw and nut (default: the current states).
        """
        states = self.states if states is None else states
        if not self.thread_friction:
            return 1.0
        if self.mode != 0:
            return self.mode * self.relative_speed(states)
        _, lam, torque = self._solve(states, 0)
        return self.r_mu * abs(lam[4]) - abs(torque)

    def step(self, h: float) -> None:
        """Advance ``h`` seconds: RK4, stick/slip events located, projection onto the joint.

        Parameters
        ----------
        h : float
            Time step, s.
        """
        remaining, guard = h, self.guard()
        for _ in range(1000):
            if remaining <= 0.0:
                break
            y = np.r_[self.states[0].pack(), self.states[1].pack()]
            states = self._rk4(y, remaining)
            if guard >= 0.0 and self.guard(states) < 0.0:
                taken, states = self._locate(y, remaining)
                self._adopt(states, taken)
                self._settle(self.states, fired=True)
                remaining -= taken
            else:
                self._adopt(states, remaining)
                remaining = 0.0
            guard = self.guard()
        acc, lam, self.friction_torque = self._solve(self.states, self.mode)
        self.last_multipliers = lam[: ScrewNutJoint.N_CONSTRAINTS]

    def _locate(self, y: np.ndarray, h: float) -> tuple[float, list[BodyState]]:
        """Bisection for the first time the guard turns negative: (time taken, states just past)."""
        lo, hi = 0.0, h
        past = self._rk4(y, h)
        while hi - lo > self.event_tolerance:
            mid = 0.5 * (lo + hi)
            states = self._rk4(y, mid)
            if self.guard(states) < 0.0:
                hi, past = mid, states
            else:
                lo = mid
        return hi, past

    def _settle(
        self, states: list[BodyState], fired: bool = False, before: int | None = None
    ) -> None:
        """Make the thread's mode fit the state (StickSlip's rules); log a change."""
        before = self.mode if before is None else before
        if self.mode != 0 and (fired or self.relative_speed(states) == 0.0):
            self.mode = 0
            self.held_angle = self.joint.relative_angle(*states)
            self._project_velocities(True)  # the relative rotation stops, momentum kept
        if self.mode == 0:
            _, lam, torque = self._solve(self.states, 0)
            if abs(torque) > self.r_mu * abs(lam[4]):
                self.mode = -1 if torque > 0.0 else 1  # slides against the needed hold
            else:
                self.held_angle = self.joint.relative_angle(*self.states)
        if self.mode != before:
            words = {0: "stuck", 1: "sliding +", -1: "sliding -"}
            self.events.append((self.time, f"thread {words[self.mode]}"))
            logger.debug("t = %.9g s: thread %s", self.time, words[self.mode])

    # -- projection ------------------------------------------------------------------
    def project(self) -> None:
        """Put the bodies exactly on the joint (least change) and choose the thread's mode.

        Call after changing states by hand (e.g. setting initial velocities):
        the thread slides in the direction of the relative rotation, or, at
        relative rest, sticks if it can hold.
        """
        self._project_positions(False)
        self._project_velocities(False)
        if self.thread_friction:
            previous, self.mode = self.mode, int(np.sign(self.relative_speed()))
            self._settle(self.states, before=previous)
            if self.mode == 0:
                self._project_positions(True)

    def _stuck(self) -> bool:
        return self.thread_friction and self.mode == 0

    def _correction(self, g: np.ndarray, residual: np.ndarray) -> np.ndarray:
        """Mass-weighted least change ``-M^-1 G^T (G M^-1 G^T)^-1 residual``."""
        m_inv = np.linalg.inv(self._mass_matrix(self.states))
        gf = g[:, self._free]
        mu = np.linalg.solve(gf @ m_inv @ gf.T, residual)
        out = np.zeros(12)
        out[self._free] = -m_inv @ gf.T @ mu
        return out

    def _position_residual(self, stuck: bool) -> np.ndarray:
        residual = self.joint.position_residual(*self.states)
        if stuck:
            residual = np.r_[residual, self.joint.relative_angle(*self.states) - self.held_angle]
        return residual

    def _project_positions(
        self, stuck: bool, iterations: int = 4, tolerance: float = 1e-15
    ) -> None:
        for _ in range(iterations):
            residual = self._position_residual(stuck)
            if np.max(np.abs(residual)) <= tolerance:
                break
            g, _ = self._rows(self.states, stuck)
            delta = self._correction(g, residual)
            for i, s in enumerate(self.states):
                if not self.bodies[i].fixed:
                    s.position = s.position + delta[6 * i : 6 * i + 3]
                    s.quaternion = _rotate_quaternion(s.quaternion, delta[6 * i + 3 : 6 * i + 6])
            self.joint.angle = self.joint.relative_angle(*self.states)

    def _project_velocities(self, stuck: bool) -> None:
        g, _ = self._rows(self.states, stuck)
        delta = self._correction(g, g @ _velocities(*self.states))
        for i, s in enumerate(self.states):
            if not self.bodies[i].fixed:
                s.velocity = s.velocity + delta[6 * i : 6 * i + 3]
                s.angular_velocity = s.angular_velocity + delta[6 * i + 3 : 6 * i + 6]

    # -- invariants ----------------------------------------------------------------
    def kinetic_energy(self) -> float:
        """J."""
        total = 0.0
        for body, s in zip(self.bodies, self.states, strict=True):
            if body.fixed:
                continue
            r = s.rotation
            w = s.angular_velocity
            total += 0.5 * body.mass * float(s.velocity @ s.velocity)
            total += 0.5 * float(w @ (r @ body.inertia @ r.T) @ w)
        return total

    def potential_energy(self) -> float:
        """Gravitational energy ``-m g . x``, J."""
        return -sum(
            b.mass * float(self.gravity @ s.position)
            for b, s in zip(self.bodies, self.states, strict=True)
            if not b.fixed
        )

    def momentum(self) -> tuple[np.ndarray, np.ndarray]:
        """Linear momentum (kg m/s) and angular momentum about the origin (kg m^2/s)."""
        p, ang = np.zeros(3), np.zeros(3)
        for body, s in zip(self.bodies, self.states, strict=True):
            if body.fixed:
                continue
            r = s.rotation
            p += body.mass * s.velocity
            ang += body.mass * _cross(s.position, s.velocity)
            ang += (r @ body.inertia @ r.T) @ s.angular_velocity
        return p, ang
