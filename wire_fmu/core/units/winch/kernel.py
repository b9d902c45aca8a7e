"""The winch's compiled kernel: drum, drive train, motor and band brake over flat arrays.

The same physics as :class:`~wire_fmu.core.units.winch.drive.WinchModel` (the
readable numpy reference), for a winch with drum inertia solved by RK4 or ROS2
(paper 004's energy-form solvers stay in Python). Everything a step needs is in
one tuple, built by :func:`kernel_data`:

=====  ===============  ====================================================
index  name             contents
=====  ===============  ====================================================
0      ``modes``        int: guards of the brake (0 without one, 2), brake
                        engaged (0/1), its stick/slip mode (0 stuck, +1/-1
                        sliding), guards of the layer (0 without layers, 2)
1      ``inertia``      inertia of each mass reduced to the drum shaft, kg m^2
2      ``stiffness``    chain stiffness matrix, N m/rad
3      ``damping``      chain damping matrix, N m s/rad
4      ``held``         see :data:`HELD`
=====  ===============  ====================================================

State ``[theta (n), omega (n), dissipated, external work]`` (rad, rad/s, J, J);
mass 0 is the motor rotor, mass ``n - 1`` the drum.
"""

from __future__ import annotations

import numpy as np

from wire_fmu.core.framework.compiled import kernel_decorators
from wire_fmu.core.framework.compiled_step import STATUS_DONE, STATUS_PYTHON, advance_to_event

jit = kernel_decorators(__file__).jit

__all__ = [
    "HELD",
    "OUTPUTS",
    "advance",
    "guards",
    "held_array",
    "kernel_data",
    "outputs",
    "project",
    "quiet_step",
    "resume",
    "rhs",
    "rope_tension",
    "summary",
]


HELD = (
    "motor torque at zero speed reduced to the drum shaft (N m)",
    "motor slope reduced to the drum shaft (N m s/rad)",
    "rope tension, or E0 of the rope's interface model (N)",
    "brake lever force (N)",
    "winding radius of the layer (m)",
    "rope inertia on the drum at phi = 0 for the layer (kg m^2)",
    "its slope d I / d phi (kg m^2/rad)",
    "brake capacity against paying out (N m)",
    "brake capacity against hauling in (N m)",
    "lowest drum angle of the layer (rad)",
    "highest drum angle of the layer (rad)",
    "drum angle the brake holds (rad)",
    "rope model: stiffness K (N/m)",
    "rope model: damping D (N s/m)",
    "rope model: effort rate R (N/s)",
    "rope model: reference payout (m)",
    "rope model: reference payout rate (m/s)",
    "rope model: the time it is about (s)",
    "rope paid out at drum angle 0 on the layer (m)",
    "motor command at the motor shaft (N m)",
    "motor ratio (motor speed per drum speed)",
    "motor slope at the motor shaft with the motor characteristic (N m s/rad), else NaN",
    "layered drum: 1, plain drum: 0",
)
"""What the ``held`` array holds, in order: inputs and the present layer's constants."""
_HELD_ANGLE = 11
_ROPE_MODEL = 12  # K, D, R, reference payout, reference rate, start: six entries from here
_PAYOUT_OFFSET = 18
_MOTOR_COMMAND = 19  # the command, the ratio, the slope (NaN: no characteristic), layered

OUTPUTS = (
    "rope.payout",
    "rope.payout_rate",
    "drum.speed",
    "drum.angle",
    "motor.speed",
    "motor.torque",
    "brake.torque",
    "brake.capacity",
    "stored_energy",
    "dissipated_energy",
    "external_work",
    "energy_balance",
)
"""The outputs :func:`quiet_step` computes at the end of a step, in order: all the winch's
outputs that can change in a step in which no mode changes (not the layer, its radius,
the brake's state or the count of mode changes)."""
_OUTPUT_COUNT = len(OUTPUTS)
BRAKE_TORQUE = OUTPUTS.index("brake.torque")
STORED_ENERGY = OUTPUTS.index("stored_energy")


