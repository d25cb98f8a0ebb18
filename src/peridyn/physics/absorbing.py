"""Absorbing boundary layers: mass-proportional damping that grows towards chosen faces.

Waves that reach the free edges of a finite plate come back and mix with the waves a
guided-wave study measures. A layer of width ``w`` along a face damps them before they
return: each point at distance ``d < w`` from the face (measured from the outermost row
of points) gets the damping coefficient

    c(d) = c_max ((w - d) / w)^3          (1/s; rho a = f - rho c v),

zero at the layer's inner edge and ``c_max`` on the face. The cubic growth keeps the
change of c over a wavelength small, so the layer itself reflects little (the absorbing
layers with increasing damping of Rajagopal et al., NDT&E Int. 2012, for commercial FE
codes). Across the layer and back, a wave of group velocity ``c_g`` with ``c << omega``
loses the amplitude factor ``exp(-c_max w / (4 c_g))`` (the decay rate is ``c / (2 c_g)``
and ``int_0^w c dd = c_max w / 4``): ``c_max = 18 c_g / w`` leaves 1 %. Points inside the
domain are not damped, so nothing changes there before a wave has been to a layer and back.
"""

from __future__ import annotations

import numpy as np

from peridyn.errors import InputError

__all__ = ["FACES", "LATERAL_FACES", "layer_damping"]

#: Faces of a body's bounding box, as in ``geometry.face``.
FACES = ("x-", "x+", "y-", "y+", "z-", "z+")
#: The free edges of a plate in the x-y plane.
LATERAL_FACES = ("x-", "x+", "y-", "y+")


def layer_damping(points, width: float, damping: float, faces=LATERAL_FACES) -> np.ndarray:
    """Damping coefficient of each point of absorbing layers along ``faces``.

    Parameters
    ----------
    points : (n, 2 or 3) float, m
        Point coordinates.
    width : float, m
        Layer width, measured inwards from the outermost points of each face.
    damping : float, 1/s
        ``c_max``, the coefficient on the faces.
    faces : sequence of "x-", "x+", "y-", "y+", "z-", "z+"
        Faces of the points' bounding box that get a layer.

    Returns
    -------
    (n,) float64, 1/s
        ``c_max ((w - d) / w)^3`` within ``width`` of the nearest face, 0 elsewhere.

    Raises
    ------
    InputError
        Width or damping not positive, an unknown or repeated face, or layers that leave no
        undamped point.
    """
    pts = np.asarray(points, dtype=float)
    if not (np.isfinite(width) and width > 0):
        raise InputError(f"absorbing layer width must be positive (m), got {width!r}")
    if not (np.isfinite(damping) and damping > 0):
        raise InputError(f"absorbing layer damping must be positive (1/s), got {damping!r}")
    faces = list(faces)
    unknown = [f for f in faces if f not in FACES[: 2 * pts.shape[1]]]
    if unknown or not faces or len(set(faces)) < len(faces):
        raise InputError(
            f"absorbing layer faces must be distinct names among "
            f"{list(FACES[: 2 * pts.shape[1]])}, got {faces}"
        )
    distance = np.full(len(pts), np.inf)
    for face in faces:
        coord = pts[:, "xyz".index(face[0])]
        distance = np.minimum(distance, coord - coord.min() if face[1] == "-" else coord.max() - coord)
    if np.all(distance < width):
        raise InputError(
            f"absorbing layers {width:g} m wide on faces {faces} cover the whole body: "
            "no undamped interior is left (narrow them)"
        )
    depth = np.clip((width - distance) / width, 0.0, 1.0)
    return damping * depth**3
