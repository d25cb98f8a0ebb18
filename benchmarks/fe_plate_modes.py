"""Continuum reference: free-free modes of a box by 27-node hexahedra (scikit-fem).

Not part of peridyn (scikit-fem is not a dependency): it gives the FE frequencies that
``docs/user-guide.md`` compares ``peridyn study`` extrapolations with. Checked against
issue 9's converged FE values for the 100 x 50 x 8 mm PMMA plate (VALIDATION.md V4).

    pip install --target /tmp/skfem scikit-fem
    PYTHONPATH=src:/tmp/skfem python benchmarks/fe_plate_modes.py 0.1,0.05,0.008 20,10,2

Arguments: box size (m) and elements per axis. Prints the six lowest elastic frequencies
(Hz, the first six of twelve being rigid), each with its type from peridyn's mode
classifier (``analysis.modes``) applied to the displacements at the element nodes (a
regular grid of half-element spacing).
"""

import sys
import time

import numpy as np
from scipy.sparse.linalg import eigsh
from skfem import Basis, BilinearForm, ElementHex2, ElementVector, MeshHex, asm
from skfem.helpers import dot
from skfem.models.elasticity import lame_parameters, linear_elasticity

#: PMMA of VALIDATION.md V4: Pa, -, kg/m^3.
E, NU, RHO = 5.35e9, 0.33, 1200.0
#: Shift (rad^2/s^2) below zero so that K - sigma M is positive definite with rigid modes.
SHIFT = -1.0e5


@BilinearForm
def mass(u, v, w):
    return RHO * dot(u, v)


def elastic_modes(size, cells, n_modes=12) -> tuple[np.ndarray, list, int]:
    """The n_modes lowest frequencies (Hz) of a free box of ``size`` (m) on ``cells`` elements,
    their types (peridyn's classifier) and the number of unknowns."""
    from peridyn.analysis.modes import classify_modes

    axes = [np.linspace(0.0, s, n + 1) for s, n in zip(size, cells, strict=True)]
    basis = Basis(MeshHex.init_tensor(*axes), ElementVector(ElementHex2()), intorder=5)
    stiffness = asm(linear_elasticity(*lame_parameters(E, NU)), basis)
    values, vectors = eigsh(stiffness, k=n_modes, M=asm(mass, basis), sigma=SHIFT, which="LM")
    order = np.argsort(values)
    components = basis.split_indices()  # x, y, z unknowns, interleaved per node
    nodes = basis.doflocs[:, components[0]].T
    shapes = np.stack([vectors[c][:, order].T for c in components], axis=2)
    rigid = np.arange(n_modes) < 6
    types = classify_modes(nodes, shapes, np.ones(len(nodes)), rigid)
    return np.sqrt(np.abs(values[order])) / (2 * np.pi), types, stiffness.shape[0]


if __name__ == "__main__":
    size = [float(x) for x in sys.argv[1].split(",")]
    cells = [int(x) for x in sys.argv[2].split(",")]
    start = time.perf_counter()
    freqs, types, dofs = elastic_modes(size, cells)
    print(f"{dofs} dofs, {time.perf_counter() - start:.1f} s: elastic modes (Hz)")
    for f, t in zip(freqs[6:], types[6:], strict=True):
        print(f"  {f:9.1f}  {t}")
