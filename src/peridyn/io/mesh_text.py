"""Peridigm-style text meshes: one point per line, ``x y z block_id volume``.

Columns are separated by whitespace; ``#`` starts a comment (whole line or
trailing) and blank lines are ignored. Coordinates are in metres, volumes in
cubic metres, block ids are integers.
"""

from __future__ import annotations

import os
import warnings

import numpy as np

from peridyn.discretization.body import Body
from peridyn.errors import InputError

N_COLUMNS = 5
COLUMNS = "x y z block_id volume"

# Latin-1 never fails to decode and parses faster than UTF-8. Numbers are ASCII and no
# UTF-8 multi-byte character contains the byte of '#', so UTF-8 comments are skipped alike.
_ENCODING = "latin-1"


def read_text_mesh(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Read a text mesh.

    Parameters
    ----------
    path : str or path-like
        The mesh file.

    Returns
    -------
    points : ndarray, shape (n, 3), float64
        Point coordinates in m.
    block_ids : ndarray, shape (n,), int64
        Block (material region) id of each point.
    volumes : ndarray, shape (n,), float64
        Point volumes in m^3, all positive.

    Raises
    ------
    InputError
        The file is missing or unreadable, has no points, a line does not have
        5 numeric columns, a coordinate is not finite, a block id is not an
        integer or a volume is not positive and finite. The message names the
        file and the line number.
    """
    path = os.fspath(path)
    table = _load_table(path)
    points = np.ascontiguousarray(table[:, :3])
    block_ids = _check_block_ids(path, table[:, 3])
    volumes = np.ascontiguousarray(table[:, 4])
    _check_finite_points(path, points)
    _check_volumes(path, volumes)
    return points, block_ids, volumes


def write_text_mesh(path: str | os.PathLike, points, block_ids, volumes) -> None:
    """Write a text mesh that :func:`read_text_mesh` reads back exactly.

    Parameters
    ----------
    path : str or path-like
        The file to write (overwritten).
    points : array_like, shape (n, 3) or (n, 2)
        Coordinates in m; 2-D points get ``z = 0``.
    block_ids : array_like, shape (n,)
        Integer block ids.
    volumes : array_like, shape (n,)
        Positive point volumes in m^3.

    Raises
    ------
    InputError
        Shapes do not match, coordinates are not finite, block ids are not
        integers or volumes are not positive and finite.
    """
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise InputError(f"points must have shape (n, 2) or (n, 3), got {points.shape}")
    n = points.shape[0]
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(n)])
    block_ids = np.asarray(block_ids)
    volumes = np.asarray(volumes, dtype=np.float64)
    if block_ids.shape != (n,) or volumes.shape != (n,):
        raise InputError(
            f"block_ids and volumes must have shape ({n},) like points, "
            f"got {block_ids.shape} and {volumes.shape}"
        )
    if not np.all(np.isfinite(points)):
        raise InputError("points must be finite")
    if block_ids.dtype.kind not in "iu":
        raise InputError(f"block_ids must be integers, got dtype {block_ids.dtype}")
    if not np.all(np.isfinite(volumes) & (volumes > 0)):
        raise InputError("volumes must be positive and finite")
    table = np.column_stack([points, block_ids, volumes])
    np.savetxt(path, table, fmt=["%.17g"] * 3 + ["%d", "%.17g"], header=COLUMNS)


def _load_table(path: str) -> np.ndarray:
    """Parse the whole file into an ``(n, 5)`` float64 table."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # "input contained no data"
            table = np.loadtxt(path, dtype=np.float64, comments="#", ndmin=2, encoding=_ENCODING)
    except FileNotFoundError:
        raise InputError(f"mesh file {path!r} does not exist") from None
    except OSError as exc:
        raise InputError(f"cannot read mesh file {path!r}: {exc.strerror or exc}") from None
    except ValueError as exc:
        raise _locate_parse_error(path, exc) from None
    if table.size == 0:
        raise InputError(f"{path}: no points (the file is empty or has only comments)")
    if table.shape[1] != N_COLUMNS:
        line = _data_line_numbers(path)[0]
        raise _column_error(path, line, table.shape[1])
    return table


def _locate_parse_error(path: str, exc: ValueError) -> InputError:
    """Find the first line with a wrong column count or a non-numeric value."""
    for line_no, tokens in _data_lines(path):
        if len(tokens) != N_COLUMNS:
            return _column_error(path, line_no, len(tokens))
        for column, token in zip(COLUMNS.split(), tokens, strict=True):
            if not _is_number(token):
                return InputError(f"{path}, line {line_no}: {column} = {token!r} is not a number")
    return InputError(f"{path}: cannot parse the mesh ({exc})")


def _column_error(path: str, line_no: int, found: int) -> InputError:
    return InputError(f"{path}, line {line_no}: found {found} columns, expected {N_COLUMNS} ({COLUMNS})")


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _data_lines(path: str):
    """Yield ``(line_number, tokens)`` for each non-blank, non-comment line (1-based)."""
    with open(path, encoding=_ENCODING) as f:
        for line_no, line in enumerate(f, start=1):
            tokens = line.split("#", 1)[0].split()
            if tokens:
                yield line_no, tokens


def _data_line_numbers(path: str) -> list[int]:
    """File line number (1-based) of each data row."""
    return [line_no for line_no, _ in _data_lines(path)]


def _first_bad_line(path: str, bad: np.ndarray) -> int | None:
    """Line number of the first row flagged in the boolean mask ``bad``, or None."""
    rows = np.flatnonzero(bad)
    if rows.size == 0:
        return None
    return _data_line_numbers(path)[rows[0]]


def _check_finite_points(path: str, points: np.ndarray) -> None:
    line = _first_bad_line(path, ~np.all(np.isfinite(points), axis=1))
    if line is not None:
        raise InputError(f"{path}, line {line}: coordinates must be finite numbers (x y z)")


def _check_block_ids(path: str, column: np.ndarray) -> np.ndarray:
    representable = np.isfinite(column) & (np.abs(column) < 2.0**62)
    ids = np.where(representable, column, 0.0).astype(np.int64)
    line = _first_bad_line(path, ~representable | (ids != column))
    if line is not None:
        raise InputError(f"{path}, line {line}: block_id must be an integer")
    return ids


def _check_volumes(path: str, volumes: np.ndarray) -> None:
    bad = ~(np.isfinite(volumes) & (volumes > 0))
    line = _first_bad_line(path, bad)
    if line is not None:
        value = volumes[np.flatnonzero(bad)[0]]
        raise InputError(f"{path}, line {line}: volume must be positive and finite, got {float(value)!r}")


def volume_cells(volumes: np.ndarray, dim: int, thickness: float | None, what: str):
    """Cells (n_points, 3) of points of ``volumes`` (m^3) read from a mesh, and their in-plane
    sides (n_points,), m: cubes of the volume in 3D, squares times ``thickness`` (m) in 2D."""
    if dim == 2:
        if thickness is None:
            raise InputError(f"a 2D {what} needs the thickness of the body")
        side = np.sqrt(volumes / thickness)
        return np.stack([side, side, np.full_like(side, thickness)], axis=1), side
    side = np.cbrt(volumes)
    return np.stack([side, side, side], axis=1), side


def from_text_mesh(path, dim: int = 3, thickness: float | None = None, plane: str | None = None) -> Body:
    """A body from a Peridigm-style text mesh (``x y z block_id volume`` per line).

    Cells are taken as cubes of the point's volume (squares times ``thickness``
    in 2D); node sets ``block_<id>`` hold the points of each block.
    """
    points, blocks, volumes = read_text_mesh(path)
    if dim == 2:
        line = _first_bad_line(os.fspath(path), points[:, 2] != 0.0)
        if line is not None:
            raise InputError(f"{path}, line {line}: a 2D body's points need z = 0")
    cells, side = volume_cells(volumes, dim, thickness, "text mesh")
    sets = {f"block_{b}": np.flatnonzero(blocks == b) for b in np.unique(blocks)}
    return Body(
        points=points,
        volumes=volumes,
        cells=cells,
        dim=dim,
        spacing=float(np.median(side)),
        node_sets=sets,
        thickness=thickness,
        plane=plane,
    )


def to_text_mesh(body: Body, path, block_ids=None) -> None:
    """Write ``body`` as a Peridigm-style text mesh (block 1 unless ``block_ids`` given)."""
    blocks = np.ones(body.n_points, dtype=np.int64) if block_ids is None else block_ids
    write_text_mesh(path, body.points, blocks, body.volumes)
