"""The block train: rope reeved over sheaves between anchors and line ends.

Assembled from the parts in :mod:`rope`, :mod:`geometry`, :mod:`friction`
(SPEC sections 2-6, paper 000). Which effects are included decides the
model's states:

========================  ===================================================
always                    rope springs with slack; blocks (mass, gravity,
                          floor); rope break; energy bookkeeping
``rope_damping``          Kelvin-Voigt term in every rope spring
``sheave_inertia``        each sheave a rotating mass: one coordinate per
                          sheave, rope spans no longer merge across it
``bearing_friction``      dry bearing friction per sheave (needs inertia)
``rope_slip``             rope on the groove is its own mass, gripping or
                          slipping by the capstan law (needs inertia)
``moving_geometry``       tangent points recomputed as bodies move
``spatial_geometry``      non-planar reevings, with fleet angles
========================  ===================================================

Coordinates and signs
---------------------
Along the path, node ``k`` joins segment ``k-1`` to segment ``k``. The rope
coordinate ``s_k`` counts unstretched rope that has passed node ``k``
forwards (from segment ``k-1`` into segment ``k``). Segment ``k`` then has
unstretched length ``l_k = l_k(0) + s_k - s_{k+1}``. A line end at the
start of the path has ``s = payout`` (rope paid in); at the end,
``s = -payout``. An anchor has ``s = 0``. A massless frictionless sheave
has no coordinate: the segments on both sides form one *span* (one spring).
Bodies move along their unit direction by a displacement ``y``.

The equations of motion are Lagrange's with the rope strain energy of
:mod:`rope`, so the energy ledger closes to integration error.
"""

from __future__ import annotations

import itertools
import math
import operator
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np

from wire_fmu.core.components.rope import rope_forces
from wire_fmu.core.errors import ConfigurationError
from wire_fmu.core.framework.compiled import use_compiled
from wire_fmu.core.framework.compiled_step import CompiledFixedStep, KernelModel
from wire_fmu.core.framework.effects import Effect, EffectCatalogue
from wire_fmu.core.framework.hybrid import SolverSettings
from wire_fmu.core.units.block_train import kernel
from wire_fmu.core.units.block_train.compiled_model import CompiledBlockTrain
from wire_fmu.core.units.block_train.friction_links import FrictionLinks
from wire_fmu.core.units.block_train.modes import ModeSwitching
from wire_fmu.core.units.block_train.ordered_sums import (
    ordered_matmul,
    ordered_matvec,
    ordered_vecmat,
)
from wire_fmu.core.units.block_train.path import ReevedPath
from wire_fmu.core.units.block_train.reeving import LINE_PORTS, MOVER_PORTS, Reeving
from wire_fmu.core.units.block_train.start import StartingState

__all__ = ["BlockTrainModel", "BlockTrainInputs", "BLOCK_TRAIN_EFFECTS", "FLAT_INPUTS", "HeldParts"]

_INERTIA = ("sheave_inertia",)
_EFFECTS = (  # name, the model without it, with it, the effects it needs
    ("rope_damping", "Hooke rope (eq. 3)", "Kelvin-Voigt rope (eq. 5)", ()),
    ("sheave_inertia", "massless sheaves, merged springs", "sheave inertia (eq. 11)", ()),
    ("bearing_friction", "frictionless bearings", "dry bearing friction with stick", _INERTIA),
    ("rope_slip", "rope grips the groove", "capstan slip (eq. 9-12)", _INERTIA),
    ("moving_geometry", "fixed line directions", "tangent points recomputed (eq. 16-31)", ()),
    ("spatial_geometry", "planar reeving", "3-D reeving with fleet angles", ()),
)
BLOCK_TRAIN_EFFECTS = EffectCatalogue(
    "block train",
    tuple(Effect(name, off, on, requires=needs) for name, off, on, needs in _EFFECTS),
)


class HeldParts(NamedTuple):
    """The held inputs' vector in its parts (:meth:`BlockTrainModel.held_parts`)."""

    line_positions: np.ndarray
    """The line ports' rope positions at the step's start, m."""
    line_rates: np.ndarray
    """Their rates, m/s."""
    mover_positions: np.ndarray
    """The driven bodies' positions at the step's start, m."""
    mover_velocities: np.ndarray
    """Their velocities, m/s."""
    line_accelerations: np.ndarray
    """The line rates' slopes over the step (ramped flows; else 0), m/s^2."""
    mover_accelerations: np.ndarray
    """The driven bodies' accelerations over the step (ramped flows; else 0), m/s^2."""


