"""The test cube of ISO 9283: its test plane, the five poses and the two test paths.

Coordinates here are those of the cube: origin at its centre, axes along its edges (parallel to
the robot base frame R, as the standard places the cube), metres. The test plane is the
diagonal plane through the cube's edge ``x = z = -h`` and the opposite edge ``x = z = +h``
(``h`` half the edge): its corners, in the order P2 to P5 take them, are ``(-h, -h, -h)``,
``(-h, +h, -h)``, ``(+h, +h, +h)``, ``(+h, -h, +h)``. P1 is the centre; P2 to P5 lie on the
plane's diagonals at :data:`CORNER_FRACTION` of the diagonal's length from their corner, i.e. at
``(1 - 2 * CORNER_FRACTION)`` times the corner. The line path runs from P2 through P1 to P4; the
circle is centred on P1 in the plane, of diameter :data:`CIRCLE_FRACTION` times the edge.
``docs/iso9283.md`` cites where each number comes from and names the choices.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "CIRCLE_FRACTION",
    "CIRCLE_SEGMENTS",
    "CORNER_FRACTION",
    "LINE_POINTS",
    "PATH_NAMES",
    "POSE_NAMES",
    "circle_points",
    "cube_corners",
    "grid_points",
    "line_points",
    "pose_points",
    "with_orientation",
]

#: Names of the five test poses, P1 the centre of the test plane.
POSE_NAMES = ("P1", "P2", "P3", "P4", "P5")
#: Names of the two test paths.
PATH_NAMES = ("line", "circle")
#: Distance of P2..P5 from their corner of the test plane, as a fraction of its diagonal.
CORNER_FRACTION = 0.1
#: Diameter of the circle path as a fraction of the cube's edge.
CIRCLE_FRACTION = 0.8
#: Points of the line path at which the path figures are evaluated (ends included).
LINE_POINTS = 21
#: Linear segments of the circle path (its points are where the figures are evaluated).
CIRCLE_SEGMENTS = 72

#: The test plane's corners in units of the half edge, in the order of P2..P5.
_PLANE_CORNERS = np.array([[-1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [1.0, 1.0, 1.0],
                           [1.0, -1.0, 1.0]])
#: Unit vectors of the test plane: along the edges it holds (y), and across (x + z).
_PLANE_U = np.array([0.0, 1.0, 0.0])
_PLANE_W = np.array([1.0, 0.0, 1.0]) / np.sqrt(2.0)


def pose_points(size: float) -> NDArray[np.float64]:
    """P1..P5 in the cube's coordinates.

    Parameters
    ----------
    size : float
        Edge of the cube (m).

    Returns
    -------
    ndarray, shape (5, 3)
        Metres.
    """
    corners = _PLANE_CORNERS * (size / 2)
    return np.vstack([np.zeros(3), (1 - 2 * CORNER_FRACTION) * corners])


def line_points(size: float) -> NDArray[np.float64]:
    """The line path from P2 through P1 to P4, :data:`LINE_POINTS` evenly spaced points.

    Parameters
    ----------
    size : float
        Edge of the cube (m).

    Returns
    -------
    ndarray, shape (LINE_POINTS, 3)
        Metres, in the cube's coordinates.
    """
    p = pose_points(size)
    t = np.linspace(0.0, 1.0, LINE_POINTS)[:, None]
    return (1 - t) * p[1] + t * p[3]


def circle_points(size: float) -> NDArray[np.float64]:
    """The circle path, closed: :data:`CIRCLE_SEGMENTS` + 1 points, the last one the first.

    Parameters
    ----------
    size : float
        Edge of the cube (m).

    Returns
    -------
    ndarray, shape (CIRCLE_SEGMENTS + 1, 3)
        Metres, in the cube's coordinates; it starts on the plane's ``+u`` (y) side and turns
        towards ``+w`` (x + z).
    """
    t = np.linspace(0.0, 2 * np.pi, CIRCLE_SEGMENTS + 1)[:, None]
    r = CIRCLE_FRACTION * size / 2
    pts = r * (np.cos(t) * _PLANE_U + np.sin(t) * _PLANE_W)
    pts[-1] = pts[0]
    return pts


def grid_points(size: float, n: int) -> NDArray[np.float64]:
    """An ``n x n x n`` grid over the whole cube, corners included.

    Parameters
    ----------
    size : float
        Edge of the cube (m).
    n : int
        Points per edge (at least 2).

    Returns
    -------
    ndarray, shape (n**3, 3)
        Metres, in the cube's coordinates.
    """
    s = np.linspace(-size / 2, size / 2, n)
    return np.stack(np.meshgrid(s, s, s, indexing="ij"), axis=-1).reshape(-1, 3)


def with_orientation(T_R_cube: ArrayLike, points: ArrayLike, R_R_TCP: ArrayLike
                     ) -> NDArray[np.float64]:
    """TCP poses in R at points of the cube, all with one orientation.

    Parameters
    ----------
    T_R_cube : array_like, shape (..., 4, 4)
        The cube's pose in R (m).
    points : array_like, shape (K, 3)
        Points in the cube's coordinates (m).
    R_R_TCP : array_like, shape (3, 3)
        The TCP's orientation in R.

    Returns
    -------
    ndarray, shape (..., K, 4, 4)
        ``T_R_TCP`` (m).
    """
    T = np.asarray(T_R_cube, dtype=float)
    p = np.asarray(points, dtype=float)
    out = np.zeros(T.shape[:-2] + p.shape[:1] + (4, 4))
    out[..., :3, :3] = np.asarray(R_R_TCP, dtype=float)
    out[..., :3, 3] = np.einsum("...ij,kj->...ki", T[..., :3, :3], p) + T[..., None, :3, 3]
    out[..., 3, 3] = 1.0
    return out


def cube_corners(poses: ArrayLike) -> NDArray[np.float64]:
    """The eight corners of the test cube, from the positions of its five test poses.

    The test plane's corners follow from P1 and P2..P5 (``corner = P1 + (Pk - P1) / (1 - 2 *
    CORNER_FRACTION)``); the cube's other four corners lie off the plane along its normal by
    the plane's short edge, on either side of the plane's long edges.

    Parameters
    ----------
    poses : array_like, shape (5, 3)
        P1..P5 in any frame (m).

    Returns
    -------
    ndarray, shape (8, 3)
        The plane's corners (in the order of P2..P5), then the other four, in the same frame.
    """
    p = np.asarray(poses, dtype=float)
    plane = p[0] + (p[1:] - p[0]) / (1 - 2 * CORNER_FRACTION)
    edge = plane[1] - plane[0]                 # the plane's short edge: a cube edge
    across = plane[3] - plane[0]               # a face diagonal: the sum of two cube edges
    side = np.cross(edge / np.linalg.norm(edge), across) / 2
    a = across / 2 + side                      # one of the two cube edges the diagonal sums
    other = np.array([plane[0] + a, plane[1] + a, plane[2] - a, plane[3] - a])
    return np.vstack([plane, other])
