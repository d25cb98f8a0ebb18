"""Matplotlib figures (Agg backend, never a window): fields, signals, Lamb curves."""
