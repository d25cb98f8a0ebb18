"""Velocity Verlet, prescribed values, bond breaking and the state check of the GPU backend
(Warp, float64 state). The same operations in the same order as ``peridyn.kernels.verlet``
and ``peridyn.kernels.damage``; arrays (n_points, 3) float64 unless said otherwise.
"""

import functools

from peridyn.kernels.gpu import warp


@functools.cache
def kick_drift_kernel():
    """``v += half_dt * a`` then ``u += dt * v`` (IN/OUT ``u``, ``v``; ``verlet.kick_drift``)."""
    wp = warp()
    A2 = wp.array2d(dtype=wp.float64)

    @wp.kernel(module="unique")
    def kick_drift(u: A2, v: A2, a: A2, half_dt: wp.float64, dt: wp.float64):
        i, c = wp.tid()
        vk = v[i, c] + half_dt * a[i, c]
        v[i, c] = vk
        u[i, c] = u[i, c] + dt * vk

    return kick_drift


@functools.cache
def acceleration_kernel(scalar):
    """``a = (f + b) * inv_rho``, ``a -= damping * v``, ``a = 0`` where ``constrained``, and with
    ``kick`` ``v += half_dt * a`` (``verlet.acceleration``): ``f`` (n, 3) of ``scalar``, taken as
    float64; ``damping`` (0,), (1,) or (n,) 1/s; ``constrained`` (n, 3) uint8. With ``keep_free``
    1, ``free`` (OUT, (n, 3)) gets ``a`` before the constraint zeroes it (the force acceleration
    of Peridigm's differenced velocity, ``solvers.explicit``)."""
    wp = warp()
    A1 = wp.array(dtype=wp.float64)
    A2 = wp.array2d(dtype=wp.float64)

    @wp.kernel(module="unique")
    def acceleration(
        f: wp.array2d(dtype=scalar),
        b: A2,
        inv_rho: A1,
        damping: A1,
        v: A2,
        constrained: wp.array2d(dtype=wp.uint8),
        a: A2,
        kick: wp.int32,
        half_dt: wp.float64,
        keep_free: wp.int32,
        free: A2,
    ):
        i, k = wp.tid()
        n_damping = damping.shape[0]
        ak = (wp.float64(f[i, k]) + b[i, k]) * inv_rho[i]
        if n_damping == 1:
            ak = ak - damping[0] * v[i, k]
        elif n_damping > 1:
            ak = ak - damping[i] * v[i, k]
        if keep_free != 0:
            free[i, k] = ak
        if constrained[i, k] != wp.uint8(0):
            ak = wp.float64(0.0)
        a[i, k] = ak
        if kick != 0:
            v[i, k] = v[i, k] + half_dt * ak

    return acceleration


@functools.cache
def difference_velocity_kernel():
    """Peridigm's velocity of the DOFs with a prescribed displacement (``mask`` (n, 3) uint8):
    ``v = (u - u_before) / dt + half_dt * free`` (``solvers.explicit``, ``prescribed_velocity:
    difference``); the other DOFs are left as they are."""
    wp = warp()
    A2 = wp.array2d(dtype=wp.float64)

    @wp.kernel(module="unique")
    def difference_velocity(
        u: A2,
        u_before: A2,
        free: A2,
        mask: wp.array2d(dtype=wp.uint8),
        dt: wp.float64,
        half_dt: wp.float64,
        v: A2,
    ):
        i, k = wp.tid()
        if mask[i, k] != wp.uint8(0):
            v[i, k] = (u[i, k] - u_before[i, k]) / dt + half_dt * free[i, k]

    return difference_velocity


