"""The co-simulation master: scenes, algorithms, recording (uses fmpy)."""
