"""Conditions, sweeps, compensator, discrepancy workflow and the ``gatetherm`` CLI."""