def kernel_data(model) -> tuple:
    """The tuple the kernel functions take, from ``model``'s present inputs and modes.

    Parameters
    ----------
    model : WinchModel
        A winch with drum inertia.
    """
    inputs = model.inputs
    rope = inputs.rope_model
    held = held_array(
        model,
        inputs.motor_command,
        inputs.tension,
        inputs.lever_force,
        model._caps,
        (
            rope.stiffness,
            rope.damping,
            rope.effort_rate,
            rope.reference_position,
            rope.reference_velocity,
            rope.start,
        ),
    )
    return _modes(model), model.base_inertia, model.stiffness, model.damping, held


def held_array(
    model,
    motor_command: float,
    tension: float,
    lever_force: float,
    capacities: np.ndarray,
    rope_model: tuple[float, ...],
) -> np.ndarray:
    """The ``held`` array (:data:`HELD`) for these inputs and ``model``'s present layer.

    Parameters
    ----------
    model : WinchModel
        A winch with drum inertia.
    motor_command : float
        Motor torque, or its zero-speed torque with the characteristic, N m at the motor
        shaft.
    tension : float
        Rope tension, or ``E0`` of the rope's interface model, N.
    lever_force : float
        Brake lever force, N.
    capacities : numpy.ndarray
        The brake's capacities for ``lever_force``, shape (1, 2), N m.
    rope_model : tuple of float
        The rope's interface model: K (N/m), D (N s/m), R (N/s), reference payout (m) and
        rate (m/s), the time it is about (s); all 0 without one.
    """
    radius, offset, slope, low, high, paid = _layer_constants(model)
    stiffness, damping, rate, position, velocity, start = rope_model
    return np.array(
        [
            model.motor_ratio * motor_command,
            model.motor_b,
            tension,
            lever_force,
            radius,
            offset,
            slope,
            capacities[0, 0],
            capacities[0, 1],
            low,
            high,
            model._held_angle,
            stiffness,
            damping,
            rate,
            position,
            velocity,
            start,
            paid,
            motor_command,
            *model.kernel_constants,
        ]
    )


def _layer_constants(model) -> tuple[float, float, float, float, float, float]:
    """The present layer's radius (m), rope inertia at 0 (kg m^2) and its slope
    (kg m^2/rad), lowest and highest drum angle (rad) and rope paid out at angle 0 (m);
    kept on the model per layer."""
    kept = model._kernel_layer
    if kept is not None and kept[0] == model.layer:
        return kept[1]
    drum, k = model.drum, model.layer
    low, high = drum.phi_bounds(k)
    constants = (
        drum.layer_radius(k),
        drum.rope_inertia(0.0, k),
        drum.rope_inertia_slope(k),
        low,
        high,
        drum.payout(0.0, k),
    )
    model._kernel_layer = (k, constants)
    return constants


def _modes(model) -> np.ndarray:
    """The ``modes`` array for the brake's present modes (kept on the model while they hold;
    never changed in place)."""
    mode = int(model.friction.mode[0]) if model.friction.links else 0
    key = (int(model.engaged), mode)
    kept = model._kernel_modes
    if kept is not None and kept[0] == key:
        return kept[1]
    brake_guards, layer_guards = model.guard_counts
    modes = np.array([brake_guards, key[0], mode, layer_guards])
    model._kernel_modes = (key, modes)
    return modes


@jit
def rope_tension(t: float, x: np.ndarray, data) -> float:
    """Rope tension at ``(t, x)``: held, or the rope's interface model (at least 0), N.

    :meth:`WinchInputs.tension_at <wire_fmu.core.units.winch.base.WinchInputs.tension_at>`
    with the same operations in the same order.

    Parameters
    ----------
    t, x, data
        Time (s), state and kernel data, as :func:`rhs` takes them.
    """
    held = data[4]
    n = data[1].size
    stiffness, damping, rate = held[_ROPE_MODEL], held[_ROPE_MODEL + 1], held[_ROPE_MODEL + 2]
    tension = held[2]
    if stiffness == 0.0 and damping == 0.0 and rate == 0.0:
        return tension
    if stiffness != 0.0:
        payout = held[_PAYOUT_OFFSET] + held[4] * x[n - 1]
        tension = tension - stiffness * (payout - held[_ROPE_MODEL + 3])
    if damping != 0.0:
        tension = tension - damping * (held[4] * x[2 * n - 1] - held[_ROPE_MODEL + 4])
    if rate != 0.0:
        tension = tension + rate * (t - held[_ROPE_MODEL + 5])
    return tension if tension > 0.0 else 0.0


