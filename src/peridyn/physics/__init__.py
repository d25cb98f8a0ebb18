"""Physics: material laws (``materials``), damage, contact, loads and time functions,
transducers and absorbing layers. Imports the discretisation and the kernels, never the
layers above (linear algebra, solvers, jobs)."""
