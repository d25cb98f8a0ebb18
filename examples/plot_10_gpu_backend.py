"""
The GPU backend, or the CPU when there is none
==============================================

The bar pulse case (a steel bar, LPS, one 50 kHz cycle of axial displacement at one end) at
2.5 mm spacing, run with ``solver.backend: gpu`` when this machine can (an NVIDIA GPU and
``pip install "peridyn[gpu]"``), else on the CPU backend: the example says which, and why it
fell back. The sensors' axial displacement shows the pulse passing along the bar; either
backend gives the same curves (docs: GPU backend, "Same answers").
"""

from pathlib import Path

import matplotlib.pyplot as plt

from peridyn import load_case, run_case
from peridyn.io.results import Results
from peridyn.kernels.gpu import unavailable

reason = unavailable()
backend = "cpu" if reason else "gpu"
if reason:
    print(f"FELL BACK TO THE CPU: the GPU backend cannot run here ({reason})")
else:
    print("running on the GPU backend")

out = Path("peridyn-out/gallery/gpu_backend")
case = load_case(
    Path("../cases/bar_pulse.yaml"),
    ["discretization.spacing=2.5e-3", f"solver.backend={backend}", "output.snapshot_times=[]"],
)
summary = run_case(case, out, overwrite=True)
print(f"backend {backend}: {summary['steps']} steps, time loop {summary['step_seconds']:.2f} s")

# %%
steps, times, u = Results(out / "results.h5").series("sensor_u")
fig, ax = plt.subplots(figsize=(7, 3.5))
for k, name in enumerate(("x50", "x100", "x150")):
    ax.plot(times * 1e6, u[:, k, 0] * 1e9, label=f"sensor {name}")
ax.set_xlabel("t (us)")
ax.set_ylabel("axial displacement (nm)")
ax.set_title("bar pulse on the GPU backend" if backend == "gpu" else "bar pulse on the CPU (no GPU here)")
ax.legend()
fig.tight_layout()
fig.savefig(out / "bar_pulse_sensors.png", dpi=120)
