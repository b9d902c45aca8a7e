"""The hydraulic cylinder with gas accumulator (riser tensioner, heave compensator)."""
