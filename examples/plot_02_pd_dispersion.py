"""
Peridynamic dispersion: influence function and horizon
======================================================

The dispersion study: the longitudinal and shear dispersion of a linear PMB and LPS medium (steel) with
the constant influence function, for two horizons. Nonlocality bends omega(k) below the
classical line omega = c k and gives a finite group velocity at the Nyquist wavenumber.
"""

from pathlib import Path

from peridyn.analysis.dispersion import Medium, dispersion_relation
from peridyn.plotting.dispersion import plot_dispersion

out = Path("peridyn-out/gallery/dispersion")
out.mkdir(parents=True, exist_ok=True)
steel = Medium(E=200e9, nu=0.25, density=7850.0)
spacing = 1e-3
relations = {
    f"{model.upper()}, horizon {m} h": dispersion_relation(model, steel, m * spacing, spacing)
    for model in ("pmb", "lps")
    for m in (3.015, 5.015)
}
plot_dispersion(relations, out / "dispersion.png", title="steel, constant influence")

# %%
# The phase velocity at the Nyquist wavenumber pi/h, as a fraction of the classical one:
for label, rel in relations.items():
    branch = rel.branches["longitudinal"]
    print(f"{label}: c(pi/h) / c0 = {branch.phase_velocity[-1] / rel.classical[0]:.3f}")
