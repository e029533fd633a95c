"""What accuracy costs: each solver's error and time, and what the ODE tolerance does to a fit."""
