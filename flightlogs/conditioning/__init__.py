"""Conditioning: wind alignment, resampling onto one time base, frames and trim, for identification."""
