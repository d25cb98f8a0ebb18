"""A model's force on the GPU (``peridyn.kernels.gpu``): its bonds in the ELL layout on the device,
with the coefficients the model gives through its linearisation.

The materials are asked, never named (docs/architecture.md): the GPU force is the ordinary
state-based form of ``Model.linearisation()`` (``physics.materials.linearisation``),

    t_ij = weight_ij |xi| (P_i + P_j) + extension_ij (|Y| - |xi|),   f_i = sum_j t_ij Y / |Y|,

exact for the force kernels of PMB (no dilatation: ``k (1/|xi| - 1/|Y|) Y`` with
``k = extension |xi|``) and LPS. A material whose force is linear in u (``is_linear``) is refused.
Partial volumes, influence functions and surface corrections are in those coefficients (set up on
the host once, as for a CPU run); several blocks likewise.
"""

from __future__ import annotations

import numpy as np

from peridyn.errors import InputError
from peridyn.kernels.gpu import device, warp
from peridyn.kernels.gpu.ell import EllSlots
from peridyn.kernels.gpu.forces import (
    lps_dilatation_cf_kernel,
    lps_dilatation_kernel,
    lps_pair_force_cf_kernel,
    lps_pair_force_kernel,
    pmb_force_cf_kernel,
    pmb_force_kernel,
)
from peridyn.kernels.gpu.update import to_scalar_kernel
from peridyn.physics.materials.base import Model

#: Bytes per directed ELL slot: neighbour (int32) and intact (uint8), then the coefficients by
#: (dtype, dilatation): float64 bond vectors and lengths, float32 from the points.
SLOT_BYTES = 5
COEF_BYTES = {("float64", False): 40, ("float64", True): 48, ("float32", False): 4, ("float32", True): 8}
#: Per point: u, v, a, body force (float64), inverse density, damping, constraint flags, the
#: force and dilatation, pressure and their coefficients in the kernel dtype, and for float32 the
#: state's copy and the points.
POINT_BYTES = {"float64": 4 * 24 + 16 + 3 + 24 + 32, "float32": 4 * 24 + 16 + 3 + 12 + 16 + 12 + 12}
#: Share added for the boundary conditions' points and amplitudes and the counters.
SMALL_ARRAYS = 0.03
#: Per slot of bond breaking: the critical length (float64), plus the float64 bond vectors
#: where the float32 force does not keep them.
DAMAGE_BYTES = {"float64": 8, "float32": 32}


def device_bytes(model: Model, damage: bool) -> dict:
    """Estimated device memory of an explicit run, bytes: ``{"bonds", "points", "total"}``, from
    the ELL shape (k_max x n_points slots) of ``model``'s families, before anything is allocated."""
    n = model.body.n_points
    counts = np.diff(model.bonds.offsets)
    slots = int(counts.max(initial=0)) * n
    dtype = model.dtype.name
    per_slot = SLOT_BYTES + COEF_BYTES[(dtype, model.has_dilatation)] + (DAMAGE_BYTES[dtype] if damage else 0)
    bonds, points = slots * per_slot, n * POINT_BYTES[dtype]
    return {"bonds": bonds, "points": points, "total": int((1.0 + SMALL_ARRAYS) * (bonds + points))}


def check_fits(model: Model, damage: bool, name: str) -> dict:
    """:func:`device_bytes`, refused with the numbers (InputError) when above the free memory of
    the CUDA device ``name`` (Warp's CPU device is not checked)."""
    need = device_bytes(model, damage)
    wp = warp()
    dev = wp.get_device(name)
    if dev.is_cuda:
        free = int(dev.free_memory)
        if need["total"] > free:
            gib = 2.0**30
            raise InputError(
                f"the model does not fit on {dev.name}: it needs {need['total'] / gib:.2f} GiB "
                f"({need['bonds'] / gib:.2f} GiB for {model.bonds.n_bonds} bonds in the ELL layout, "
                f"{need['points'] / gib:.2f} GiB for {model.body.n_points} points), "
                f"{free / gib:.2f} GiB free: coarsen the grid or use --backend cpu"
            )
    return need


