"""flight-sysid."""
