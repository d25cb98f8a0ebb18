"""
Lamb waves from a PZT, and their f-k map
========================================

Patra et al.'s (2018) plate (300 x 200 x 2 mm, 3 layers, 125 250 points): a surface PZT driven by a
3.5-cycle 150 kHz tone burst launches S0 and A0. The run writes its sensor signals, a
space-time B-scan along the line through the PZT, and the frequency-wavenumber map of that
line with the Rayleigh-Lamb curves over it.
"""

from peridyn import load_case, run_case
from peridyn.data.examples import example_path

case = load_case(
    example_path("cases/lamb_plate.yaml"),
    ["output.snapshot_times=[]", "analysis.kxky=null"],
)
summary = run_case(case, "peridyn-out/gallery/lamb_plate", overwrite=True)

# %%
# The f-k peaks against theory (rad/m) at 150 kHz:
print("measured:", summary["fk_peaks_rad_m"])
print("theory:  ", summary["fk_theory_rad_m"])
