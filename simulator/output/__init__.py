"""Output: a simulated flight written as ArduPilot DataFlash or PX4 ULog, anemometer CSV and truth JSON."""