@jit
def _dynamics(t: float, x: np.ndarray, data):
    """Accelerations (rad/s^2) and the brake torque on the drum (N m) in the present mode."""
    acc = np.empty(data[1].size)
    return acc, _dynamics_into(acc, t, x, data)


@jit
def _dynamics_into(acc: np.ndarray, t: float, x: np.ndarray, data) -> float:
    """Accelerations into ``acc`` (rad/s^2; a derivative's rows, or scratch), and the brake
    torque on the drum (N m), in the present mode."""
    modes, inertia, stiffness, damping, held = data
    n = inertia.size
    forces = acc  # the torques, divided in place: no array made
    if n > 1:
        for i in range(n):
            total = 0.0
            for j in range(n):
                total -= stiffness[i, j] * x[j]
            for j in range(n):
                total -= damping[i, j] * x[n + j]
            forces[i] = total
    else:
        forces[0] = -damping[0, 0] * x[1]
    forces[0] += held[0] - held[1] * x[n]
    w = x[2 * n - 1]
    forces[n - 1] += rope_tension(t, x, data) * held[4] - 0.5 * held[6] * w * w
    drum_mass = inertia[n - 1] + (held[5] + held[6] * x[n - 1])  # with the rope on it
    brake = 0.0
    engaged, mode = modes[1] == 1, modes[2]
    if engaged and mode != 0:
        brake = -mode * (held[7] if mode > 0 else held[8])
        forces[n - 1] += brake
    drum_torque = forces[n - 1]
    for i in range(n - 1):
        acc[i] = forces[i] / inertia[i]
    acc[n - 1] = drum_torque / drum_mass
    if engaged and mode == 0:
        acc[n - 1] = 0.0
        brake = -drum_torque
    return brake


@jit
def rhs(t: float, x: np.ndarray, data) -> np.ndarray:
    """``[theta', omega', dissipated', external work']``.

    Parameters
    ----------
    t : float
        Time, s.
    x : numpy.ndarray
        State (see the module docstring).
    data : tuple
        See the module docstring.
    """
    out = np.empty_like(x)
    n = data[1].size
    brake = _dynamics_into(out[n : 2 * n], t, x, data)
    return _derivative_into(out, t, x, data, brake)


@jit
def _derivative_into(out: np.ndarray, t: float, x: np.ndarray, data, brake: float) -> np.ndarray:
    """:func:`rhs` into ``out``, whose accelerations' rows :func:`_dynamics_into` wrote, with
    the brake torque (N m) it gave at ``(t, x)``."""
    modes, inertia, _, damping, held = data
    n = inertia.size
    loss = 0.0
    for i in range(n):
        out[i] = x[n + i]
        row = 0.0
        for j in range(n):
            row += x[n + j] * damping[j, i]
        loss += row * x[n + i]
    if modes[1] == 1:
        if modes[2] != 0:
            loss -= brake * x[2 * n - 1]
        else:
            out[n - 1] = 0.0
    out[2 * n] = loss
    omega0 = x[n]
    rope = rope_tension(t, x, data)
    out[2 * n + 1] = (held[0] - held[1] * omega0) * omega0 + rope * held[4] * x[2 * n - 1]
    return out


@jit
def guards(t: float, x: np.ndarray, data) -> np.ndarray:
    """Brake stick/slip and engagement, then the layer's two edges (all fire downwards).

    Parameters
    ----------
    t, x, data
        Time (s), state and kernel data, as :func:`rhs` takes them.
    """
    modes = data[0]
    brake = 0.0
    if modes[0] == 2 and modes[1] == 1 and modes[2] == 0:  # the only guard that needs it
        brake = _dynamics(t, x, data)[1]
    return _guards_of(x, data, brake)


@jit
def rhs_guards(t: float, x: np.ndarray, data) -> tuple:
    """:func:`rhs` and :func:`guards` at ``(t, x)`` from one :func:`_dynamics`.

    Parameters
    ----------
    t, x, data
        Time (s), state and kernel data, as :func:`rhs` takes them.
    """
    out = np.empty_like(x)
    n = data[1].size
    brake = _dynamics_into(out[n : 2 * n], t, x, data)
    return _derivative_into(out, t, x, data, brake), _guards_of(x, data, brake)


