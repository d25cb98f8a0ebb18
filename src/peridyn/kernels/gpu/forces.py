"""Force kernels of the GPU backend (Warp), one thread a point over the ELL layout
(``peridyn.kernels.gpu``). Each ``*_kernel(scalar)`` returns the Warp kernel for ``scalar``
(``wp.float64`` or ``wp.float32``), compiled on its first launch and cached by Warp on disk.

They compute the forms of the numba kernels (``peridyn.kernels.pmb``, ``peridyn.kernels.lps``):

- float64, "length form" from the stored bond vectors ``xi0, xi1, xi2`` (k_max, n) and lengths:
  PMB ``f_i = sum_j k (1/|xi| - 1/|Y|) Y``; LPS dilatation
  ``theta_i = theta_coef_i sum_j w |xi| (|Y| - |xi|)`` and pair force
  ``f_i = sum_j [w |xi| (P_i + P_j) + dev (|Y| - |xi|)] Y / |Y|``, ``P = p_coef theta``;
- float32, "cancellation-free form" from the points ``x`` (n, 3): ``|Y| - |xi| =
  du . (Y + xi) / (|Y| + |xi|)``, ``du = u_j - u_i``.

``Y = xi + (u_j - u_i)`` (m), forces in N/m^3, broken bonds (``intact`` 0) add nothing.
"""

import functools

from peridyn.kernels.gpu import warp


@functools.cache
def pmb_force_kernel(scalar):
    """PMB force, length form: ``f`` (OUT, (n, 3)) from ``u`` (n, 3), the bond vectors, ``inv_len``
    = 1/|xi| and the bond stiffness ``k`` (k_max, n), N/m^4 (``kernels.pmb.pmb_force``)."""
    wp = warp()
    A2 = wp.array2d(dtype=scalar)

    @wp.kernel(module="unique")
    def pmb_force(
        xi0: A2,
        xi1: A2,
        xi2: A2,
        u: A2,
        count: wp.array(dtype=wp.int32),
        nbr: wp.array2d(dtype=wp.int32),
        inv_len: A2,
        k: A2,
        intact: wp.array2d(dtype=wp.uint8),
        f: A2,
    ):
        i = wp.tid()
        ui0 = u[i, 0]
        ui1 = u[i, 1]
        ui2 = u[i, 2]
        f0 = scalar(0.0)
        f1 = scalar(0.0)
        f2 = scalar(0.0)
        for q in range(count[i]):
            if intact[q, i] != wp.uint8(0):
                j = nbr[q, i]
                y0 = xi0[q, i] + (u[j, 0] - ui0)
                y1 = xi1[q, i] + (u[j, 1] - ui1)
                y2 = xi2[q, i] + (u[j, 2] - ui2)
                s = k[q, i] * (inv_len[q, i] - scalar(1.0) / wp.sqrt(y0 * y0 + y1 * y1 + y2 * y2))
                f0 += s * y0
                f1 += s * y1
                f2 += s * y2
        f[i, 0] = f0
        f[i, 1] = f1
        f[i, 2] = f2

    return pmb_force