@dataclass
class BlockTrainInputs:
    """Inputs held over one step, from its start: each rate ramps with its acceleration
    (held when that is 0) and each position advances with the rate.

    Attributes
    ----------
    payout : dict of str to float
        Rope paid in through each line end, m (unstretched length).
    payout_rate : dict of str to float
        Its rate, m/s.
    mover_position, mover_velocity : dict of str to float
        Displacement (m) and velocity (m/s) of each driven body's port.
    payout_acceleration, mover_acceleration : dict of str to float
        The rates' change over the step, m/s² (a ramped flow); none: held.
    """

    payout: dict[str, float]
    payout_rate: dict[str, float]
    mover_position: dict[str, float]
    mover_velocity: dict[str, float]
    payout_acceleration: dict[str, float] = field(default_factory=dict)
    mover_acceleration: dict[str, float] = field(default_factory=dict)

    @classmethod
    def from_flat(cls, flat: Sequence[float]) -> BlockTrainInputs:
        """The inputs from their values in the order of :data:`FLAT_INPUTS`.

        Parameters
        ----------
        flat : sequence of float
            Each field's value at each of its ports, in the order of :data:`FLAT_INPUTS`
            (m, m/s, m/s²).
        """
        fields = map(dict, map(zip, _FLAT_PORTS, map(list(flat).__getitem__, _FLAT_SLICES)))
        return cls(**dict(zip(_FLAT_FIELDS, fields, strict=True)))

    def flat(self) -> tuple[float, ...]:
        """The inputs' values in the order of :data:`FLAT_INPUTS` (0 at a port without one):
        the inverse of :meth:`from_flat`."""
        return tuple(
            getattr(self, name).get(port, 0.0) for name, ports in FLAT_INPUTS for port in ports
        )


FLAT_INPUTS = (
    ("payout", LINE_PORTS),
    ("payout_rate", LINE_PORTS),
    ("payout_acceleration", LINE_PORTS),
    ("mover_position", MOVER_PORTS),
    ("mover_velocity", MOVER_PORTS),
    ("mover_acceleration", MOVER_PORTS),
)
"""The inputs as one flat sequence (:meth:`BlockTrainInputs.from_flat`): each field of
:class:`BlockTrainInputs` with the ports it has a value at, in this order."""
_FLAT_FIELDS = tuple(name for name, _ in FLAT_INPUTS)
_FLAT_PORTS = tuple(ports for _, ports in FLAT_INPUTS)
_FLAT_SLICES = tuple(
    slice(end - len(ports), end)
    for ports, end in zip(_FLAT_PORTS, itertools.accumulate(map(len, _FLAT_PORTS)), strict=True)
)
"""Where each field's values sit in the flat sequence."""


