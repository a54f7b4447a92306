"""Alternative backends for `roverlink emulate`: the compiled firmware in simavr (`simavr/`), and on
an RP2040 in rp2040js (`rp2040/`: its harness so far); `pipe.py` is the process both step."""