@functools.cache
def pmb_force_cf_kernel(scalar):
    """PMB force, cancellation-free form from the points ``x`` (n, 3) (``kernels.pmb.pmb_force_cf``)."""
    wp = warp()
    A2 = wp.array2d(dtype=scalar)

    @wp.kernel(module="unique")
    def pmb_force_cf(
        x: A2,
        u: A2,
        count: wp.array(dtype=wp.int32),
        nbr: wp.array2d(dtype=wp.int32),
        k: A2,
        intact: wp.array2d(dtype=wp.uint8),
        f: A2,
    ):
        i = wp.tid()
        f0 = scalar(0.0)
        f1 = scalar(0.0)
        f2 = scalar(0.0)
        for q in range(count[i]):
            if intact[q, i] != wp.uint8(0):
                j = nbr[q, i]
                d0 = x[j, 0] - x[i, 0]
                d1 = x[j, 1] - x[i, 1]
                d2 = x[j, 2] - x[i, 2]
                e0 = u[j, 0] - u[i, 0]
                e1 = u[j, 1] - u[i, 1]
                e2 = u[j, 2] - u[i, 2]
                y0 = d0 + e0
                y1 = d1 + e1
                y2 = d2 + e2
                r = wp.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
                length = wp.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
                ext2 = e0 * (y0 + d0) + e1 * (y1 + d1) + e2 * (y2 + d2)
                s = k[q, i] * ext2 / (r * length * (r + length))
                f0 += s * y0
                f1 += s * y1
                f2 += s * y2
        f[i, 0] = f0
        f[i, 1] = f1
        f[i, 2] = f2

    return pmb_force_cf


@functools.cache
def lps_dilatation_kernel(scalar):
    """LPS dilatation, length form: ``theta`` and ``p = p_coef theta`` (OUT, (n,)) from the bond
    vectors, ``length`` |xi| and the influence weights ``w`` (k_max, n), m^3
    (``kernels.lps.lps_dilatation``)."""
    wp = warp()
    A1 = wp.array(dtype=scalar)
    A2 = wp.array2d(dtype=scalar)

    @wp.kernel(module="unique")
    def lps_dilatation(
        xi0: A2,
        xi1: A2,
        xi2: A2,
        u: A2,
        count: wp.array(dtype=wp.int32),
        nbr: wp.array2d(dtype=wp.int32),
        length: A2,
        w: A2,
        intact: wp.array2d(dtype=wp.uint8),
        theta_coef: A1,
        p_coef: A1,
        theta: A1,
        p: A1,
    ):
        i = wp.tid()
        ui0 = u[i, 0]
        ui1 = u[i, 1]
        ui2 = u[i, 2]
        acc = scalar(0.0)
        for q in range(count[i]):
            if intact[q, i] != wp.uint8(0):
                j = nbr[q, i]
                y0 = xi0[q, i] + (u[j, 0] - ui0)
                y1 = xi1[q, i] + (u[j, 1] - ui1)
                y2 = xi2[q, i] + (u[j, 2] - ui2)
                r = wp.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
                L = length[q, i]
                acc += w[q, i] * L * (r - L)
        th = theta_coef[i] * acc
        theta[i] = th
        p[i] = th * p_coef[i]

    return lps_dilatation


@functools.cache
def lps_pair_force_kernel(scalar):
    """LPS pair force, length form: ``f`` (OUT, (n, 3)) from ``p`` (n,) and the per-bond ``length``,
    ``w`` and deviatoric stiffness ``dev`` (k_max, n) (``kernels.lps.lps_pair_force``)."""
    wp = warp()
    A1 = wp.array(dtype=scalar)
    A2 = wp.array2d(dtype=scalar)

    @wp.kernel(module="unique")
    def lps_pair_force(
        xi0: A2,
        xi1: A2,
        xi2: A2,
        u: A2,
        count: wp.array(dtype=wp.int32),
        nbr: wp.array2d(dtype=wp.int32),
        length: A2,
        w: A2,
        dev: A2,
        intact: wp.array2d(dtype=wp.uint8),
        p: A1,
        f: A2,
    ):
        i = wp.tid()
        ui0 = u[i, 0]
        ui1 = u[i, 1]
        ui2 = u[i, 2]
        pi = p[i]
        f0 = scalar(0.0)
        f1 = scalar(0.0)
        f2 = scalar(0.0)
        for q in range(count[i]):
            if intact[q, i] != wp.uint8(0):
                j = nbr[q, i]
                y0 = xi0[q, i] + (u[j, 0] - ui0)
                y1 = xi1[q, i] + (u[j, 1] - ui1)
                y2 = xi2[q, i] + (u[j, 2] - ui2)
                r = wp.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
                L = length[q, i]
                t = (w[q, i] * L * (pi + p[j]) + dev[q, i] * (r - L)) / r
                f0 += t * y0
                f1 += t * y1
                f2 += t * y2
        f[i, 0] = f0
        f[i, 1] = f1
        f[i, 2] = f2

    return lps_pair_force