@jit
def _guards_of(x: np.ndarray, data, brake: float) -> np.ndarray:
    """:func:`guards` at state ``x`` with the brake torque ``brake`` (N m) :func:`_dynamics`
    gives there (read only while the brake holds the drum)."""
    modes, inertia, _, _, held = data
    n = inertia.size
    out = np.empty(modes[0] + modes[3])
    i = 0
    if modes[0] == 2:
        if modes[1] == 1:
            if modes[2] == 0:
                against = held[7] if (-brake if brake != 0.0 else 1.0) > 0 else held[8]
                out[0] = against - abs(brake)
            else:
                out[0] = modes[2] * x[2 * n - 1]
            out[1] = held[3]
        else:
            out[0] = 1.0
            out[1] = -held[3]
        i = 2
    if modes[3] == 2:
        phi = x[n - 1]
        out[i] = phi - held[9]
        out[i + 1] = held[10] - phi
    return out


@jit
def summary(t: float, x: np.ndarray, data) -> np.ndarray:
    """What the outputs need beyond the state: brake torque (N m) and stored energy (J).

    Parameters
    ----------
    t : float
        Time, s (the rope model's tension acts on a held drum's brake torque).
    x : numpy.ndarray
        State (see the module docstring).
    data : tuple
        See the module docstring.
    """
    modes, inertia, stiffness, _, held = data
    n = inertia.size
    brake = _dynamics(t, x, data)[1] if modes[1] == 1 else 0.0
    kinetic = 0.0
    for i in range(n):
        mass = inertia[i] + (held[5] + held[6] * x[n - 1] if i == n - 1 else 0.0)
        kinetic += mass * x[n + i] * x[n + i]
    strain = 0.0
    if n > 1:
        for i in range(n):
            for j in range(n):
                strain += x[i] * stiffness[i, j] * x[j]
    out = np.empty(2)
    out[0] = brake
    out[1] = 0.5 * kinetic + 0.5 * strain
    return out


@jit
def outputs(t: float, x: np.ndarray, data, initial_energy: float) -> np.ndarray:
    """The values of :data:`OUTPUTS` at ``(t, x)``, in their units.

    What :meth:`WinchModel.report <wire_fmu.core.units.winch.drive.WinchModel.report>` and
    the unit's ledger make of the state, with the same operations in the same order.

    Parameters
    ----------
    t, x, data
        Time (s), state and kernel data, as :func:`rhs` takes them.
    initial_energy : float
        Stored energy at the start of the ledger, J.
    """
    modes, inertia, _, _, held = data
    n = inertia.size
    values = summary(t, x, data)
    brake, stored = values[0], values[1]
    phi, w, radius = x[n - 1], x[2 * n - 1], held[4]
    motor_speed = held[_MOTOR_COMMAND + 1] * x[n]
    slope = held[_MOTOR_COMMAND + 2]
    command = held[_MOTOR_COMMAND]
    dissipated, external = x[2 * n], x[2 * n + 1]
    out = np.empty(_OUTPUT_COUNT)
    out[0] = held[_PAYOUT_OFFSET] + radius * phi if held[_MOTOR_COMMAND + 3] else radius * phi
    out[1] = radius * w
    out[2] = w
    out[3] = phi
    out[4] = motor_speed
    out[5] = command if np.isnan(slope) else command - slope * motor_speed
    out[6] = brake + 0.0 if modes[1] == 1 else 0.0
    out[7] = held[7]
    out[8] = stored
    out[9] = dissipated
    out[10] = external
    out[11] = stored - initial_energy + dissipated - external
    return out


@jit
def project(x: np.ndarray, data) -> np.ndarray:
    """A held drum stays exactly where it stuck, at rest.

    Parameters
    ----------
    x : numpy.ndarray
        State, changed in place and returned.
    data : tuple
        See the module docstring.
    """
    modes, inertia, _, _, held = data
    n = inertia.size
    if modes[1] == 1 and modes[2] == 0:
        x[n - 1] = held[11]
        x[2 * n - 1] = 0.0
    return x


