"""Guided-wave structural health monitoring: damage indices of transducer paths against a
baseline (``indices``), time windows around the first arrivals (``windows``), damage images from
the path indices (``imaging``) and the geometry of paths and crack polylines (``paths``).
Plain NumPy/SciPy on arrays; docs/monitoring.md."""
