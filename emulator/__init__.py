"""RoverLink firmware emulator: a Python reference model of the firmware and a vehicle plant."""
