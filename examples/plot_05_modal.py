"""
Free vibration of a PMMA plate
==============================

Freimanis's (2019) 100 x 50 x 8 mm PMMA plate, free-free, at a 4 mm spacing: the stiffness and mass of
the peridynamic model, a shift-invert eigensolve, six rigid modes and the first elastic ones,
classified by type (bending, torsion, ...).
"""

from peridyn import load_case, run_case
from peridyn.data.examples import example_path

case = load_case(example_path("cases/pmma_plate.yaml"), ["discretization.spacing=4e-3"])
summary = run_case(case, "peridyn-out/gallery/modal", overwrite=True)

# %%
for mode in summary["modes"]:
    print(f"{mode['label']:>12}: {mode['frequency_hz']:9.1f} Hz")
