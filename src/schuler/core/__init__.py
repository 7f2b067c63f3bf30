"""Shared numerical core: pure functions and types on SI floats and arrays.

Nothing here parses units, plots, prints or writes files.
"""