@jit
def advance(method, t0, t1, n, k, t, x, directions, tol, data):
    """:func:`~wire_fmu.core.framework.compiled_step.advance_to_event` over this kernel.

    Parameters
    ----------
    method, t0, t1, n, k, t, x, directions, tol, data
        As :func:`~wire_fmu.core.framework.compiled_step.advance_to_event` takes them.
    """
    return advance_to_event(
        rhs, guards, rhs_guards, project, method, t0, t1, n, k, t, x, directions, tol, data
    )


@jit
def quiet_step(
    method, t0, t1, n, tol, x, directions, data, check_stick, hold_angle, k, t, resume, energy
):
    """A whole communication step in one call, when the new inputs switch no brake mode.

    What :meth:`WinchModel.advance <wire_fmu.core.units.winch.drive.WinchModel.advance>`
    does once its inputs are set, in the same order and with the same arithmetic: the
    brake's mode kept (a held drum keeps its angle and rests), the loop of
    :func:`advance` to the end of the step or its first event, the :func:`outputs` at
    the end. It changes nothing it was given.

    With ``resume`` it is :func:`advance` from ``(k, t, x)`` instead, without the
    outputs (:func:`resume`, after an event Python switched): the one entry point
    Python calls for both, so that one compiled function is loaded from the cache,
    not two.

    Parameters
    ----------
    method, t0, t1, n, tol, directions
        As :func:`~wire_fmu.core.framework.compiled_step.advance_to_event` takes them.
    x : numpy.ndarray
        State at ``t0`` (at ``t`` with ``resume``).
    data : tuple
        See the module docstring, for the new inputs.
    check_stick : bool
        The brake holds the drum: leave the step to Python if it cannot hold any more.
    hold_angle : bool
        The brake is in the mode it keeps: a held drum stays at the angle it has now.
    k : int
        With ``resume``: the interval ``t`` lies in (else 0).
    t : float
        With ``resume``: the time the loop goes on from, s (else ``t0``).
    resume : bool
        Go on with :func:`advance` from ``(k, t, x)``, nothing else.
    energy : float
        Stored energy at the start of the ledger, J (for the output ``energy_balance``).

    Returns
    -------
    tuple
        The loop's ``(status, x, t, k, fired, steps, rhs_calls, h)``, the values of
        :data:`OUTPUTS` at the end (empty unless the status is ``STATUS_DONE``) and
        whether all of them are finite; the status is :data:`STATUS_PYTHON`, and nothing
        else meaningful, when Python must settle the brake first.
    """
    no_outputs = np.zeros(0)
    if resume:
        status, x, t, k, fired, steps, calls, h = advance_to_event(
            rhs, guards, rhs_guards, project, method, t0, t1, n, k, t, x, directions, tol, data
        )
        return status, x, t, k, fired, steps, calls, h, no_outputs, False
    if check_stick and guards(t0, x, data)[0] < 0.0:
        no_fire = np.zeros(directions.size, dtype=np.bool_)
        return STATUS_PYTHON, x, t0, 0, no_fire, 0, 0, 0.0, no_outputs, False
    x = x.copy()
    if hold_angle:
        modes, inertia, stiffness, damping, held = data
        held = held.copy()
        held[_HELD_ANGLE] = x[inertia.size - 1]
        data = (modes, inertia, stiffness, damping, held)
        x = project(x, data)
    status, x, t, k, fired, steps, calls, h = advance_to_event(
        rhs, guards, rhs_guards, project, method, t0, t1, n, 0, t0, x, directions, tol, data
    )
    if status != STATUS_DONE:
        return status, x, t, k, fired, steps, calls, h, no_outputs, False
    values = outputs(t, x, data, energy)
    finite = True
    for value in values:
        if not np.isfinite(value):
            finite = False
    return status, x, t, k, fired, steps, calls, h, values, finite


def resume(method, t0, t1, n, k, t, x, directions, tol, data) -> tuple:
    """:func:`advance` through :func:`quiet_step` (the entry point the solver calls).

    Parameters
    ----------
    method, t0, t1, n, k, t, x, directions, tol, data
        As :func:`~wire_fmu.core.framework.compiled_step.advance_to_event` takes them.
    """
    step = quiet_step(method, t0, t1, n, tol, x, directions, data, False, False, k, t, True, 0.0)
    return step[:8]
