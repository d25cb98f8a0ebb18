"""
A Peridigm deck, run unchanged
==============================

Peridigm's ``WaveInBar.xml`` test deck (an Exodus hex mesh of a bar, 525 points, LPS "Elastic"
material, an initial velocity of -100 m/s on one end's node set, velocity Verlet with a fixed
step, output every 20 steps) run by peridyn as it is: the deck is translated to a peridyn case
(``peridyn convert`` prints it) and its Exodus output, ``WaveInBar.e``, carries Peridigm's
variables under Peridigm's names. The displacement along the bar at the last output (the mean
over each cross-section) is drawn over Peridigm's own result (its gold file); the deck's
tolerance on it is 5e-14 m.
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from peridyn.data.examples import example_path
from peridyn.io.exodus import read_exodus
from peridyn.io.peridigm_case import load_deck
from peridyn.jobs.run import run_case

data = example_path("gallery/peridigm/WaveInBar.xml").parent
out = Path("peridyn-out/gallery/peridigm")
case = load_deck(data / "WaveInBar.xml")
run_case(case, out, overwrite=True)

mine, gold = read_exodus(out / "WaveInBar.e"), read_exodus(data / "WaveInBar_gold.e")
x, sections = np.unique(np.round(mine.coordinates[:, 0], 9), return_inverse=True)
ux, gold_ux = mine.nodal_variables["DisplacementX"][-1], gold.nodal_variables["DisplacementX"][-1]
print(f"{len(mine.times)} outputs, last at t = {mine.times[-1]:.6g} s (Peridigm: {gold.times[-1]:.6g} s)")
print(f"largest difference in DisplacementX: {np.max(np.abs(ux - gold_ux)):.2e} m")


def section_mean(values):
    """Mean of a nodal variable over each cross-section of the bar."""
    return np.bincount(sections, values) / np.bincount(sections)


# %%
fig, ax = plt.subplots(figsize=(7, 3.5))
ax.plot(x * 1e3, section_mean(gold_ux) * 1e6, "k-", lw=3, alpha=0.35, label="Peridigm (gold file)")
ax.plot(x * 1e3, section_mean(ux) * 1e6, "C0o", ms=4, label="peridyn run WaveInBar.xml")
ax.set_xlabel("x (mm)")
ax.set_ylabel("mean displacement x (um)")
ax.set_title(f"WaveInBar at t = {mine.times[-1] * 1e6:.2f} us")
ax.legend()
fig.tight_layout()
fig.savefig(out / "wave_in_bar.png", dpi=120)
