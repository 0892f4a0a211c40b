"""Flights: batches of nonlinear trials, linear-model hover flights and heave-only flights."""
