"""Readers: every supported log and measurement file into a :class:`~flightlogs.flightlog.FlightLog` or its own container."""