@functools.cache
def prescribe_kernel():
    """``target[index[r], comps[c]] = amplitude[r, c] * scale`` (``add`` 0), or ``+=`` that
    (``add`` 1): a boundary condition's values at one time, ``index`` (m,) int32, ``comps``
    (n_comp,) int32, ``amplitude`` (m, n_comp) float64 (``physics.loads``)."""
    wp = warp()
    A2 = wp.array2d(dtype=wp.float64)

    @wp.kernel(module="unique")
    def prescribe(
        target: A2,
        index: wp.array(dtype=wp.int32),
        comps: wp.array(dtype=wp.int32),
        amplitude: A2,
        scale: wp.float64,
        add: wp.int32,
    ):
        r, c = wp.tid()
        value = amplitude[r, c] * scale
        i = index[r]
        k = comps[c]
        if add != 0:
            target[i, k] = target[i, k] + value
        else:
            target[i, k] = value

    return prescribe


@functools.cache
def to_scalar_kernel(scalar):
    """``out = u`` converted to ``scalar`` (the float32 force's displacement)."""
    wp = warp()

    @wp.kernel(module="unique")
    def to_scalar(u: wp.array2d(dtype=wp.float64), out: wp.array2d(dtype=scalar)):
        i, k = wp.tid()
        out[i, k] = scalar(u[i, k])

    return to_scalar


@functools.cache
def stretch_break_kernel():
    """Break every intact bond whose deformed length passes its critical length: ``intact``
    (IN/OUT, (k_max, n) uint8) set to 0 where ``|Y|^2 > limit^2``, ``Y = xi + (u_j - u_i)``,
    ``limit`` (k_max, n) m (inf: may not break); ``broken`` (1,) int32 counts the directed bonds
    broken. Both copies of a bond get the same verdict (``Y_ji = -Y_ij`` exactly), as in
    ``kernels.damage.stretch_test_families``, which tests the same squared length."""
    wp = warp()
    A2 = wp.array2d(dtype=wp.float64)

    @wp.kernel(module="unique")
    def stretch_break(
        xi0: A2,
        xi1: A2,
        xi2: A2,
        u: A2,
        count: wp.array(dtype=wp.int32),
        nbr: wp.array2d(dtype=wp.int32),
        limit: A2,
        intact: wp.array2d(dtype=wp.uint8),
        broken: wp.array(dtype=wp.int32),
    ):
        i = wp.tid()
        ui0 = u[i, 0]
        ui1 = u[i, 1]
        ui2 = u[i, 2]
        hits = wp.int32(0)
        for q in range(count[i]):
            if intact[q, i] != wp.uint8(0):
                j = nbr[q, i]
                y0 = xi0[q, i] + (u[j, 0] - ui0)
                y1 = xi1[q, i] + (u[j, 1] - ui1)
                y2 = xi2[q, i] + (u[j, 2] - ui2)
                lim = limit[q, i]
                if y0 * y0 + y1 * y1 + y2 * y2 > lim * lim:
                    intact[q, i] = wp.uint8(0)
                    hits += wp.int32(1)
        if hits > 0:
            wp.atomic_add(broken, 0, hits)

    return stretch_break


@functools.cache
def unsound_kernel():
    """``bad`` (1,) int32 += 1 for each point with a component of ``u`` above
    ``max_displacement`` (m) or not finite, or of ``v`` not finite (``verlet.state_is_sound``)."""
    wp = warp()
    A2 = wp.array2d(dtype=wp.float64)

    @wp.kernel(module="unique")
    def unsound(u: A2, v: A2, max_displacement: wp.float64, bad: wp.array(dtype=wp.int32)):
        i = wp.tid()
        bad_values = wp.int32(0)
        for k in range(3):
            if not (wp.abs(u[i, k]) <= max_displacement):
                bad_values += wp.int32(1)
            if not wp.isfinite(v[i, k]):
                bad_values += wp.int32(1)
        if bad_values > 0:
            wp.atomic_add(bad, 0, 1)

    return unsound


@functools.cache
def gather_rows_kernel():
    """``out[r] = values[index[r]]``: the rows (n_points, 3) float64 of ``index`` (k,) int32 into
    ``out`` (k, 3) (a recorder's probe points)."""
    wp = warp()
    A2 = wp.array2d(dtype=wp.float64)

    @wp.kernel(module="unique")
    def gather_rows(values: A2, index: wp.array(dtype=wp.int32), out: A2):
        r, c = wp.tid()
        out[r, c] = values[index[r], c]

    return gather_rows
