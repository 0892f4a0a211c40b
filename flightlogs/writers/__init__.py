"""Writers: valid PX4 ULog and ArduPilot DataFlash files from numpy columns, and atomic output files."""