@functools.cache
def lps_dilatation_cf_kernel(scalar):
    """LPS dilatation, cancellation-free form from ``x`` (``kernels.lps.lps_dilatation_cf``);
    writes ``theta`` and ``p`` like :func:`lps_dilatation_kernel`."""
    wp = warp()
    A1 = wp.array(dtype=scalar)
    A2 = wp.array2d(dtype=scalar)

    @wp.kernel(module="unique")
    def lps_dilatation_cf(
        x: A2,
        u: A2,
        count: wp.array(dtype=wp.int32),
        nbr: wp.array2d(dtype=wp.int32),
        w: A2,
        intact: wp.array2d(dtype=wp.uint8),
        theta_coef: A1,
        p_coef: A1,
        theta: A1,
        p: A1,
    ):
        i = wp.tid()
        acc = scalar(0.0)
        for q in range(count[i]):
            if intact[q, i] != wp.uint8(0):
                j = nbr[q, i]
                d0 = x[j, 0] - x[i, 0]
                d1 = x[j, 1] - x[i, 1]
                d2 = x[j, 2] - x[i, 2]
                e0 = u[j, 0] - u[i, 0]
                e1 = u[j, 1] - u[i, 1]
                e2 = u[j, 2] - u[i, 2]
                y0 = d0 + e0
                y1 = d1 + e1
                y2 = d2 + e2
                r = wp.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
                L = wp.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
                ext2 = e0 * (y0 + d0) + e1 * (y1 + d1) + e2 * (y2 + d2)
                acc += w[q, i] * L * ext2 / (r + L)
        th = theta_coef[i] * acc
        theta[i] = th
        p[i] = th * p_coef[i]

    return lps_dilatation_cf


@functools.cache
def lps_pair_force_cf_kernel(scalar):
    """LPS pair force, cancellation-free form from ``x`` (``kernels.lps.lps_pair_force_cf``)."""
    wp = warp()
    A1 = wp.array(dtype=scalar)
    A2 = wp.array2d(dtype=scalar)

    @wp.kernel(module="unique")
    def lps_pair_force_cf(
        x: A2,
        u: A2,
        count: wp.array(dtype=wp.int32),
        nbr: wp.array2d(dtype=wp.int32),
        w: A2,
        dev: A2,
        intact: wp.array2d(dtype=wp.uint8),
        p: A1,
        f: A2,
    ):
        i = wp.tid()
        pi = p[i]
        f0 = scalar(0.0)
        f1 = scalar(0.0)
        f2 = scalar(0.0)
        for q in range(count[i]):
            if intact[q, i] != wp.uint8(0):
                j = nbr[q, i]
                d0 = x[j, 0] - x[i, 0]
                d1 = x[j, 1] - x[i, 1]
                d2 = x[j, 2] - x[i, 2]
                e0 = u[j, 0] - u[i, 0]
                e1 = u[j, 1] - u[i, 1]
                e2 = u[j, 2] - u[i, 2]
                y0 = d0 + e0
                y1 = d1 + e1
                y2 = d2 + e2
                r = wp.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
                L = wp.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
                ext2 = e0 * (y0 + d0) + e1 * (y1 + d1) + e2 * (y2 + d2)
                rl = r + L
                t = (w[q, i] * L * rl * (pi + p[j]) + dev[q, i] * ext2) / (r * rl)
                f0 += t * y0
                f1 += t * y1
                f2 += t * y2
        f[i, 0] = f0
        f[i, 1] = f1
        f[i, 2] = f2

    return lps_pair_force_cf
