"""The hydraulic cylinder unit's variables: parameters per component, the rod's input, outputs."""

from __future__ import annotations

from wire_fmu.core.framework.interface_model import interface_inputs
from wire_fmu.core.framework.solver_options import solver_parameters
from wire_fmu.core.framework.unit import input_, mode_change_time_output, output, parameter
from wire_fmu.core.units.hydraulics.interface import INTERFACE_INPUTS
from wire_fmu.core.units.hydraulics.model import HYDRAULICS_EFFECTS

__all__ = ["DEFAULT_ROD_FORCE", "variables"]

DEFAULT_ROD_FORCE = -4.0 * 356.0e3
"""Start value of ``rod.force``: an 80 kip rope tension through a 4:1 reeving, N."""

_FEEDTHROUGH = ("rod.force", *INTERFACE_INPUTS)
"""What the outputs that depend on the rod force depend on: the force and its interface
model (setting any of them starts the local model afresh at the present time)."""
_LINE = ("line_losses", "line_inertance")
_SEAL = ("seal_friction",)
_STOPS = ("end_stops",)


def _size(name: str, start: float, unit: str, description: str, **more):
    """A fixed physical parameter; not negative unless ``more`` says otherwise."""
    return parameter(name, start, unit, description, **({"min": 0.0} | more))


def _positive(name: str, start: float, unit: str, description: str, **more):
    """A fixed physical parameter that must be > 0."""
    return _size(name, start, unit, description, min_exclusive=True, **more)


def _cylinder_parameters():
    side = (
        "Oil-filled side: 'bore' (gas pushes the rod out) or 'annulus' (gas pulls it in); "
        "the other side is vented"
    )
    gravity = "Gravity along the extension direction (-9.81: vertical, rod extends up)"
    return (
        parameter("pressurised_side", "bore", "", side, type=str),
        _positive("bore_diameter", 0.356, "m", "Piston (bore) diameter"),
        _positive("rod_diameter", 0.229, "m", "Rod diameter, smaller than the bore"),
        _positive("stroke", 3.81, "m", "Stroke"),
        _positive("moving_mass", 3500.0, "kg", "Rod, piston and the sheave cluster it carries"),
        _size("chamber_dead_volume", 0.01, "m3", "Oil in the chamber at zero working length"),
        parameter("gravity_along_rod", -9.81, "m/s2", gravity),
        _size("ambient_pressure", 101325.0, "Pa", "Absolute pressure on the vented side and rod"),
    )


def _accumulator_parameters():
    exponent = "Exponent n of p V^n = const (1: isothermal, 1.4: adiabatic)"
    precharge = (
        "Absolute gas pressure with no oil in the accumulator. The start needs oil in it, "
        "but not more than it holds: p_start V_dead / V_gas < precharge <= p_start, with "
        "p_start the starting gas pressure (from rod.force with initial_equilibrium), "
        "V_gas = accumulator_volume + gas_bank_volume, V_dead = accumulator_dead_volume "
        "+ gas_bank_volume"
    )
    return (
        _positive("accumulator_volume", 0.6, "m3", "Accumulator volume (gas plus oil side)"),
        _size("gas_bank_volume", 3.0, "m3", "Volume of the air pressure vessels"),
        _size(
            "accumulator_dead_volume",
            0.01,
            "m3",
            "Gas left in a full accumulator, smaller than accumulator_volume",
        ),
        _positive("precharge_pressure", 13.5e6, "Pa", precharge),
        _size(
            "polytropic_exponent",
            1.4,
            "1",
            exponent,
            min=1.0,
            max=2.0,
            acts_with=("polytropic_gas",),
        ),
    )


_LOSSES = ("line_losses",)
_OIL = ("oil_compressibility",)


def _oil_parameters():
    minor = "Sum of minor-loss coefficients (valves, bends, entry, exit)"
    volume = "Oil volume whose compressibility is modelled (0: chamber at the start plus line)"
    cavitation = "Absolute chamber pressure at which the step is refused (cavitation)"
    return (
        _positive("line_length", 15.0, "m", "Length of the oil line", acts_with=_LINE + _OIL),
        _positive(
            "line_diameter", 0.1524, "m", "Inner diameter of the oil line", acts_with=_LINE + _OIL
        ),
        _positive("oil_density", 870.0, "kg/m3", "Oil density", acts_with=_LINE),
        _size("oil_viscosity", 0.028, "Pa.s", "Oil dynamic viscosity", acts_with=_LOSSES),
        _size(
            "line_friction_factor",
            0.025,
            "1",
            "Darcy friction factor, turbulent",
            acts_with=_LOSSES,
        ),
        _size("line_loss_coefficient", 5.0, "1", minor, acts_with=_LOSSES),
        _positive("bulk_modulus", 1.5e9, "Pa", "Effective oil bulk modulus", acts_with=_OIL),
        _size("oil_volume", 0.0, "m3", volume, acts_with=_OIL),
        _size("cavitation_pressure", 1.0e4, "Pa", cavitation),
    )


