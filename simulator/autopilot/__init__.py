"""The autopilot: cascaded hover control and the excitation it injects."""
