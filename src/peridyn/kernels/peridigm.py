"""The LPS force in Peridigm's order of operations (``solver.arithmetic: peridigm``).

Peridigm's "Elastic" material (``computeDilatation`` and ``computeInternalForceLinearElastic``
of its ``material_utilities.cxx`` and ``elastic.cxx``) works from the deformed positions
y = x + u, not from the displacements: each bond's deformed vector is ``y_j - y_i``, its
reference length ``sqrt(dx*dx + dy*dy + dz*dz)`` of ``x_j - x_i``, and, point by point in
the order of the families,

    theta_i += 3 omega (1 - d) |xi| e V_j / m_i             (e = |Y| - |xi|, d the bond damage)
    t = (1 - d) (omega theta_i p_i |xi| + (1 - d) omega alpha_i e)
    f_i += (t Y_a / |Y|) V_j,    f_j -= (t Y_a / |Y|) V_i   (a = x, y, z),

with p_i = 3 K / m_i - alpha_i / 3 and alpha_i = 15 mu / m_i. The rounding of y (of the size
of the coordinates) then enters the extension as it does in Peridigm: where a deck's tolerance
asks for Peridigm's last bits (1e-9 N of 1e8 N forces), only this order meets it
(docs/peridigm.md, Rounding). Serial, compiled without fast-math (every operation rounded as
written, in the written order): the pair force adds to both ends of a bond, as Peridigm does.
"""

import numba
import numpy as np


@numba.njit(cache=True)
def peridigm_lps_force(x, y, offsets, nbr, volume, influence, intact, m, alpha, p_coef, theta, f):
    """Dilatation ``theta`` (OUT, (n,)) and force density ``f`` (OUT, (n, 3), N/m^3) of the
    module docstring.

    ``x``, ``y`` (n, 3) float64 reference and deformed positions, m; ``volume`` (n,) the
    points' volumes, m^3; ``influence`` (n_bonds,) omega; ``intact`` (n_bonds,) bool (a broken
    bond has d = 1); ``m`` (n,) weighted volumes, m^5; ``alpha`` (n,) Pa/m^5; ``p_coef`` (n,)
    Pa/m^5.
    """
    n = x.shape[0]
    for i in range(n):
        acc = 0.0
        for k in range(offsets[i], offsets[i + 1]):
            j = nbr[k]
            dx = x[j, 0] - x[i, 0]
            dy = x[j, 1] - x[i, 1]
            dz = x[j, 2] - x[i, 2]
            zeta_squared = dx * dx + dy * dy + dz * dz
            y0 = y[j, 0] - y[i, 0]
            y1 = y[j, 1] - y[i, 1]
            y2 = y[j, 2] - y[i, 2]
            dY = y0 * y0 + y1 * y1 + y2 * y2
            zeta = np.sqrt(zeta_squared)
            e = np.sqrt(dY) - zeta
            damage = 0.0 if intact[k] else 1.0
            acc += 3.0 * influence[k] * (1.0 - damage) * zeta * e * volume[j] / m[i]
        theta[i] = acc
    for i in range(n):
        f[i, 0] = 0.0
        f[i, 1] = 0.0
        f[i, 2] = 0.0
    for i in range(n):
        a = alpha[i]
        vi = volume[i]
        for k in range(offsets[i], offsets[i + 1]):
            j = nbr[k]
            dx = x[j, 0] - x[i, 0]
            dy = x[j, 1] - x[i, 1]
            dz = x[j, 2] - x[i, 2]
            zeta = np.sqrt(dx * dx + dy * dy + dz * dz)
            y0 = y[j, 0] - y[i, 0]
            y1 = y[j, 1] - y[i, 1]
            y2 = y[j, 2] - y[i, 2]
            dY = np.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            if not intact[k]:
                continue  # Peridigm's (1 - d) = 0 times the rest: no force (nor its NaN at |Y| = 0)
            omega = influence[k]
            c1 = omega * theta[i] * p_coef[i]
            t = c1 * zeta + omega * a * (dY - zeta)  # (1 - d) = 1: products by 1, exact
            f0 = t * y0 / dY
            f1 = t * y1 / dY
            f2 = t * y2 / dY
            vj = volume[j]
            f[i, 0] += f0 * vj
            f[i, 1] += f1 * vj
            f[i, 2] += f2 * vj
            f[j, 0] -= f0 * vi
            f[j, 1] -= f1 * vi
            f[j, 2] -= f2 * vi
    return theta, f
