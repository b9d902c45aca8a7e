"""The hydraulic cylinder unit's variables: parameters per component, the rod's input, outputs."""

from __future__ import annotations

from wire_fmu.core.framework.solver_options import solver_parameters
from wire_fmu.core.framework.unit import input_, mode_change_time_output, output, parameter
from wire_fmu.core.units.hydraulics.model import HYDRAULICS_EFFECTS

__all__ = ["DEFAULT_ROD_FORCE", "variables"]

DEFAULT_ROD_FORCE = -4.0 * 356.0e3
"""Start value of ``rod.force``: an 80 kip rope tension through a 4:1 reeving, N."""

_FEEDTHROUGH = ("rod.force",)


def _size(name: str, start: float, unit: str, description: str, **limits: float):
    """A fixed physical parameter; not negative unless ``limits`` say otherwise."""
    return parameter(name, start, unit, description, **({"min": 0.0} | limits))


def _cylinder_parameters():
    side = (
        "Oil-filled side: 'bore' (gas pushes the rod out) or 'annulus' (gas pulls it in); "
        "the other side is vented"
    )
    gravity = "Gravity along the extension direction (-9.81: vertical, rod extends up)"
    return (
        parameter("pressurised_side", "bore", "", side, type=str),
        _size("bore_diameter", 0.356, "m", "Piston (bore) diameter"),
        _size("rod_diameter", 0.229, "m", "Rod diameter"),
        _size("stroke", 3.81, "m", "Stroke"),
        _size("moving_mass", 3500.0, "kg", "Rod, piston and the sheave cluster it carries"),
        _size("chamber_dead_volume", 0.01, "m3", "Oil in the chamber at zero working length"),
        parameter("gravity_along_rod", -9.81, "m/s2", gravity),
        _size("ambient_pressure", 101325.0, "Pa", "Absolute pressure on the vented side and rod"),
    )


def _accumulator_parameters():
    exponent = "Exponent n of p V^n = const with effect polytropic_gas (1.4: adiabatic)"
    return (
        _size("accumulator_volume", 0.6, "m3", "Accumulator volume (gas plus oil side)"),
        _size("gas_bank_volume", 3.0, "m3", "Volume of the air pressure vessels"),
        _size("accumulator_dead_volume", 0.01, "m3", "Gas left in a full accumulator"),
        _size("precharge_pressure", 13.5e6, "Pa", "Absolute gas pressure with no oil in it"),
        _size("polytropic_exponent", 1.4, "1", exponent, min=1.0, max=2.0),
    )


def _oil_parameters():
    minor = "Sum of minor-loss coefficients (valves, bends, entry, exit)"
    volume = "Oil volume whose compressibility is modelled (0: chamber at the start plus line)"
    cavitation = "Absolute chamber pressure at which the step is refused (cavitation)"
    return (
        _size("line_length", 15.0, "m", "Length of the oil line"),
        _size("line_diameter", 0.1524, "m", "Inner diameter of the oil line"),
        _size("oil_density", 870.0, "kg/m3", "Oil density"),
        _size("oil_viscosity", 0.028, "Pa.s", "Oil dynamic viscosity"),
        _size("line_friction_factor", 0.025, "1", "Darcy friction factor, turbulent"),
        _size("line_loss_coefficient", 5.0, "1", minor),
        _size("bulk_modulus", 1.5e9, "Pa", "Effective oil bulk modulus"),
        _size("oil_volume", 0.0, "m3", volume),
        _size("cavitation_pressure", 1.0e4, "Pa", cavitation),
    )


def _seal_and_stop_parameters():
    return (
        _size("seal_static_friction", 25.0e3, "N", "Seal breakaway force"),
        _size("seal_coulomb_friction", 15.0e3, "N", "Seal sliding (Coulomb) force"),
        _size("seal_viscous_friction", 2.0e4, "N.s/m", "Seal viscous coefficient"),
        _size("seal_stribeck_velocity", 0.01, "m/s", "Stribeck velocity (0: no Stribeck decay)"),
        _size("cushion_length", 0.15, "m", "Length of the cushion zone at each end"),
        _size("cushion_coefficient", 1.0e5, "N.s2/m2", "Cushion force coefficient c in F = c v^2"),
        _size("stop_stiffness", 1.0e9, "N/m", "End-stop contact stiffness"),
        _size("stop_restitution", 0.3, "1", "Coefficient of restitution at an end stop", max=1.0),
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
        ),
    )
    inputs = (
        input_(
            "rod.force",
            DEFAULT_ROD_FORCE,
            "N",
            "External force on the rod along extension (positive pushes it out)",
        ),
    )
    deps = _FEEDTHROUGH
    outputs = (
        output("rod.position", "m", "Rod extension from fully retracted"),
        output("rod.velocity", "m/s", "Rod velocity along extension"),
        output("rod.displacement", "m", "Rod extension since the start"),
        output("rod.acceleration", "m/s2", "Rod acceleration along extension", depends_on=deps),
        output("rod.stiffness", "N/m", "Quasi-static spring rate of gas and oil at the rod"),
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
