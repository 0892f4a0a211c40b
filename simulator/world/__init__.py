"""The world around the vehicle: ground effect, wind and turbulence, payload, CG offset, sensors."""
