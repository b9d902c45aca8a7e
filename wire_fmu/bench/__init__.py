"""Benchmarks: what the physics and the FMI layer cost (not run by the tests)."""
