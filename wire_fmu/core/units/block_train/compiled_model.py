"""The block train's side of its compiled kernel: the flat arrays, the one-call step.

:class:`CompiledBlockTrain` is the part of
:class:`~wire_fmu.core.units.block_train.model.BlockTrainModel` that says whether
:mod:`~wire_fmu.core.units.block_train.kernel` covers the model, builds the arrays the
kernel reads, takes a quiet step in one compiled call and keeps its summary for the
outputs.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from wire_fmu.core.framework import bordered_band
from wire_fmu.core.framework.compiled_step import STATUS_DONE, STATUS_PYTHON
from wire_fmu.core.framework.step_limits import IntegrationError
from wire_fmu.core.units.block_train import kernel, kernel_outputs
from wire_fmu.core.units.block_train.interface import RELATIVE_STEP, TIME_STEP
from wire_fmu.core.units.block_train.kernel_jacobian import coloured_jacobian, jacobian_structure
from wire_fmu.core.units.block_train.kernel_outputs import (
    EVALUATE,
    RESUME,
    STEP,
    STEP_WITH_OUTPUTS,
)
from wire_fmu.core.units.block_train.quiet_outputs import OutputPlan, output_plan

if TYPE_CHECKING:
    from wire_fmu.core.units.block_train.model import BlockTrainInputs

__all__ = ["BandedLinearAlgebra", "CompiledBlockTrain"]


class BandedLinearAlgebra:
    """ROS2's linear algebra of a block train for the Python solver: the structured
    Jacobian of :mod:`.kernel_jacobian` over the model's :meth:`rhs_parts
    <wire_fmu.core.units.block_train.model.BlockTrainModel.rhs_parts>`, factored and
    solved as a bordered band -- the compiled kernel's arithmetic, operation for
    operation.

    Parameters
    ----------
    model : BlockTrainModel
        The block train, in its current mode.
    """

    def __init__(self, model) -> None:
        self.model = model
        self.structure = model.kernel_jacobian_structure

    def linearise(self, t: float, x: np.ndarray) -> tuple[tuple, int]:
        """The Jacobian at ``(t, x)`` and the right-hand sides evaluated for it."""
        model = self.model
        columns = getattr(coloured_jacobian, "py_func", coloured_jacobian)
        return columns(
            lambda t, x, data: model.rhs_parts(t, x), t, x, None, self.structure, model.masses
        )

    def factor(self, jac: tuple, gh: float) -> tuple:
        """Factors of ``I - gh J`` (``gh`` in s)."""
        return bordered_band.factor(jac, gh, self.structure)

    def solve(self, factors: tuple, b: np.ndarray) -> np.ndarray:
        """``(I - gh J)^-1 b``."""
        return bordered_band.solve(factors, b, self.structure)


class CompiledBlockTrain:
    """Kernel arrays, compiled evaluation and the one-call step (a mixin of the model)."""

    def kernel_applies(self) -> bool:
        """Whether the compiled kernel covers this block train's effects.

        It does with lengths linear in the body motion or recomputed by the planar
        path (``moving_geometry`` without ``spatial_geometry``), with or without
        friction links; see :mod:`~wire_fmu.core.units.block_train.kernel`.
        """
        return not self.moving or self._planar is not None

    def _build_kernel_arrays(self) -> None:
        """The parameters of :mod:`~wire_fmu.core.units.block_train.kernel` as flat arrays."""
        moving = int(self.moving and self._planar is not None)
        self.kernel_sizes = np.array(
            [self.n_coords, len(self.blocks), len(self.drivers), moving], dtype=np.int64
        )
        self.kernel_rope = np.array(
            [self.rope.axial_stiffness, self.rope.damping, self.rope.breaking_load]
        )
        blocks = np.zeros((len(self.blocks), 5))
        for j, b in enumerate(self.blocks):
            blocks[j, :2] = self.block_weight[j], b.position
            if b.floor is not None:
                blocks[j, 2:] = b.floor.position, b.floor.stiffness, b.floor.damping
        self.kernel_blocks = blocks
        self._build_kernel_geometry(bool(moving))
        self.kernel_jacobian_structure = jacobian_structure(self)

    def linear_algebra(self) -> BandedLinearAlgebra:
        """ROS2's Jacobian and solves for the Python solver (see :class:`BandedLinearAlgebra`)."""
        return BandedLinearAlgebra(self)

    def jacobian_evaluations(self, x: np.ndarray) -> int:
        """Right-hand sides one structured Jacobian takes: one per colour and one more."""
        return int(self.kernel_jacobian_structure[0][4]) + 1

    def _build_kernel_geometry(self, moving: bool) -> None:
        """The planar path of :meth:`_planar_segment_lengths` as flat arrays (empty if fixed)."""
        segment_span = [self.span_of_segment[k] for k in range(self.n_segments)]
        self.kernel_segment_span = np.array(segment_span, dtype=np.int64)
        self.kernel_geometry_step = np.array([self.GEOMETRY_STEP])
        if not moving:
            self.kernel_path_nodes = np.zeros((0, 3))
            self.kernel_carriers = np.zeros((0, 1), dtype=np.int64)
            self.kernel_body_dirs = np.zeros((0, 2))
            return
        xy0, radii, dof_of_node, dirs, _ = self._planar
        self.kernel_path_nodes = np.array([(x, z, r) for (x, z), r in zip(xy0, radii, strict=True)])
        width = max(1, max(len(dofs) for dofs in dof_of_node))
        carriers = np.full((self.n_nodes, width), -1, dtype=np.int64)
        for k, dofs in enumerate(dof_of_node):
            carriers[k, : len(dofs)] = dofs
        self.kernel_carriers = carriers
        self.kernel_body_dirs = np.array(dirs, dtype=float).reshape(len(self.body_dof), 2)

    def _evaluate_compiled(self, t: float, x: np.ndarray) -> dict:
        """:meth:`evaluate` by the compiled kernel (the Python one names a span run out)."""
        result = kernel.evaluate(t, x, self.kernel_data())
        forces, tension, stretch, line_force, body_force = (result[i] for i in (0, 1, 4, 5, 6))
        depth, trial_contact, span_energy, potential, loss = (result[i] for i in (7, 8, 9, 10, 11))
        if not result[13]:  # the Python kernel raises the error that names the span
            return self._python_evaluate(t, x)
        n, nb = self.n_coords, len(self.blocks)
        _, line_rate, mover_y, mover_v = self.held_motion(t)
        return {
            "forces": forces,
            "tension": tension,
            "stretch": stretch,
            "line_force": line_force,
            "depth": depth,
            "trial_contact": trial_contact,
            "body_force": body_force,
            "contact": np.where(self.contact_mask, trial_contact, 0.0),
            "rope_energy": float(span_energy.sum()),
            "span_energy": span_energy,
            "potential": potential,
            "loss": loss,
            "y": np.concatenate((x[:nb], mover_y)),
            "ydot": np.concatenate((x[n : n + nb], mover_v)),
            "line_rate": line_rate,
        }

    def _quiet_step(self, t: float, h: float, inputs: BlockTrainInputs) -> bool:
        """The step in one compiled call (:func:`kernel.quiet_step`, through the entry point
        :func:`.kernel_outputs.quiet_step_outputs`); False if it is Python's.

        Events inside the step are switched by :meth:`handle_events` as in any step:
        the compiled loop goes on from the first one.
        """
        held = self._held(t, inputs)
        solver = self.solver
        t1 = t + h
        n = solver.internal_count(t, t1)
        arguments = self._quiet_arguments(t, t1, n, held, self._no_outputs(), 0.0, STEP)
        result = kernel_outputs.quiet_step_outputs(*arguments)
        if result[0] == STATUS_PYTHON:
            return False
        self._hold(t, inputs, held)
        if self.friction.links:
            self._held_positions = self.state[: self.n_coords].copy()
        self.state, self._quiet_events, values = solver.finish_quiet_step(
            self, t, self.state, t1, result
        )
        if values is not None:
            self._step_summary = (t1, self.state, values)
        return True

    def quiet_step_outputs(
        self, t: float, h: float, flat: tuple[float, ...], plan: OutputPlan, initial_energy: float
    ) -> list[float] | None:
        """A step in which nothing happens, with its outputs: one call of the compiled step,
        one of the interface model if ports publish it, one of the outputs.

        What :meth:`advance` and then the unit's outputs do for such a step, with the same
        arithmetic, to the last bit (:mod:`.kernel_outputs`), without the Python between
        the calls. When anything happens in the step -- a mode switch, an event, a value
        that is not finite -- it changes nothing and answers None: the step is then taken
        the general way, which names what happened.

        Parameters
        ----------
        t, h : float
            Start and length of the step, s.
        flat : tuple of float
            The inputs at ``t``, in the order of :data:`.model.FLAT_INPUTS`.
        plan : OutputPlan
            Which outputs, in which order (:func:`.quiet_outputs.output_plan`).
        initial_energy : float
            The stored energy at the start, J.

        Returns
        -------
        list of float or None
            The values of ``plan.names``, in their units; None if the step was not taken.
        """
        solver, t1 = self.solver, t + h
        try:
            count = solver.internal_count(t, t1)
        except IntegrationError:  # a step too long: refused the general way, with the reason
            return None
        held = self._held_from_flat(t, flat)
        arguments = self._quiet_arguments(t, t1, count, held, plan, initial_energy)
        status, x, _, _, _, steps, rhs_calls, _, values, held_positions, out, finite = (
            kernel_outputs.quiet_step_outputs(*arguments)
        )
        if status != STATUS_DONE or not finite:
            return None
        self.last_events = []
        self.first_event_time = math.inf
        self._flat_inputs = flat
        self._hold(t, None, held)
        self._held_positions = held_positions
        self.state = x
        self._step_summary = (t1, x, values)
        solver.steps += steps
        solver.rhs_calls += rhs_calls
        return out.tolist()

    def _quiet_arguments(
        self,
        t: float,
        t1: float,
        count: int,
        held: np.ndarray,
        plan: OutputPlan,
        initial_energy: float,
        mode: int = STEP_WITH_OUTPUTS,
        k: int = 0,
        t_from: float | None = None,
        *,
        x: np.ndarray | None = None,
        data: tuple | None = None,
    ) -> tuple:
        """The arguments of :func:`.kernel_outputs.quiet_step_outputs` for a step from
        ``t`` to ``t1`` (s) in ``count`` internal steps, with the inputs ``held``; the
        ``mode``'s, and with :data:`.kernel_outputs.RESUME` the interval ``k`` and time
        ``t_from`` (s) it goes on from, the state ``x`` and the kernel's ``data`` (by
        default the model's)."""
        return (
            self.solver.method,
            t,
            t1,
            count,
            self.settings.event_time_tolerance,
            self.state if x is None else x,
            self._guard_dirs,
            self.kernel_data() if data is None else data,
            held,
            self._held_positions,
            bool(self.friction.links),
            plan.interface_rows,
            RELATIVE_STEP,
            TIME_STEP,
            plan.no_ports,
            len(self.spans),
            self.masses,
            plan.line_spans,
            plan.driver_bodies,
            plan.block_coords,
            plan.block_starts,
            initial_energy,
            mode,
            k,
            t if t_from is None else t_from,
        )

    def evaluate_start(self, t: float, plan: OutputPlan) -> None:
        """The start's summary and ports' interface models, evaluated at ``(t, state)`` by
        :func:`.kernel_outputs.quiet_step_outputs` and kept for the start's outputs.

        The one call also loads that function (its callees with it) from the compiled-code
        cache, so that neither the start's outputs nor the first quiet step load a function
        of their own. Values that are not finite are not kept: the outputs are then
        evaluated the general way, which names the failure.

        Parameters
        ----------
        t : float
            The present time, s.
        plan : OutputPlan
            The unit's plan of its quiet steps' outputs.
        """
        arguments = self._quiet_arguments(t, t, 1, self.held_vector, plan, 0.0, EVALUATE)
        result = kernel_outputs.quiet_step_outputs(*arguments)
        values, table, finite = result[8], result[10], result[11]
        if finite:
            self._step_summary = (t, self.state, values)
            self.start_table = (t, self.state, plan.interface_rows, table)

    def resume(self, method, t0, t1, n, k, t, x, directions, tol, data) -> tuple:
        """The loop after an event (:class:`CompiledFixedStep`'s entry point), through the
        block train's one compiled entry point (:data:`.kernel_outputs.RESUME`).

        Parameters
        ----------
        method, t0, t1, n, k, t, x, directions, tol, data
            As :func:`~wire_fmu.core.framework.compiled_step.advance_to_event` takes them.
        """
        plan = self._no_outputs()  # the solver's method, tolerance and directions: the model's
        arguments = self._quiet_arguments(
            t0, t1, n, data[11], plan, 0.0, RESUME, k, t, x=x, data=data
        )
        return kernel_outputs.quiet_step_outputs(*arguments)[:8]

    def _no_outputs(self) -> OutputPlan:
        """A plan of no outputs but the fixed ones (for the modes that write none): the
        same argument types as every plan."""
        plan = getattr(self, "_plan_of_no_outputs", None)  # made at the first call
        if plan is None:
            plan = self._plan_of_no_outputs = output_plan(self, [], [], [], ())
        return plan

    def summary(self, t: float, x: np.ndarray) -> tuple[float, float, np.ndarray, np.ndarray]:
        """What the outputs need at ``(t, x)``.

        Parameters
        ----------
        t : float
            Time, s.
        x : numpy.ndarray
            State ``[q, v, dissipated, external work]`` (m, m/s, J, J).

        Returns
        -------
        rope_energy : float
            Strain energy of the rope, J.
        potential : float
            Gravitational and floor-contact energy, J.
        tension : numpy.ndarray
            Tension of each span, N.
        body_force : numpy.ndarray
            Force of the rope on each body along its direction (blocks, then driven), N.
        """
        if self.compiled:
            done = self._step_summary
            if done is not None and done[0] == t and done[1] is x:
                values = done[2]
            else:
                values = kernel.summary(t, x, self.kernel_data())
            if math.isfinite(values[0]):
                n_spans = len(self.spans)
                return values[0], values[1], values[2 : 2 + n_spans], values[2 + n_spans :]
        ev = self.evaluate(t, x) if not self.compiled else self._python_evaluate(t, x)
        return ev["rope_energy"], ev["potential"], ev["tension"], ev["body_force"]

    def _python_evaluate(self, t: float, x: np.ndarray) -> dict:
        """:meth:`evaluate` by the Python kernel."""
        with self.python_kernel():
            return self.evaluate(t, x)
