"""Multi-mass and branched two-motor drives (paper 002)."""
