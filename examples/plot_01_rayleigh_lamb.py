"""
Rayleigh-Lamb dispersion of an aluminium plate
==============================================

The exact phase-velocity curves of the symmetric (S) and antisymmetric (A) Lamb modes of a
2 mm aluminium 6061-T6 plate (Patra et al.'s (2018) plate): the reference every Lamb-wave run is checked
against.
"""

import matplotlib.pyplot as plt

from peridyn.analysis.lamb import dispersion_curves, lamb_modes
from peridyn.plotting.lamb import plot_lamb_dispersion

E, nu, rho, thickness = 68.9e9, 0.33, 2700.0, 2e-3
curves = dispersion_curves(E, nu, rho, thickness, f_max=1.5e6)
fig, axes = plt.subplots(1, 2, figsize=(10, 4))
plot_lamb_dispersion(curves, ax=axes)

# %%
# At the paper's 150 kHz only S0 and A0 propagate:
for mode in lamb_modes(E, nu, rho, thickness, [150e3]):
    print(f"{mode.mode}: c = {mode.phase_velocity_m_s:7.1f} m/s, k = {mode.wavenumber_rad_m:6.1f} rad/m")
