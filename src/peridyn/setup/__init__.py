"""Setup: from a validated case to the objects of a run, before anything is run. The body,
bonds, model, loads, damage and contact (``build``), the storage of the bonds (``storage``),
the checks before allocation (the memory ``estimate``, the continuum ``stable_step``, the
time-stepping plan's ``run_checks``, the modal ``eigensolver``'s), the values of Peridigm's
named Exodus variables (``exodus_variables``) and Peridigm's time step (``peridigm_step``).
The jobs above take these objects and run them."""
