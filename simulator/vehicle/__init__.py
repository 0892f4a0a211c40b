"""The vehicle: rigid body, rotors, mixer, motors and battery; presets; trim and linearisation."""
