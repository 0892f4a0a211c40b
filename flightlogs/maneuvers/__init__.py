"""Maneuvers: find the sweeps, doublets, 3211s, multisines and hover in a flight, and recover the excitation."""