class BlockTrainModel(
    KernelModel, CompiledBlockTrain, FrictionLinks, ReevedPath, ModeSwitching, StartingState
):
    """Hybrid ODE of a block train; see the module docstring.

    Parameters
    ----------
    reeving : Reeving
        Validated reeving.
    effects : frozenset of str
        Effects to include (validated by :data:`BLOCK_TRAIN_EFFECTS`).
    solver : SolverSettings
        Internal solver for :meth:`advance`.
    """

    KERNEL = kernel
    GEOMETRY_STEP = 1e-6  # m, central differences of lengths w.r.t. body motion

    def __init__(self, reeving: Reeving, effects: frozenset[str], solver: SolverSettings) -> None:
        self.reeving = reeving
        self.effects = effects
        self.settings = solver
        self.rope = reeving.rope
        if "rope_slip" in effects and not self.rope.linear_mass > 0.0:
            raise ConfigurationError(
                "block train",
                [
                    "effect 'rope_slip' needs rope 'linear_mass' > 0 kg/m (the rope on a groove "
                    "is the mass that slips)"
                ],
            )
        if "rope_damping" not in effects:
            self.rope = replace(self.rope, damping=0.0)
        self._build_nodes()
        self._build_coordinates()
        self._build_spans()
        self._build_geometry()
        self._build_friction()
        self._build_flow_map()
        self._floored = [j for j, b in enumerate(self.blocks) if b.floor is not None]
        self._guard_dirs = self._guard_directions()
        self.broken = [False] * len(self.spans)
        self.offsets = np.zeros(len(self.spans))  # l_span(0) - s(start) + s(end)
        self.state = np.zeros(2 * self.n_coords + 2)
        self.set_inputs(0.0, BlockTrainInputs({}, {}, {}, {}))
        self.mode_changes = 0
        self.last_events: list[str] = []
        self.first_event_time = math.inf  # of the last step's located events, s
        self._held_positions = np.zeros(self.n_coords)
        self.taut_mask = np.ones(len(self.spans), dtype=bool)
        self.contact_mask = np.zeros(len(self.blocks), dtype=bool)
        self._build_kernel_arrays()
        self.compiled = self.kernel_applies() and use_compiled("block train")
        self.solver = self.kernel_solver(self._internal_solver(solver))

    def resume_entry(self):
        """:meth:`KernelModel.resume_entry`: through the block train's one compiled entry
        point (:meth:`CompiledBlockTrain.resume`)."""
        return self.resume

    def _internal_solver(self, settings: SolverSettings) -> SolverSettings:
        """``settings``, with one internal step a communication step when nothing is dynamic.

        A block train without coordinates (every body driven, sheaves massless) is
        algebraic in its held inputs: its only states are the energy ledgers, and RK4
        on them is Simpson's rule. With no line paid out and lengths linear in the
        body motion, a span's stretch moves linearly over a step with the inputs held
        and its damper force stays constant: the powers are quadratic in time and one
        step integrates them exactly; otherwise they are smooth over the step (error
        of order ``h^5``). A guard (slack, break) then crosses at most once a step.
        """
        if self.n_coords:
            return settings
        return replace(settings, max_step=math.inf)

    # ------------------------------------------------------------------ build
    @property
    def broken(self) -> list[bool]:
        """Whether each rope span has broken."""
        return [bool(b) for b in self.broken_mask]

    @broken.setter
    def broken(self, value: list[bool]) -> None:
        """Set which rope spans have broken.

        Parameters
        ----------
        value : list of bool
            One flag per rope span, True if broken.
        """
        self.broken_mask = np.array(value, dtype=bool)

    # ---------------------------------------------------------- state layout
    @property
    def q(self) -> np.ndarray:
        """Coordinates (m): blocks, rims, rope on grooves."""
        return self.state[: self.n_coords]

    @property
    def v(self) -> np.ndarray:
        """Velocities (m/s), same order as :attr:`q`."""
        return self.state[self.n_coords : 2 * self.n_coords]

    # ------------------------------------------------------------ kinematics
    def _build_flow_map(self) -> None:
        """Unstretched span lengths as ``l = offsets + B @ [q, s_line_a, s_line_b]``."""
        n = self.n_coords
        flow = np.zeros((len(self.spans), n + len(LINE_PORTS)))
        self.line_sign = np.zeros(len(LINE_PORTS))
        for k in (0, self.n_nodes - 1):
            node = self.nodes[k]
            if node.kind == "line_end":
                self.line_sign[LINE_PORTS.index(node.name)] = 1.0 if k == 0 else -1.0
        for i, sp in enumerate(self.spans):
            for node, sign in ((sp.start_node, 1.0), (sp.end_node, -1.0)):
                if node in self.rope_index:
                    flow[i, self.rope_index[node]] += sign
                elif self.nodes[node].kind == "line_end":
                    flow[i, n + LINE_PORTS.index(self.nodes[node].name)] += sign
        self.flow_matrix = flow
        width = max(1, max((np.count_nonzero(row) for row in flow), default=0))
        self.kernel_flow_columns = np.full((len(self.spans), width), -1, dtype=np.int64)
        self.kernel_flow_values = np.zeros((len(self.spans), width))
        for i, row in enumerate(flow):
            columns = np.flatnonzero(row)
            self.kernel_flow_columns[i, : columns.size] = columns
            self.kernel_flow_values[i, : columns.size] = row[columns]
        self._line_signs = [float(c) for c in self.line_sign]
        self.driver_ports = [b.port for b in self.drivers]
        self._build_held_gather()
        self.block_weight = np.array(
            [
                b.mass * float(np.array(self.reeving.gravity) @ np.array(b.direction))
                for b in self.blocks
            ]
        )

    def set_inputs(self, t: float, inputs: BlockTrainInputs) -> None:
        """Hold ``inputs`` from time ``t`` on (positions advance with their rates).

        Parameters
        ----------
        t : float
            Time from which the inputs hold, s.
        inputs : BlockTrainInputs
            Line payouts and mover positions at ``t``, with their rates.
        """
        self._hold(t, inputs, self._held(t, inputs))

    @property
    def inputs(self) -> BlockTrainInputs:
        """The inputs held since the last step started (made from their flat values, when a
        quiet step held them so, on first use)."""
        if self._inputs is None:
            self._inputs = BlockTrainInputs.from_flat(self._flat_inputs)
        return self._inputs

    def _build_held_gather(self) -> None:
        """Where each entry of the held-input vector (:meth:`_held`) sits in
        ``(t, *flat inputs)`` (:data:`FLAT_INPUTS`), and the sign it is taken with."""
        flat = [(name, port) for name, ports in FLAT_INPUTS for port in ports]
        at = {entry: 1 + k for k, entry in enumerate(flat)}  # 0 is the time
        drivers, ones = self.driver_ports, [1.0] * len(self.driver_ports)
        entries = [(1.0, 0)]
        for name, ports, signs in (
            ("payout", LINE_PORTS, self._line_signs),
            ("payout_rate", LINE_PORTS, self._line_signs),
            ("mover_position", drivers, ones),
            ("mover_velocity", drivers, ones),
            ("payout_acceleration", LINE_PORTS, self._line_signs),
            ("mover_acceleration", drivers, ones),
        ):
            entries += [(sign, at[(name, port)]) for port, sign in zip(ports, signs, strict=True)]
        self._held_signs = [sign for sign, _ in entries]
        self._take_held = operator.itemgetter(*(index for _, index in entries))

    def _held_from_flat(self, t: float, flat: Sequence[float]) -> np.ndarray:
        """:meth:`_held` of the inputs whose flat values (:data:`FLAT_INPUTS`) are ``flat``:
        the same vector, to the last bit (a value times its sign, 1 for a driven body's)."""
        return np.array(list(map(operator.mul, self._held_signs, self._take_held((t, *flat)))))

    def _held(self, t: float, inputs: BlockTrainInputs) -> np.ndarray:
        """The held-input vector of the kernels (see :mod:`kernel`) for ``inputs`` from ``t``."""
        return self._held_from_flat(t, inputs.flat())

    def _hold(self, t: float, inputs: BlockTrainInputs | None, vector: np.ndarray) -> None:
        """Hold ``inputs`` (and their vector ``vector``, from :meth:`_held`) from ``t`` on;
        None: inputs whose flat values :attr:`_flat_inputs` holds."""
        self._inputs = inputs
        self._t_step = t
        self._step_summary = None
        self.start_table: tuple | None = None  # (t, x, rows, table) of evaluate_start
        self.held_vector = vector

    def held_parts(self) -> HeldParts:
        """The held inputs' vector (:attr:`held_vector`) in its parts (views of it)."""
        nl, nd, vector = len(LINE_PORTS), len(self.driver_ports), self.held_vector
        lines, movers, ramps = 1 + nl, 1 + 2 * nl, 1 + 2 * nl + 2 * nd
        return HeldParts(
            vector[1:lines],
            vector[lines:movers],
            vector[movers : movers + nd],
            vector[movers + nd : ramps],
            vector[ramps : ramps + nl],
            vector[ramps + nl :],
        )

    def held_motion(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The held inputs' motion at ``t``: line rope positions and rates, driven bodies'
        positions and velocities (m, m/s; the kernel's :func:`kernel.held_motion`).

        Parameters
        ----------
        t : float
            Time, s.
        """
        dt = t - self._t_step
        line_s0, line_rate0, mover_y0, mover_v0, line_acc, mover_acc = self.held_parts()
        line_rate = line_rate0 + line_acc * dt
        mover_v = mover_v0 + mover_acc * dt
        line_s = line_s0 + (line_rate0 + 0.5 * line_acc * dt) * dt
        mover_y = mover_y0 + (mover_v0 + 0.5 * mover_acc * dt) * dt
        return line_s, line_rate, mover_y, mover_v

    @contextmanager
    def holding(self, vector: np.ndarray) -> Iterator[None]:
        """Evaluate with the held-input vector ``vector`` (layout of :meth:`_held`) inside
        the ``with`` block; the inputs held before come back after it."""
        t_held, inputs, kept = self._t_step, self.inputs, self.held_vector
        summary = self._step_summary
        self._hold(t_held, inputs, vector)
        try:
            yield
        finally:
            self._hold(t_held, inputs, kept)
            self._step_summary = summary

    def span_lengths(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Geometric span lengths (m) and their Jacobian w.r.t. body motion.

        The geometry is chosen once, when the path is built:
        :meth:`_fixed_span_lengths` or :meth:`_moving_span_lengths`.

        Parameters
        ----------
        y : numpy.ndarray
            Body displacements along their directions, m: the blocks, then the driven bodies.

        Returns
        -------
        lengths : numpy.ndarray
            Geometric length of each span, m.
        jacobian : numpy.ndarray
            ``d lengths / d y``, one row per span and one column per body, 1.
        """
        return self._span_geometry(y)

    def _fixed_span_lengths(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`span_lengths` with fixed line directions: linear in ``y``."""
        return self.span_length0 + ordered_matvec(self.span_jacobian, y), self.span_jacobian

    def _moving_span_lengths(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`span_lengths` with ``moving_geometry``: tangent points recomputed."""
        lengths = self._moving_segment_lengths
        seg = lengths(y)
        jac = np.zeros((self.n_segments, len(y)))
        h = self.GEOMETRY_STEP
        for b in range(len(y)):
            step = np.zeros(len(y))
            step[b] = h
            jac[:, b] = (lengths(y + step) - lengths(y - step)) / (2 * h)
        return ordered_matvec(self.span_matrix, seg), ordered_matmul(self.span_matrix, jac)

    def _spatial_segment_lengths(self, y: np.ndarray) -> np.ndarray:
        return self._segment_lengths(dict(zip(self.body_dof, y, strict=True)))[0]

    # -------------------------------------------------------------- physics
    def evaluate(self, t: float, x: np.ndarray) -> dict:
        """Everything the model knows at (t, x): forces, tensions, energies.

        Parameters
        ----------
        t : float
            Time, s.
        x : numpy.ndarray
            State ``[q, v, dissipated, external work]`` (m, m/s, J, J).

        Returns
        -------
        dict
            By name: generalised ``forces`` on the coordinates (N), span ``tension`` (N)
            and ``stretch`` (m), ``line_force`` at the line ends (N), ``body_force`` on
            the bodies (N), floor ``depth`` (m) and ``contact``/``trial_contact`` forces
            (N), ``rope_energy``/``span_energy``/``potential`` (J), ``loss`` power (W),
            the rope forces ``rope`` (Python kernel only), body displacements ``y`` (m) and
            velocities ``ydot`` (m/s), and the span lengths' ``span_jacobian`` ``dL/dy``
            (Python kernel only).
        """
        if self.compiled:
            return self._evaluate_compiled(t, x)
        n, nb = self.n_coords, len(self.blocks)
        q, v = x[:n], x[n : 2 * n]
        line_s, line_rate, mover_y, mover_v = self.held_motion(t)
        y = np.concatenate((q[:nb], mover_y))
        ydot = np.concatenate((v[:nb], mover_v))
        big_l, dl_dy = self.span_lengths(y)
        flow = np.concatenate((q, line_s))
        flow_rate = np.concatenate((v, line_rate))
        small_l = self.offsets + ordered_matvec(self.flow_matrix, flow)
        if np.any(small_l <= 0.0):
            i = int(np.argmin(small_l))
            raise FloatingPointError(f"rope span {i} has no unstretched rope left")
        intact = ~self.broken_mask
        rf = rope_forces(
            self.rope,
            big_l,
            small_l,
            ordered_matvec(dl_dy, ydot),
            ordered_matvec(self.flow_matrix, flow_rate),
            self.taut_mask & intact,
        )
        tension = rf.tension * intact
        g_big = rf.force_on_length * intact
        g_small = rf.force_on_unstretched * intact
        span_energy = rf.energy * intact
        body_force = -ordered_vecmat(g_big, dl_dy)
        generalised = ordered_vecmat(g_small, self.flow_matrix)  # on [q, s_line_a, s_line_b]
        forces = generalised[:n].copy()
        forces[:nb] += body_force[:nb] + self.block_weight
        potential = -float(self.block_weight @ q[:nb])
        loss = float(rf.loss_power @ intact)
        contact = np.zeros(nb)
        trial_contact = np.zeros(nb)
        depth = np.zeros(nb)
        for j in self._floored:
            block = self.blocks[j]
            depth[j], trial_contact[j], e, p_loss = _floor_contact(
                block.floor, block.position + q[j], v[j]
            )
            if self.contact_mask[j]:
                contact[j] = trial_contact[j]
                forces[j] += contact[j]
                potential += e
                loss += p_loss
            elif depth[j] > 0.0:  # lifting off faster than the pad recovers: it drains
                potential += e
                loss += block.floor.stiffness * depth[j] * v[j]
        return {
            "forces": forces,
            "tension": tension,
            "stretch": big_l - small_l,
            "line_force": generalised[n:],
            "rope": rf,
            "depth": depth,
            "trial_contact": trial_contact,
            "body_force": body_force,
            "contact": contact,
            "rope_energy": float(span_energy.sum()),
            "span_energy": span_energy,
            "potential": potential,
            "loss": loss,
            "y": y,
            "ydot": ydot,
            "span_jacobian": dl_dy,
            "line_rate": line_rate,
        }

    def _external_power(self, ev: dict) -> float:
        """Power delivered into the block train through its ports, W."""
        nb = len(self.blocks)
        power = -float(ev["line_force"] @ ev["line_rate"])
        power -= float(ev["body_force"][nb:] @ ev["ydot"][nb:])
        return power

    # ------------------------------------------------ HybridSystem protocol
    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """State derivative: [q', v', dissipated', external work'].

        Parameters
        ----------
        t : float
            Time, s.
        x : numpy.ndarray
            State ``[q, v, dissipated, external work]`` (m, m/s, J, J).
        """
        if self.compiled:
            return kernel.rhs(t, x, self.kernel_data())
        return self._rhs_of(x, self.evaluate(t, x))[0]

    def rhs_parts(self, t: float, x: np.ndarray) -> tuple:
        """:meth:`rhs` and the local pieces its coupled rows are sums of, from one
        evaluation (what the structured Jacobian differences; the compiled kernel's
        ``rhs_parts``, operation for operation).

        Parameters
        ----------
        t : float
            Time, s.
        x : numpy.ndarray
            State ``[q, v, dissipated, external work]`` (m, m/s, J, J).

        Returns
        -------
        tuple
            The state derivative; per span its tension (N), its share of the
            dissipated power and of the external power (W); ``dL/dy`` (spans x
            bodies); per friction link the power it dissipates (W).
        """
        if self.compiled:
            return kernel.rhs_parts(t, x, self.kernel_data())
        n, nb = self.n_coords, len(self.blocks)
        ev = self.evaluate(t, x)
        intact = ~self.broken_mask
        on_unstretched = ev["rope"].force_on_unstretched * intact
        tension, dl_dy = ev["tension"], ev["span_jacobian"]
        span_power = np.empty(len(self.spans))
        for i in range(len(self.spans)):
            p = 0.0
            for line, rate in enumerate(ev["line_rate"]):
                p -= on_unstretched[i] * self.flow_matrix[i, n + line] * rate
            for j, velocity in enumerate(ev["ydot"][nb:]):
                p += tension[i] * dl_dy[i, nb + j] * velocity
            span_power[i] = p
        out, link_force = self._rhs_of(x, ev)
        v = x[n : 2 * n]
        link_loss = np.array(
            [
                -link_force[k] * self.friction.relative_velocity(v, k) if mode != 0 else 0.0
                for k, mode in enumerate(self.friction.mode)
            ]
        )
        span_loss = ev["rope"].loss_power * intact
        return out, tension, span_loss, span_power, dl_dy, link_loss

    def _rhs_of(self, x: np.ndarray, ev: dict) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`rhs` from the Python kernel's evaluation ``ev`` at state ``x``, and the
        friction links' forces (N)."""
        n = self.n_coords
        v = x[n : 2 * n]
        out = np.empty_like(x)
        out[:n] = v
        caps = self._capacities(ev["tension"])
        acc, link_force = self.friction.accelerations(ev["forces"], caps)
        out[n : 2 * n] = acc
        if self.friction.links:
            out[self.friction.stuck_to_ground()] = 0.0
        out[2 * n] = ev["loss"] + self.friction.loss_power(v, link_force)
        out[2 * n + 1] = self._external_power(ev)
        return out, link_force

    # -------------------------------------------------------------- stepping
    def advance(
        self, t: float, h: float, inputs: BlockTrainInputs, break_segment: int | None = None
    ) -> int:
        """Advance the state from ``t`` by ``h`` with ``inputs`` held; return events.

        ``break_segment`` (0-based), if given, breaks that segment's span at ``t``.

        Parameters
        ----------
        t : float
            Start of the step, s.
        h : float
            Step length, s.
        inputs : BlockTrainInputs
            Inputs at ``t``, held over the step (positions advance with their rates).
        break_segment : int or None
            Segment (0-based) whose span breaks at ``t``; None for none.

        Returns
        -------
        int
            Number of events the solver located in the step.
        """
        self.last_events = []
        self.first_event_time = math.inf
        self._step_summary = None
        quiet = self.compiled and isinstance(self.solver, CompiledFixedStep)
        if quiet and break_segment is None and self._quiet_step(t, h, inputs):
            return self._quiet_events
        before = self._input_energy(t)
        self.set_inputs(t, inputs)
        changed = self._settle_contact_modes(t, self.state)
        # a jump of a position input does work on the rope at once: book it
        self.state[2 * self.n_coords + 1] += self._input_energy(t) - before
        self.mode_changes += int(changed)
        if break_segment is not None and not self.broken[self.span_of_segment[break_segment]]:
            self._break_span(self.span_of_segment[break_segment], self.state, t)
            self.mode_changes += 1  # a mode event: masters must not extrapolate across it
        self.state = self._settle_modes(t, self.state)  # new inputs may break a stuck link
        x, events = self.solver.advance(self, t, self.state, t + h)
        self.state = x
        return events

    def _input_energy(self, t: float) -> float:
        """The part of the stored energy that inputs can change at once (rope strain), J."""
        return self.summary(t, self.state)[0]

    def held_inputs(self) -> dict:
        """The inputs held since the last step started, as plain data."""
        inp = self.inputs
        return {
            "time": self._t_step,
            "payout": dict(inp.payout),
            "payout_rate": dict(inp.payout_rate),
            "mover_position": dict(inp.mover_position),
            "mover_velocity": dict(inp.mover_velocity),
            "payout_acceleration": dict(inp.payout_acceleration),
            "mover_acceleration": dict(inp.mover_acceleration),
        }

    def restore_held_inputs(self, data: dict) -> None:
        """Restore inputs saved by :meth:`held_inputs`.

        Parameters
        ----------
        data : dict
            Inputs as returned by :meth:`held_inputs`.
        """
        inputs = BlockTrainInputs(
            {k: float(v) for k, v in data["payout"].items()},
            {k: float(v) for k, v in data["payout_rate"].items()},
            {k: float(v) for k, v in data["mover_position"].items()},
            {k: float(v) for k, v in data["mover_velocity"].items()},
            {k: float(v) for k, v in data.get("payout_acceleration", {}).items()},
            {k: float(v) for k, v in data.get("mover_acceleration", {}).items()},
        )
        self.set_inputs(float(data["time"]), inputs)

    # ----------------------------------------------------------- energy
    def stored_energy(self, t: float | None = None) -> float:
        """Kinetic + strain + gravitational + contact energy, J.

        Parameters
        ----------
        t : float or None
            Time the held inputs are evaluated at, s; None for the start of the held step.
        """
        t = self._t_step if t is None else t
        rope_energy, potential, _, _ = self.summary(t, self.state)
        return self.kinetic_energy(self.state.tolist()) + rope_energy + potential

    def kinetic_energy(self, x: list[float]) -> float:
        """Kinetic energy of the coordinates' masses at state ``x``, J.

        Parameters
        ----------
        x : list of float
            The state ``[q, v, dissipated, external work]`` as a list (m, m/s, J, J): a
            sum over a few floats costs less in Python than a numpy call on them.
        """
        n = self.n_coords
        v = x[n : 2 * n]
        return 0.5 * sum(map(operator.mul, self.masses.tolist(), map(operator.mul, v, v)))


def _floor_contact(floor, position: float, velocity: float):
    """Depth, trial force (along the body direction), energy and loss of a floor contact.

    The force is that of a spring-damper while in contact; contact is a
    mode switched by the caller, so a support never pulls.
    """
    depth = floor.position - position
    elastic = floor.stiffness * depth
    damping = -floor.damping * velocity
    return depth, elastic + damping, 0.5 * elastic * depth, -damping * velocity
