"""Campaigns: scenario files, the built-in scenarios and the demo flight, flown and written to disk."""
