"""The block train: rope reeved over sheaves, forks and anchors (SPEC sections 3-6)."""
