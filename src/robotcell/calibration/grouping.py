"""Which measurement rows were taken at the same commanded axis values: grouping by resolution.

Joint or axis values read back from a controller carry a jitter of 0.01-0.1 deg around the
commanded value, so rows commanded at the same value are not equal as floating-point numbers.
Every procedure that groups rows (the circle point analysis of an identification, the 2-axis
positioner's start, the distinct angles of a turntable, the distinct positions of a track, the
distinct configurations that count for an identification's redundancy) groups them here, by what
the measurement can resolve:

* **A stated tolerance** (``tol``, rad for revolute and m for prismatic columns, one number or
  one per column): two rows are neighbours when every column differs by at most its tolerance,
  and a group is a set of rows linked by neighbours (single linkage).
* **Derived from the data** (``tol=None``, :func:`resolution`): the columns are scaled by the
  largest jitter a read-back can plausibly have (:data:`MAX_JITTER_ANGLE`,
  :data:`MAX_JITTER_LENGTH`), and the distance of two rows is their largest scaled column
  difference. Single linkage merges the rows in the order of these distances (the edges of their
  minimum spanning tree): rows commanded at the same values merge at the jitter's scale, groups
  at different commanded values a grid step later. Sorted, the merge distances show a jump: the
  highest place where one is at least :data:`GAP_RATIO` times the one below it, the lower one
  within the plausible jitter, separates the two. The tolerance is the geometric mean of the two
  (the upper one counted at most ``GAP_RATIO`` times the plausible jitter); rows that all lie
  within the plausible jitter of each other are one value. Without such a jump (every row at
  its own values, or values equal to rounding) it is :data:`EXACT`: values equal to 1e-9 rad
  or m.

Both run on a k-d tree (``scipy.spatial.cKDTree``, Chebyshev distance): each row is linked to its
16 nearest rows within a few grid steps, and the groups these links leave are linked through
their centres (single linkage, exact on a line, where the values are sorted instead), so time and
memory grow about linearly with the rows however many share a value.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components, minimum_spanning_tree
from scipy.spatial import cKDTree

from robotcell.errors import InputError

__all__ = ["EXACT", "GAP_RATIO", "MAX_JITTER_ANGLE", "MAX_JITTER_LENGTH", "alone_groups",
           "distinct", "groups", "joint_tolerances", "resolution"]

#: Tolerance when the data show no jitter (rad or m): values equal to rounding.
EXACT = 1e-9
#: Largest read-back jitter a tolerance derived from the data may stand for: 0.5 deg for an
#: angle, 0.5 mm for a length (controllers read back within 0.01-0.1 deg of the commanded value).
MAX_JITTER_ANGLE = math.radians(0.5)
MAX_JITTER_LENGTH = 0.5e-3
#: Ratio between the merge distance of rows at different commanded values and that of rows at
#: the same value from which the two are told apart (and the reach, in plausible jitters, of the
#: merge distances computed).
GAP_RATIO = 10.0
#: Smallest merge distance counted, in units of the plausible jitter: rows equal to rounding.
_FLOOR = 1e-9 / MAX_JITTER_ANGLE
#: Nearest rows each row is linked to (:func:`_linkage`).
_NEIGHBOURS = 16


def _as_rows(values: ArrayLike) -> NDArray[np.float64]:
    arr = np.asarray(values, dtype=float)
    if arr.ndim == 1:
        arr = arr[:, None]
    if arr.ndim != 2:
        raise InputError(f"values to group must have shape (N,) or (N, k), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InputError("values to group contain NaN or infinite values")
    return arr


def _caps(k: int, prismatic: ArrayLike | None) -> NDArray[np.float64]:
    """The plausible jitter per column: angles, or lengths where ``prismatic``."""
    pris = np.zeros(k, dtype=bool) if prismatic is None else np.asarray(prismatic, dtype=bool)
    if pris.shape != (k,):
        raise InputError(f"prismatic must have one entry per column ({k}), got {pris.shape}")
    return np.where(pris, MAX_JITTER_LENGTH, MAX_JITTER_ANGLE)


def joint_tolerances(tol: ArrayLike, prismatic: ArrayLike) -> NDArray[np.float64]:
    """A stated tolerance per joint, in SI: a single number is an angle.

    Parameters
    ----------
    tol : float or array_like, shape (n,)
        One number (rad) for every revolute joint, a prismatic joint taking as many millimetres
        as that is degrees (the units of a measurement file's joint columns); or one value per
        joint (rad, m).
    prismatic : array_like of bool, shape (n,)

    Returns
    -------
    ndarray, shape (n,)
        Rad for revolute, m for prismatic joints.
    """
    pris = np.asarray(prismatic, dtype=bool)
    t = np.asarray(tol, dtype=float)
    if t.ndim == 0:
        return np.where(pris, math.degrees(float(t)) * 1e-3, float(t))
    return _tolerances(t, len(pris))


def _tolerances(tol: ArrayLike, k: int) -> NDArray[np.float64]:
    t = np.asarray(tol, dtype=float)
    if t.ndim == 0:
        t = np.full(k, float(t))
    if t.shape != (k,) or not np.all(np.isfinite(t)) or np.any(t < 0):
        raise InputError(f"the grouping tolerance must be a number >= 0 or one per column ({k}), "
                         f"got {tol!r}")
    return np.maximum(t, EXACT)


def _linkage(scaled: NDArray[np.float64], reach: float
             ) -> tuple[NDArray[np.float64], NDArray[np.int_]]:
    """Single linkage of the rows up to ``reach`` (largest column difference, scaled units).

    Returns the merge distances no longer than ``reach`` (unsorted) and the group of each row
    when every merge up to ``reach`` is made. On a line these are the gaps between the sorted
    values. Else each row is linked to its :data:`_NEIGHBOURS` nearest rows within reach (a k-d
    tree query, linear memory however many rows share a value), the minimum spanning forest of
    those links merges the rows, and the groups it leaves are linked again through their
    centres, the same way, until no two are within reach.
    """
    n, k = scaled.shape
    if k == 1:
        order = np.argsort(scaled[:, 0], kind="stable")
        gaps = np.maximum(np.diff(scaled[order, 0]), _FLOOR)
        labels = np.empty(n, dtype=int)
        labels[order] = np.concatenate([[0], np.cumsum(gaps > reach)])
        return gaps[gaps <= reach], labels
    m = min(n, _NEIGHBOURS + 1)
    d, j = cKDTree(scaled).query(scaled, k=m, p=np.inf, distance_upper_bound=reach)
    d, j = d.reshape(n, m), j.reshape(n, m)
    i = np.broadcast_to(np.arange(n)[:, None], (n, m))
    ok = np.isfinite(d) & (j != i)  # itself, and no row within reach, left out
    weight = np.maximum(d[ok], _FLOOR)  # rows equal to rounding are linked too
    forest = minimum_spanning_tree(coo_matrix((weight, (i[ok], j[ok])), shape=(n, n)).tocsr())
    count, labels = connected_components(forest, directed=False)
    edges = forest.data
    if 1 < count < n:
        centres = np.zeros((count, k))
        np.add.at(centres, labels, scaled)
        centres /= np.bincount(labels, minlength=count)[:, None]
        more, joined = _linkage(centres, reach)
        edges, labels = np.concatenate([edges, more]), joined[labels]
    return edges, labels


def _merge_distances(scaled: NDArray[np.float64]) -> NDArray[np.float64]:
    """Single-linkage merge distances of the rows up to :data:`GAP_RATIO` (scaled units): sorted,
    then ``inf`` when the rows do not all link within it."""
    edges = np.sort(_linkage(scaled, GAP_RATIO)[0])
    return np.append(edges, np.inf) if len(edges) < len(scaled) - 1 else edges


def resolution(values: ArrayLike, prismatic: ArrayLike | None = None) -> NDArray[np.float64]:
    """The tolerance the data resolve commanded values to, per column (see the module).

    Parameters
    ----------
    values : array_like, shape (N,) or (N, k)
        Axis values of each row (rad; m for prismatic columns).
    prismatic : array_like of bool, shape (k,), optional
        Columns that are lengths (default: all angles).

    Returns
    -------
    ndarray, shape (k,)
        Rows whose every column differs by at most this (rad, m) are at the same commanded
        values; :data:`EXACT` where the data show no jitter.
    """
    rows = _as_rows(values)
    caps = _caps(rows.shape[1], prismatic)
    if len(rows) < 2:
        return np.full(rows.shape[1], EXACT)
    scaled = rows / caps
    s = _merge_distances(scaled)
    if np.isfinite(s[-1]) and np.ptp(scaled, axis=0).max() <= 1.0:
        s = np.append(s, np.inf)  # every row within the plausible jitter of the others: one value
    jump = np.flatnonzero((s[1:] >= GAP_RATIO * s[:-1]) & (s[:-1] <= 1.0))
    if not jump.size:
        return np.full(rows.shape[1], EXACT)
    i = jump[-1]
    return np.maximum(math.sqrt(s[i] * min(s[i + 1], GAP_RATIO)) * caps, EXACT)


def groups(values: ArrayLike, tol: ArrayLike | None = None,
           prismatic: ArrayLike | None = None) -> NDArray[np.int_]:
    """Label the rows by the commanded values they were taken at.

    Parameters
    ----------
    values : array_like, shape (N,) or (N, k)
        Axis values of each row (rad; m for prismatic columns).
    tol : float or array_like, shape (k,), optional
        Stated tolerance (rad, m): rows whose every column differs by at most it are neighbours,
        and neighbours of neighbours are one group. Default :func:`resolution` of ``values``.
    prismatic : array_like of bool, shape (k,), optional
        Columns that are lengths, for the derived tolerance.

    Returns
    -------
    ndarray of int, shape (N,)
        Group of each row, numbered 0, 1, ... in the order of their first row.

    Raises
    ------
    InputError
        Values that are not finite, a tolerance that is negative or of the wrong shape.
    """
    rows = _as_rows(values)
    n, k = rows.shape
    if n == 0:
        return np.zeros(0, dtype=int)
    t = resolution(rows, prismatic) if tol is None else _tolerances(tol, k)
    labels = _linkage(rows / t, 1.0 + 1e-12)[1]
    _, first, inverse = np.unique(labels, return_index=True, return_inverse=True)
    order = np.argsort(np.argsort(first))
    return order[inverse]


def distinct(values: ArrayLike, tol: ArrayLike | None = None,
             prismatic: ArrayLike | None = None) -> int:
    """Number of distinct commanded values among the rows (:func:`groups`)."""
    labels = groups(values, tol, prismatic)
    return int(labels.max()) + 1 if labels.size else 0


def alone_groups(values: ArrayLike, j: int, *, least: int, span: float,
                 tol: ArrayLike | None = None, prismatic: ArrayLike | None = None
                 ) -> list[NDArray[np.int_]]:
    """Row sets in which only column ``j`` moves: the rows a circle point analysis fits.

    Parameters
    ----------
    values : array_like, shape (N, k)
        Axis values of each row (rad; m for prismatic columns), k >= 2.
    j : int
        The moving column.
    least : int
        Fewest distinct values of column ``j`` in a set.
    span : float
        Smallest range of column ``j`` in a set (rad or m).
    tol : float or array_like, shape (k,), optional
        Stated tolerance (rad, m); default derived from the data (:func:`resolution`): of the
        other columns together for which rows hold them still, of column ``j`` for its distinct
        values.
    prismatic : array_like of bool, shape (k,), optional
        Columns that are lengths.

    Returns
    -------
    list of ndarray of int
        Row indices of each set, in the order of their first row.
    """
    rows = _as_rows(values)
    k = rows.shape[1]
    pris = np.zeros(k, dtype=bool) if prismatic is None else np.asarray(prismatic, dtype=bool)
    t = None if tol is None else _tolerances(tol, k)
    others = np.delete(rows, j, axis=1)
    labels = groups(others, None if t is None else np.delete(t, j), np.delete(pris, j))
    tol_j = resolution(rows[:, j], pris[j:j + 1]) if t is None else t[j:j + 1]
    out = []
    for g in range(int(labels.max()) + 1 if labels.size else 0):
        idx = np.flatnonzero(labels == g)
        moved = rows[idx, j]
        if (len(idx) >= least and np.ptp(moved) >= span * 0.999
                and distinct(moved, tol_j) >= least):
            out.append(idx)
    return out
