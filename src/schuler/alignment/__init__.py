"""Alignment, north finding and calibration beyond the seeds."""
