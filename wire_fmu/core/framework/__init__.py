"""What every unit is built on: the unit base class, hybrid integration, effects, solvers."""
