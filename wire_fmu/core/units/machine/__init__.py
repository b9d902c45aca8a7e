"""The machine unit in steady motion, with paper 004's energy-form integrator."""
