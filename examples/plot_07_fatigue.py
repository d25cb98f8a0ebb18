"""
Fatigue crack growth in a single-edge-notched specimen
======================================================

The remaining-life fatigue model (phases I and II) on a plane-stress SEN strip under cyclic
tension: bonds break one after the other as their remaining life runs out (each fatigue step
runs to the next bond break), and once the bonds ahead of the 1.75 mm notch have failed through
the damage threshold the crack tip moves. Shown: crack length against cycles over the first 400
fatigue steps on a 0.5 mm grid: the first 200 steps break bonds at the notch root without moving
the tip, then the crack grows in steps of one grid spacing to 4.75 mm after 2.4e8 cycles.
"""

from peridyn import load_case
from peridyn.data.examples import example_path
from peridyn.jobs.fatigue import run_fatigue_case

case = load_case(
    example_path("cases/sen_fatigue_2d.yaml"),
    ["discretization.spacing=0.5e-3", "fatigue.mapping=[{steps: 400, tau: 1.0e-6}]"],
)
summary = run_fatigue_case(case, "peridyn-out/gallery/fatigue", overwrite=True)

# %%
print({k: v for k, v in summary.items() if "cycle" in k or "crack" in k})
