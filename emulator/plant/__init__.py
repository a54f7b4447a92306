"""Vehicle plant: motors, ESC, steering servo, encoders, turn-signal LEDs and the vehicle body."""
