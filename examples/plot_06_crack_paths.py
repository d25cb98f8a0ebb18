"""
A crack grows across a stretched plate
======================================

Martowicz: a 10 x 4 mm aluminium plate with a short central crack, pulled at both ends. Bonds
break above the critical bond stress and the crack runs across the plate. Shown: the damage
map with the crack path found from it.
"""

from peridyn import load_case, run_case
from peridyn.data.examples import example_path

case = load_case(example_path("cases/plate2d_stretch.yaml"))
summary = run_case(case, "peridyn-out/gallery/crack_paths", overwrite=True)

# %%
print("broken bonds:", summary["broken_bonds"])
for path in summary["crack_paths"]:
    print(path)
