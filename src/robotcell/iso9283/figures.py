"""The figures of ISO 9283 from measured cycles: arrays in, figures out (m, rad).

Formulas as restated in the public literature (``docs/iso9283.md`` cites each):

- pose accuracy: the barycentre ``(xbar, ybar, zbar)`` of the n cycles of a pose,
  ``AP_x = xbar - x_c`` (likewise y, z) and ``AP_p = sqrt(AP_x^2 + AP_y^2 + AP_z^2)``;
- pose repeatability: ``l_j`` the distance of cycle j from the barycentre,
  ``RP_l = lbar + 3 S_l`` with ``S_l`` the sample standard deviation of the ``l_j`` (n - 1);
- orientation: the deviation of cycle j is the rotation vector of ``R_j R_c^T`` in the frame,
  whose x, y, z components are the standard's a, b, c (rotations about x, y, z; exact for the
  small deviations of a robot); ``AP_a`` is their mean, ``RP_a = 3 S_a``;
- distance accuracy and repeatability between two poses: ``D_j`` their measured distance in
  cycle j, ``D_c`` the commanded one, ``AD_p = Dbar - D_c``, ``RD_p = 3 S_D``;
- path accuracy and repeatability: at each command point i the crossings ``x_ij`` of the
  measured paths with the plane through the point normal to the command path, their barycentre
  ``xbar_i``, ``AT_p = max_i |xbar_i - c_i|`` and ``RT_p = max_i (lbar_i + 3 S_li)`` with
  ``l_ij = |x_ij - xbar_i|``;
- orientation path accuracy (a choice: the pose's orientation deviation at the path's
  crossings): at each command point i the deviation of cycle j is the rotation vector of
  ``R_ij R_ci^T``, ``R_ij`` the orientation of the cycle's sample nearest its crossing;
  ``AT_a = max_i |mean_j a_ij|`` (likewise b, c).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

__all__ = [
    "PathFigures",
    "PoseFigures",
    "crossings",
    "distance_figures",
    "nearest_samples",
    "orientation_figures",
    "path_figures",
    "path_orientation_figures",
    "pose_figures",
    "tangents",
]


@dataclass(frozen=True)
class PoseFigures:
    """Position figures of one pose.

    Attributes
    ----------
    barycentre : ndarray, shape (3,)
        Mean measured position (m).
    AP : ndarray, shape (3,)
        ``AP_x, AP_y, AP_z``: barycentre minus command (m).
    AP_p : float
        Its length (m).
    l : ndarray, shape (n,)
        Distance of each cycle from the barycentre (m).
    l_mean, S_l, RP_l : float
        Mean of ``l``, its sample standard deviation, ``l_mean + 3 S_l`` (m).
    """

    barycentre: NDArray[np.float64]
    AP: NDArray[np.float64]
    AP_p: float
    l: NDArray[np.float64]
    l_mean: float
    S_l: float
    RP_l: float


def pose_figures(p: ArrayLike, command: ArrayLike) -> PoseFigures:
    """Pose accuracy and repeatability of one pose.

    Parameters
    ----------
    p : array_like, shape (n, 3)
        The measured positions of its n cycles (m), n >= 2.
    command : array_like, shape (3,)
        The commanded position (m).

    Returns
    -------
    PoseFigures
    """
    pts = np.asarray(p, dtype=float)
    bar = pts.mean(axis=0)
    ap = bar - np.asarray(command, dtype=float)
    l = np.linalg.norm(pts - bar, axis=1)
    s = float(np.std(l, ddof=1))
    return PoseFigures(bar, ap, float(np.linalg.norm(ap)), l, float(l.mean()), s,
                       float(l.mean() + 3 * s))


def orientation_figures(R: ArrayLike, command: ArrayLike
                        ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Orientation accuracy and repeatability of one pose.

    Parameters
    ----------
    R : array_like, shape (n, 3, 3)
        Measured orientations of its n cycles.
    command : array_like, shape (3, 3)
        The commanded orientation.

    Returns
    -------
    AP_abc : ndarray, shape (3,)
        Mean deviation about x, y, z of the frame (rad).
    RP_abc : ndarray, shape (3,)
        Three sample standard deviations of the deviations about x, y, z (rad).
    """
    dev = Rotation.from_matrix(np.asarray(R) @ np.asarray(command).T).as_rotvec()
    return dev.mean(axis=0), 3 * np.std(dev, axis=0, ddof=1)


def distance_figures(p1: ArrayLike, p2: ArrayLike, c1: ArrayLike, c2: ArrayLike
                     ) -> tuple[float, float, float, float, float]:
    """Distance accuracy and repeatability between two poses measured in the same cycles.

    Parameters
    ----------
    p1, p2 : array_like, shape (n, 3)
        Measured positions of the two poses, row j of each from cycle j (m).
    c1, c2 : array_like, shape (3,)
        Their commanded positions (m).

    Returns
    -------
    D_c, D_mean, AD_p, S_D, RD_p : float
        Commanded distance, mean measured distance, ``D_mean - D_c``, the sample standard
        deviation of the measured distances and ``3 S_D`` (m).
    """
    d = np.linalg.norm(np.asarray(p1, dtype=float) - np.asarray(p2, dtype=float), axis=1)
    dc = float(np.linalg.norm(np.asarray(c1, dtype=float) - np.asarray(c2, dtype=float)))
    s = float(np.std(d, ddof=1))
    return dc, float(d.mean()), float(d.mean() - dc), s, 3 * s


