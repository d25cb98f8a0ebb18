"""
Bloch waves of the discrete plate
=================================

The exact dispersion of the discretised plate of Patra et al. (2018) (3 layers through its 2 mm thickness,
1.2 mm in-plane spacing, LPS with the shear correction): the lowest symmetric, antisymmetric
and shear-horizontal branches of the periodic point lattice, against Rayleigh-Lamb theory
(dashed). Where they part is where the simulation cannot follow the plate.
"""

from pathlib import Path

from peridyn.analysis.bloch import BlochLattice
from peridyn.analysis.bloch_study import predict
from peridyn.plotting.bloch import plot_bloch

out = Path("peridyn-out/gallery/bloch")
out.mkdir(parents=True, exist_ok=True)
plate = BlochLattice(
    spacing=1.2e-3,
    horizon=3.015 * 1.2e-3,
    model="lps",
    E=68.9e9,
    nu=0.33,
    density=2700.0,
    kind="plate",
    thickness=2e-3,
    layers=3,
    layer_placement="surface",
    partial_volumes=False,
    surface_correction="shear-factor",
)
plot_bloch(plate, out / "bloch.png", frequencies=[150e3], f_max=400e3)

# %%
# The wavenumbers of the discrete plate against theory at the paper's 150 kHz:
for row in predict(plate, [150e3]):
    print(row)
