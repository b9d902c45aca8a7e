"""The scissor jack of paper 001: screw-nut connection, self-locking."""