def tangents(command: ArrayLike) -> NDArray[np.float64]:
    """Unit directions of a command path at its points (central differences; a closed path,
    whose last point is its first, wraps around).

    Parameters
    ----------
    command : array_like, shape (M, 3)
        Points of the path in order (m), M >= 2.

    Returns
    -------
    ndarray, shape (M, 3)
    """
    c = np.asarray(command, dtype=float)
    closed = len(c) > 2 and np.linalg.norm(c[-1] - c[0]) < 1e-9
    nxt = np.vstack([c[1:], c[1:2] if closed else c[-1:]])
    prv = np.vstack([c[-2:-1] if closed else c[:1], c[:-1]])
    t = nxt - prv
    return t / np.linalg.norm(t, axis=1, keepdims=True)


def crossings(samples: ArrayLike, command: ArrayLike) -> NDArray[np.float64]:
    """Where one measured path crosses the plane normal to the command path at each point.

    Of all crossings of the polyline of the samples with the plane and the sample nearest the
    command point, the one nearest the command point: a crossing, except at an end of the path
    where the samples need not cross the plane (a robot that stops short of it).

    Parameters
    ----------
    samples : array_like, shape (K, 3)
        The measured path, in order (m), K >= 2.
    command : array_like, shape (M, 3)
        The command path (m).

    Returns
    -------
    ndarray, shape (M, 3)
        Metres.
    """
    s = np.asarray(samples, dtype=float)
    c = np.asarray(command, dtype=float)
    t = tangents(c)
    d = np.einsum("mj,mkj->mk", t, s[None] - c[:, None])       # (M, K) signed distances
    a, b = d[:, :-1], d[:, 1:]
    cross = (a * b <= 0) & (a != b)
    w = np.where(cross, a / np.where(a != b, a - b, 1.0), 0.0)   # (M, K-1)
    x = s[None, :-1] + w[..., None] * (s[1:] - s[:-1])[None]    # (M, K-1, 3)
    dist = np.where(cross, np.linalg.norm(x - c[:, None], axis=-1), np.inf)
    k = np.argmin(dist, axis=1)
    rows = np.arange(len(c))
    out = x[rows, k]
    near = np.linalg.norm(s[None] - c[:, None], axis=-1)        # (M, K)
    j = np.argmin(near, axis=1)
    closer = near[rows, j] < dist[rows, k]
    out[closer] = s[j[closer]]
    return out


@dataclass(frozen=True)
class PathFigures:
    """Figures of one path.

    Attributes
    ----------
    barycentre : ndarray, shape (M, 3)
        Barycentre of the cycles' crossings at each command point (m).
    deviation : ndarray, shape (M,)
        ``|xbar_i - c_i|`` (m).
    repeatability : ndarray, shape (M,)
        ``lbar_i + 3 S_li`` (m).
    AT_p, RT_p : float
        Their largest values (m).
    """

    barycentre: NDArray[np.float64]
    deviation: NDArray[np.float64]
    repeatability: NDArray[np.float64]
    AT_p: float
    RT_p: float


def path_figures(x: ArrayLike, command: ArrayLike) -> PathFigures:
    """Path accuracy and repeatability from the crossings of n cycles.

    Parameters
    ----------
    x : array_like, shape (n, M, 3)
        Crossings of each cycle at each command point (m), n >= 2.
    command : array_like, shape (M, 3)
        The command points (m).

    Returns
    -------
    PathFigures
    """
    xs = np.asarray(x, dtype=float)
    bar = xs.mean(axis=0)
    dev = np.linalg.norm(bar - np.asarray(command, dtype=float), axis=1)
    l = np.linalg.norm(xs - bar, axis=2)
    rep = l.mean(axis=0) + 3 * np.std(l, axis=0, ddof=1)
    return PathFigures(bar, dev, rep, float(dev.max()), float(rep.max()))


def nearest_samples(samples: ArrayLike, points: ArrayLike) -> NDArray[np.int_]:
    """Index of the sample nearest each point.

    Parameters
    ----------
    samples : array_like, shape (K, 3)
        A measured path (m).
    points : array_like, shape (M, 3)
        Its crossings (m).

    Returns
    -------
    ndarray of int, shape (M,)
    """
    s = np.asarray(samples, dtype=float)
    x = np.asarray(points, dtype=float)
    return np.argmin(np.linalg.norm(s[None] - x[:, None], axis=-1), axis=1)


def path_orientation_figures(R: ArrayLike, command: ArrayLike
                             ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Orientation path accuracy from the orientations of n cycles at the M command points.

    Parameters
    ----------
    R : array_like, shape (n, M, 3, 3)
        Measured orientation of each cycle at each command point.
    command : array_like, shape (M, 3, 3)
        Commanded orientations.

    Returns
    -------
    mean : ndarray, shape (M, 3)
        Mean deviation about x, y, z of the frame at each point (rad).
    AT_abc : ndarray, shape (3,)
        ``AT_a, AT_b, AT_c``: the largest magnitude of each over the points (rad).
    """
    dev = Rotation.from_matrix(
        (np.asarray(R) @ np.swapaxes(np.asarray(command), -1, -2)[None]).reshape(-1, 3, 3)
    ).as_rotvec().reshape(np.shape(R)[:2] + (3,))
    mean = dev.mean(axis=0)
    return mean, np.abs(mean).max(axis=0)
