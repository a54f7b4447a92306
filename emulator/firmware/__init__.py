"""Python reference model of the RoverLink firmware core (docs/control.md), over a Board interface."""
