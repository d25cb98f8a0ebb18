"""Discretisation: the body (points, volumes, node sets), grids, bonds (families, influence
functions, partial volumes, pre-cracks) and the state of the points. Imports only the kernels
and ``peridyn.errors``."""
