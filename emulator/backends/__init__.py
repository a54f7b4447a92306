"""Alternative backends for `roverlink emulate`: the compiled firmware in simavr (simavr.py)."""
