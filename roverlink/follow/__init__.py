"""`roverlink follow`'s logic: the run loop, the emulated setup, the metrics and the PiCar baseline."""