class DeviceForce:
    """The internal force of ``model`` on the Warp device ``name``.

    Attributes
    ----------
    slots : EllSlots
    f : Warp (n_points, 3) array of the model's dtype, N/m^3
        The force of the last :meth:`compute`.
    intact : Warp (k_max, n_points) uint8
        The device's intact mask (bonds broken there are read by the next force).
    xi : list of three Warp (k_max, n_points) float64 arrays, m
        The bonds' reference vectors (bond breaking reads them whatever the force's dtype).
    """

    def __init__(self, model: Model, name: str | None = None):
        if model.is_linear:
            raise InputError(
                f"material {model.name!r}: its force is linear in u, which the GPU backend does not "
                "compute yet: use --backend cpu"
            )
        self.wp = wp = warp()
        self.device = name or device()
        self.model = model
        b = model.bonds
        lin = model.linearisation()
        self.slots = s = EllSlots.of(b.offsets)
        self.n = n = model.body.n_points
        self.float32 = model.dtype == np.float32
        self.scalar = wp.float32 if self.float32 else wp.float64
        dt = model.dtype
        self.count = self._put(s.count, wp.int32)
        self.nbr = self._put(s.to_ell(b.neighbours, np.int32), wp.int32)
        self.intact = self._put(s.to_ell(b.intact, np.uint8), wp.uint8)
        self.f = wp.zeros((n, 3), dtype=self.scalar, device=self.device)
        self.dilatation = lin.has_dilatation
        self._xi = None
        if self.float32:
            self.x = self._put(np.ascontiguousarray(model.body.points, dtype=np.float32), wp.float32)
            self.u32 = wp.zeros((n, 3), dtype=wp.float32, device=self.device)
        else:
            self._upload_bond_vectors()  # the length form reads them
        if self.dilatation:
            self.w = self._bond(lin.weight.astype(dt))
            self.dev = self._bond(lin.extension.astype(dt))
            self.theta_coef = self._put(lin.theta_coef.astype(dt), self.scalar)
            self.p_coef = self._put(lin.p_coef.astype(dt), self.scalar)
            self.theta = wp.zeros(n, dtype=self.scalar, device=self.device)
            self.p = wp.zeros(n, dtype=self.scalar, device=self.device)
            if not self.float32:
                self.length = self._bond(b.length)
        else:
            self.k = self._bond((lin.extension * b.length).astype(dt))
            if not self.float32:
                self.inv_len = self._bond(1.0 / b.length)

    def _put(self, array, dtype):
        return self.wp.array(np.ascontiguousarray(array), dtype=dtype, device=self.device)

    def _bond(self, values, fill=0.0):
        """A per-bond (n_bonds,) array on the device in the ELL layout, in its own dtype."""
        dtype = self.wp.float32 if values.dtype == np.float32 else self.wp.float64
        return self._put(self.slots.to_ell(values, values.dtype, fill), dtype)

    def _upload_bond_vectors(self) -> None:
        vectors = self.model.bond_vectors_once()
        self._xi = [self._bond(np.ascontiguousarray(vectors[:, a])) for a in range(3)]

    @property
    def xi(self):
        """The bond vectors (three (k_max, n_points) float64 arrays, m), made on first use."""
        if self._xi is None:
            self._upload_bond_vectors()
        return self._xi

    def per_bond(self, values: np.ndarray, fill=0.0):
        """A float64 per-bond array (n_bonds,) on the device, ELL layout (``fill`` in the padding)."""
        return self._bond(np.asarray(values, dtype=np.float64), fill)

    def intact_host(self) -> np.ndarray:
        """(n_bonds,) bool: the device's intact mask in CSR order."""
        return self.slots.from_ell(self.intact.numpy()).astype(bool)

    def compute(self, u):
        """The force density at the device displacement ``u`` (Warp (n, 3) float64, m) into ``f``."""
        wp, n, dev, S = self.wp, self.n, self.device, self.scalar
        common = (self.count, self.nbr)
        if self.float32:
            wp.launch(to_scalar_kernel(S), dim=(n, 3), inputs=[u, self.u32], device=dev)
            state = (self.x, self.u32, *common)
            if self.dilatation:
                coefs = [self.theta_coef, self.p_coef, self.theta, self.p]
                wp.launch(
                    lps_dilatation_cf_kernel(S),
                    dim=n,
                    inputs=[*state, self.w, self.intact, *coefs],
                    device=dev,
                )
                inputs = [*state, self.w, self.dev, self.intact, self.p, self.f]
                wp.launch(lps_pair_force_cf_kernel(S), dim=n, inputs=inputs, device=dev)
            else:
                wp.launch(
                    pmb_force_cf_kernel(S), dim=n, inputs=[*state, self.k, self.intact, self.f], device=dev
                )
            return self.f
        state = (*self.xi, u, *common)
        if self.dilatation:
            coefs = [self.theta_coef, self.p_coef, self.theta, self.p]
            inputs = [*state, self.length, self.w, self.intact, *coefs]
            wp.launch(lps_dilatation_kernel(S), dim=n, inputs=inputs, device=dev)
            inputs = [*state, self.length, self.w, self.dev, self.intact, self.p, self.f]
            wp.launch(lps_pair_force_kernel(S), dim=n, inputs=inputs, device=dev)
        else:
            inputs = [*state, self.inv_len, self.k, self.intact, self.f]
            wp.launch(pmb_force_kernel(S), dim=n, inputs=inputs, device=dev)
        return self.f