def _seal_and_stop_parameters():
    stribeck = "Stribeck velocity (0: no Stribeck decay)"
    cushion = "Length of the cushion zone at each end, less than half the stroke"
    restitution = "Coefficient of restitution at an end stop"
    return (
        _size("seal_static_friction", 25.0e3, "N", "Seal breakaway force", acts_with=_SEAL),
        _size(
            "seal_coulomb_friction",
            15.0e3,
            "N",
            "Seal sliding (Coulomb) force, at most the breakaway force",
            acts_with=_SEAL,
        ),
        _size("seal_viscous_friction", 2.0e4, "N.s/m", "Seal viscous coefficient", acts_with=_SEAL),
        _size("seal_stribeck_velocity", 0.01, "m/s", stribeck, acts_with=_SEAL),
        _size("cushion_length", 0.15, "m", cushion, acts_with=_STOPS),
        _size(
            "cushion_coefficient",
            1.0e5,
            "N.s2/m2",
            "Cushion force coefficient c in F = c v^2",
            acts_with=_STOPS,
        ),
        _positive("stop_stiffness", 1.0e9, "N/m", "End-stop contact stiffness", acts_with=_STOPS),
        _positive("stop_restitution", 0.3, "1", restitution, max=1.0, acts_with=_STOPS),
    )


def _physical_parameters():
    return (
        *_cylinder_parameters(),
        *_accumulator_parameters(),
        *_oil_parameters(),
        *_seal_and_stop_parameters(),
    )


def variables() -> tuple:
    """The unit's variables: effects and solver, physical parameters, start, inputs, outputs."""
    params = (
        parameter(
            "effects",
            "",
            "",
            "Effects to include, comma separated: " + ", ".join(HYDRAULICS_EFFECTS.names),
            type=str,
        ),
        *solver_parameters("ros2", 1e-3),
        *_physical_parameters(),
        parameter(
            "initial_equilibrium",
            True,
            "",
            "Start at rest in static equilibrium with the initial rod.force",
            type=bool,
        ),
        parameter("initial_position", 1.905, "m", "Initial extension from fully retracted"),
        parameter(
            "initial_velocity",
            0.0,
            "m/s",
            "Initial rod velocity (0 required with initial_equilibrium)",
        ),
        parameter(
            "initial_gas_pressure",
            14.75e6,
            "Pa",
            "Initial absolute gas pressure when initial_equilibrium is false",
            min=0.0,
            min_exclusive=True,
        ),
    )
    inputs = (
        input_(
            "rod.force",
            DEFAULT_ROD_FORCE,
            "N",
            "External force on the rod along extension (positive pushes it out); held over "
            "the step, or E0 of the interface model",
        ),
        *interface_inputs("rod", "translational", "rod.force", "rod.displacement", "rod.velocity"),
    )
    deps = _FEEDTHROUGH
    outputs = (
        output("rod.position", "m", "Rod extension from fully retracted"),
        output("rod.velocity", "m/s", "Rod velocity along extension"),
        output("rod.displacement", "m", "Rod extension since the start"),
        output("rod.acceleration", "m/s2", "Rod acceleration along extension", depends_on=deps),
        output("hydraulic_stiffness", "N/m", "Quasi-static spring rate of gas and oil at the rod"),
        output("chamber.pressure", "Pa", "Absolute pressure at the cylinder port", depends_on=deps),
        output(
            "hydraulic_force",
            "N",
            "Oil force on the rod along extension (gauge pressure times area)",
            depends_on=deps,
        ),
        output("gas.pressure", "Pa", "Absolute gas pressure"),
        output("gas.volume", "m3", "Gas volume (accumulator gas side plus gas bank)"),
        output("line.flow", "m3/s", "Oil flow from the accumulator to the cylinder"),
        output("accumulator.oil_volume", "m3", "Oil in the accumulator"),
        output("stroke_used", "1", "Rod extension as a fraction of the stroke"),
        output(
            "seal.friction_force", "N", "Seal friction on the rod along extension", depends_on=deps
        ),
        output("seal.stuck", "", "Whether the seals hold the rod (stick)", type=bool),
        output("end_stop.force", "N", "Cushion and stop force on the rod along extension"),
        output("end_stop.contact", "", "Whether the rod is on an end stop", type=bool),
        output("stored_energy", "J", "Kinetic, gas, oil, stop-pad and potential energy"),
        output("dissipated_energy", "J", "Energy dissipated since the start"),
        output("external_work", "J", "Work done on the unit through the rod since the start"),
        output(
            "energy_balance", "J", "Ledger residual: stored change + dissipated - external work"
        ),
        mode_change_time_output("stick/slip, end stops, cushions"),
        output(
            "mode_changes",
            "",
            "Number of mode events so far (stick/slip, end stops, cushions)",
            type=int,
        ),
    )
    return params + inputs + outputs
