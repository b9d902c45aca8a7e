"""Physics core: components, units and their integrators (no FMI here)."""
