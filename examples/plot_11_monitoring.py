"""
Monitoring a growing fatigue crack with guided waves
====================================================

A 40 x 40 x 2 mm aluminium plate with a notched hole is cycled in tension-tension until a crack
grows from the notch (a plane-stress fatigue model); at 0 cycles and after each millimetre of
growth until the crack is 2.5 mm long, three PZTs fire 250 kHz tone bursts in turn on the 3D
plate with the fatigue model's broken bonds broken through its thickness. The path that the
crack crosses (t0-t1) shows a damage index that rises with the crack length; the RAPID image
concentrates on it. The small copy of ``cases/monitoring/monitor_notched_hole.yaml``
(docs/monitoring.md). Each run has one numba thread (``threads=1``): runs of 4 704 points gain
little from two, and on a machine busy with other work two threads wait on each other at every
step.
"""

import matplotlib.image as mpimg
import matplotlib.pyplot as plt

from peridyn import run_monitor
from peridyn.data.examples import example_path

summary = run_monitor(
    example_path("cases/monitoring/monitor_small.yaml"),
    "peridyn-out/gallery/monitoring",
    overrides=["check_transfer=false"],
    overwrite=True,
    threads=1,
)
print({k: v for k, v in summary["monitoring"].items() if k != "noise_free"})

# %%
# The correlation index (1 - Pearson's rho against the baseline) of each path against cycles and
# crack length, and the RAPID image at each interrogation with the crack (green) and the peak (+).
for name in ("correlation_index.png", "images.png"):
    fig, ax = plt.subplots(figsize=(10, 4))
    ax.imshow(mpimg.imread(f"peridyn-out/gallery/monitoring/{name}"))
    ax.set_axis_off()
