"""One folder per unit type: ``model.py`` (the physics) and ``unit.py`` (the co-simulation unit)."""
