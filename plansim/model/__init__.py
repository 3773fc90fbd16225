"""The world being simulated: calibration parameters, sensor effects, noise, turntable, laboratory."""
